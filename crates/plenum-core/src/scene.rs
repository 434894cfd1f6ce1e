//! A scene ready to render: primitives in a BVH, materials, lights, camera and background.
//! Built once by [`SceneBuilder`]; immutable and shared by every render thread.

use crate::accel::Bvh;
use crate::camera::CameraSettings;
use crate::color::Color;
use crate::geometry::{HitRecord, Shape};
use crate::light::Light;
use crate::material::{Coefficients, Material};
use crate::math::{gamma, Bounds3, Ray, Transform, Vec3};
use crate::texture::TextureCoords;
use std::sync::Arc;

/// Index of a material in [`Scene::materials`].
pub type MaterialId = u32;

/// A shape placed in the world with a material.
#[derive(Clone, Debug)]
pub struct Primitive {
    pub shape: Shape,
    /// Object-to-world transform; `None` when the shape is already in world coordinates.
    pub to_world: Option<Box<Transform>>,
    pub material: MaterialId,
    /// For meshes: a material per vertex, blended across each triangle by its barycentric
    /// coordinates (the course `.ray` format's per-vertex materials). Replaces `material`.
    pub vertex_materials: Option<Arc<Vec<MaterialId>>>,
}

/// Everything the integrator needs about a hit, in world space.
#[derive(Clone, Copy, Debug)]
pub struct Interaction {
    pub p: Vec3,
    pub p_error: Vec3,
    /// Unit geometric normal, outward for solids.
    pub n: Vec3,
    /// Unit shading normal, on the same side as `n`.
    pub shading_n: Vec3,
    pub texture: TextureCoords,
    pub primitive: u32,
    /// The shape's record of the hit: which triangle, and where in it.
    pub hit: HitRecord,
}

impl Primitive {
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<HitRecord> {
        match &self.to_world {
            None => self.shape.intersect(ray, t_max),
            Some(t) => {
                let (local, dt) = t.ray_to_object(ray);
                let mut hit = self.shape.intersect(&local, t_max - dt)?;
                hit.t += dt;
                Some(hit)
            }
        }
    }

    /// The hit in world space; `want_uv` asks for texture coordinates.
    pub fn interaction(
        &self,
        ray: &Ray,
        hit: &HitRecord,
        primitive: u32,
        want_uv: bool,
    ) -> Interaction {
        match &self.to_world {
            None => {
                let g = self.shape.surface(ray, hit, want_uv);
                Interaction {
                    p: g.p,
                    p_error: g.p_error,
                    n: g.n,
                    shading_n: g.shading_n,
                    texture: TextureCoords {
                        uv: g.uv,
                        object_point: g.p,
                    },
                    primitive,
                    hit: *hit,
                }
            }
            Some(t) => {
                let (local, dt) = t.ray_to_object(ray);
                let local_hit = HitRecord {
                    t: hit.t - dt,
                    ..*hit
                };
                let g = self.shape.surface(&local, &local_hit, want_uv);
                let (p, p_error) = t.point_with_error(g.p, g.p_error);
                // A spawned ray is intersected in object space, where what keeps it off the
                // surface is its distance along the object normal. Offsetting by the world
                // error box alone falls short under anisotropic scales: require the world
                // offset to map to more than the object-space error along the normal (that of
                // the hit, that of taking the new origin back into object space, and that of
                // the stored inverse itself).
                let normal = t.normal(g.n);
                // A degenerate normal (a shape's singular point) keeps the world's error box.
                let stretch = normal.length().max(f64::MIN_POSITIVE);
                let n = normal / stretch;
                let inverse_mismatch = t.inverse_residual() * (g.p.abs().max_component() + 1.0);
                let object_error = g.n.abs().dot(g.p_error + t.inverse_error(p))
                    + inverse_mismatch * g.n.abs().dot(Vec3::ONE);
                let p_error = p_error + n.abs() * (object_error / stretch * (1.0 + gamma(4)));
                Interaction {
                    p,
                    p_error,
                    n,
                    shading_n: t.normal(g.shading_n).normalized(),
                    texture: TextureCoords {
                        uv: g.uv,
                        object_point: g.p,
                    },
                    primitive,
                    hit: *hit,
                }
            }
        }
    }

    pub fn world_bounds(&self) -> Option<Bounds3> {
        let b = self.shape.bounds()?;
        Some(match &self.to_world {
            None => b,
            Some(t) => Bounds3::from_points(b.corners().map(|c| t.point(c))),
        })
    }
}

#[derive(Clone, Debug)]
pub struct Scene {
    pub camera: CameraSettings,
    pub primitives: Vec<Primitive>,
    /// A name per primitive, for the ray tree and messages.
    pub object_names: Vec<String>,
    pub materials: Vec<Material>,
    pub material_names: Vec<String>,
    pub lights: Vec<Light>,
    pub light_names: Vec<String>,
    /// Per primitive: some light can pass through (a transmissive material or vertex material).
    transmissive: Vec<bool>,
    /// Per primitive: its material looks something up by texture coordinates.
    needs_uv: Vec<bool>,
    /// I_a: the sum of the scene's ambient lights.
    pub ambient: Color,
    /// Radiance of rays that hit nothing.
    pub background: Color,
    bvh: Bvh,
    /// Primitive index of each BVH item: the BVH holds the bounded primitives only.
    bounded: Vec<u32>,
    /// Primitives without bounds (infinite planes), tested on every ray.
    unbounded: Vec<u32>,
}

impl Scene {
    /// The nearest hit in (0, t_max): the primitive's index and the hit.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<(u32, HitRecord)> {
        let mut best = self.bvh.intersect(ray, t_max, |i, t| {
            self.primitives[self.bounded[i as usize] as usize].intersect(ray, t)
        });
        if let Some((i, _)) = &mut best {
            *i = self.bounded[*i as usize];
        }
        for &i in &self.unbounded {
            let limit = best.map_or(t_max, |(_, h)| h.t);
            if let Some(hit) = self.primitives[i as usize].intersect(ray, limit) {
                best = Some((i, hit));
            }
        }
        best
    }

    /// Calls `visit(primitive, hit)` with each primitive's nearest hit in (0, t_max), in no
    /// particular order, until `visit` returns false: an any-hit query for shadow rays.
    pub fn for_each_hit(
        &self,
        ray: &Ray,
        t_max: f64,
        mut visit: impl FnMut(u32, &HitRecord) -> bool,
    ) {
        let mut go_on = true;
        self.bvh.for_each_candidate(ray, t_max, |i| {
            let prim = self.bounded[i as usize];
            if let Some(hit) = self.primitives[prim as usize].intersect(ray, t_max) {
                go_on = visit(prim, &hit);
            }
            go_on
        });
        for &i in &self.unbounded {
            if !go_on {
                return;
            }
            if let Some(hit) = self.primitives[i as usize].intersect(ray, t_max) {
                go_on = visit(i, &hit);
            }
        }
    }

    pub fn interaction(&self, ray: &Ray, primitive: u32, hit: &HitRecord) -> Interaction {
        let want_uv = self.needs_uv[primitive as usize];
        self.primitives[primitive as usize].interaction(ray, hit, primitive, want_uv)
    }

    pub fn material_of(&self, primitive: u32) -> &Material {
        &self.materials[self.primitives[primitive as usize].material as usize]
    }

    /// Whether light can pass through the primitive anywhere.
    pub fn is_transmissive(&self, primitive: u32) -> bool {
        self.transmissive[primitive as usize]
    }

    /// The material's coefficients at a hit; per-vertex materials are blended by the hit's
    /// barycentric coordinates.
    pub fn coefficients(&self, it: &Interaction) -> Coefficients {
        let p = &self.primitives[it.primitive as usize];
        if let (Some(ids), Shape::Mesh(mesh)) = (&p.vertex_materials, &p.shape) {
            let triangle = mesh.triangles()[it.hit.part as usize];
            let (b1, b2) = (it.hit.u, it.hit.v);
            let weights = [1.0 - b1 - b2, b1, b2];
            let parts = [0, 1, 2].map(|i| {
                let m = &self.materials[ids[triangle[i] as usize] as usize];
                (weights[i], m.evaluate(&it.texture))
            });
            return Coefficients::blend(&parts);
        }
        self.material_of(it.primitive).evaluate(&it.texture)
    }

    /// Bounds of all bounded primitives.
    pub fn bounds(&self) -> Bounds3 {
        self.bvh.bounds()
    }
}

/// Collects the parts of a scene, then builds the acceleration structure.
#[derive(Clone, Debug, Default)]
pub struct SceneBuilder {
    pub camera: CameraSettings,
    pub background: Color,
    pub ambient: Color,
    primitives: Vec<Primitive>,
    object_names: Vec<String>,
    materials: Vec<Material>,
    material_names: Vec<String>,
    lights: Vec<Light>,
    light_names: Vec<String>,
}

impl SceneBuilder {
    pub fn add_material(&mut self, name: impl Into<String>, material: Material) -> MaterialId {
        self.materials.push(material);
        self.material_names.push(name.into());
        (self.materials.len() - 1) as MaterialId
    }

    /// Places `shape` with an object-to-world transform (identity: none).
    pub fn add_object(
        &mut self,
        name: impl Into<String>,
        shape: Shape,
        to_world: Transform,
        material: MaterialId,
    ) {
        self.primitives.push(Primitive {
            shape,
            to_world: (!to_world.is_identity()).then(|| Box::new(to_world)),
            material,
            vertex_materials: None,
        });
        self.object_names.push(name.into());
    }

    /// Places a mesh whose material varies per vertex (one id per mesh vertex).
    pub fn add_mesh_with_vertex_materials(
        &mut self,
        name: impl Into<String>,
        mesh: Arc<crate::geometry::TriangleMesh>,
        to_world: Transform,
        vertex_materials: Vec<MaterialId>,
    ) {
        let first = vertex_materials.first().copied().unwrap_or(0);
        self.add_object(name, Shape::Mesh(mesh), to_world, first);
        if let Some(p) = self.primitives.last_mut() {
            p.vertex_materials = Some(Arc::new(vertex_materials));
        }
    }

    pub fn add_light(&mut self, name: impl Into<String>, light: Light) {
        self.lights.push(light);
        self.light_names.push(name.into());
    }

    pub fn build(mut self) -> Scene {
        // An opaque polyhedron is never entered, so its back faces can be culled.
        for p in &mut self.primitives {
            if let Shape::Polyhedron(poly) = &mut p.shape {
                poly.cull_back_faces = !self.materials[p.material as usize].is_transmissive();
            }
        }
        let mut bounds = Vec::new();
        let mut bounded = Vec::new();
        let mut unbounded = Vec::new();
        for (i, p) in self.primitives.iter().enumerate() {
            match p.world_bounds() {
                Some(b) => {
                    bounds.push(b);
                    bounded.push(i as u32);
                }
                None => unbounded.push(i as u32),
            }
        }
        let transmissive = self
            .primitives
            .iter()
            .map(|p| match &p.vertex_materials {
                Some(ids) => ids
                    .iter()
                    .any(|&m| self.materials[m as usize].is_transmissive()),
                None => self.materials[p.material as usize].is_transmissive(),
            })
            .collect();
        let needs_uv = self
            .primitives
            .iter()
            .map(|p| match &p.vertex_materials {
                Some(ids) => ids.iter().any(|&m| self.materials[m as usize].needs_uv()),
                None => self.materials[p.material as usize].needs_uv(),
            })
            .collect();
        Scene {
            transmissive,
            needs_uv,
            camera: self.camera,
            bvh: Bvh::build(&bounds),
            bounded,
            unbounded,
            primitives: self.primitives,
            object_names: self.object_names,
            materials: self.materials,
            material_names: self.material_names,
            lights: self.lights,
            light_names: self.light_names,
            ambient: self.ambient,
            background: self.background,
        }
    }
}
