//! A scene ready to render: primitives in a BVH, materials, lights, camera and background.
//! Built once by [`SceneBuilder`]; immutable and shared by every render thread.

use crate::accel::{Accel, AccelKind, Coherence, LeafSize};
use crate::camera::CameraSettings;
use crate::color::Color;
use crate::geometry::{Disk, HitRecord, Polygon, Shape, Sphere, TriangleMesh};
use crate::light::{Emitter, Light};
use crate::material::{Coefficients, Material};
use crate::math::{gamma, Bounds3, Motion, Ray, Transform, Vec3};
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
    /// For an object that moves while the shutter is open: its transforms at times 0 and 1,
    /// which replace `to_world` (the pose at time 0).
    pub motion: Option<Box<Motion>>,
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
    /// Calls `f` with the object-to-world transform at `time` (`None`: identity).
    #[inline]
    fn placed<R>(&self, time: f64, f: impl FnOnce(Option<&Transform>) -> R) -> R {
        match &self.motion {
            None => f(self.to_world.as_deref()),
            Some(m) => f(Some(&m.at(time))),
        }
    }

    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<HitRecord> {
        self.placed(ray.time, |placement| match placement {
            None => self.shape.intersect(ray, t_max),
            Some(t) => {
                let (local, dt) = t.ray_to_object(ray);
                let mut hit = self.shape.intersect(&local, t_max - dt)?;
                hit.t += dt;
                Some(hit)
            }
        })
    }

    /// The hit in world space; `want_uv` asks for texture coordinates.
    pub fn interaction(
        &self,
        ray: &Ray,
        hit: &HitRecord,
        primitive: u32,
        want_uv: bool,
    ) -> Interaction {
        self.placed(ray.time, |placement| match placement {
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
        })
    }

    /// Some hit in (0, t_max), not necessarily the nearest (see [`Shape::intersect_any`]).
    pub fn intersect_any(&self, ray: &Ray, t_max: f64, coherence: Coherence) -> Option<HitRecord> {
        self.placed(ray.time, |placement| match placement {
            None => self.shape.intersect_any(ray, t_max, coherence),
            Some(t) => {
                let (local, dt) = t.ray_to_object(ray);
                let mut hit = self.shape.intersect_any(&local, t_max - dt, coherence)?;
                hit.t += dt;
                Some(hit)
            }
        })
    }

    /// World bounds; for a moving object, of everywhere it goes while the shutter is open.
    pub fn world_bounds(&self) -> Option<Bounds3> {
        let b = self.shape.bounds()?;
        Some(match (&self.motion, &self.to_world) {
            (Some(m), _) => m.bounds(&b),
            (None, None) => b,
            (None, Some(t)) => Bounds3::from_points(b.corners().map(|c| t.point(c))),
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
    /// Per light: the primitive that shows it, for area lights.
    pub light_objects: Vec<Option<u32>>,
    /// Per primitive: some light can pass through (a transmissive material or vertex material).
    transmissive: Vec<bool>,
    /// Per primitive: its material looks something up by texture coordinates.
    needs_uv: Vec<bool>,
    /// I_a: the sum of the scene's ambient lights.
    pub ambient: Color,
    /// Radiance of rays that hit nothing.
    pub background: Color,
    accel: Accel,
    /// Primitive index of each item of `accel`, which holds the bounded primitives only.
    bounded: Vec<u32>,
    /// Primitives without bounds (infinite planes), tested on every ray.
    unbounded: Vec<u32>,
}

impl Scene {
    /// The nearest hit in (0, t_max): the primitive's index and the hit.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<(u32, HitRecord)> {
        let mut best = None;
        self.accel.traverse(ray, t_max, |items, t_max| {
            for &i in items {
                let prim = self.bounded[i as usize];
                if let Some(hit) = self.primitives[prim as usize].intersect(ray, *t_max) {
                    *t_max = hit.t;
                    best = Some((prim, hit));
                }
            }
            true
        });
        for &i in &self.unbounded {
            let limit = best.map_or(t_max, |(_, h)| h.t);
            if let Some(hit) = self.primitives[i as usize].intersect(ray, limit) {
                best = Some((i, hit));
            }
        }
        best
    }

    /// Calls `visit(primitive, hit)` once for each primitive hit in (0, t_max), in no
    /// particular order, until `visit` returns false: the query of shadow rays. A
    /// transmissive primitive reports its nearest hit (where its material is looked up);
    /// an opaque one, the first hit found, a mesh walked as suits `coherence` rays.
    pub fn for_each_hit(
        &self,
        ray: &Ray,
        t_max: f64,
        coherence: Coherence,
        mut visit: impl FnMut(u32, &HitRecord) -> bool,
    ) {
        let hit_of = |prim: u32| {
            let p = &self.primitives[prim as usize];
            if self.transmissive[prim as usize] {
                p.intersect(ray, t_max)
            } else {
                p.intersect_any(ray, t_max, coherence)
            }
        };
        let mut go_on = true;
        self.accel.traverse(ray, t_max, |items, _| {
            for &i in items {
                let prim = self.bounded[i as usize];
                if let Some(hit) = hit_of(prim) {
                    go_on = visit(prim, &hit);
                    if !go_on {
                        break;
                    }
                }
            }
            go_on
        });
        for &i in &self.unbounded {
            if !go_on {
                return;
            }
            if let Some(hit) = hit_of(i) {
                go_on = visit(i, &hit);
            }
        }
    }

    /// Whether anything is hit in (0, t_max), for one of `coherence` rays.
    pub fn occluded(&self, ray: &Ray, t_max: f64, coherence: Coherence) -> bool {
        let mut hit = false;
        self.for_each_hit(ray, t_max, coherence, |_, _| {
            hit = true;
            false
        });
        hit
    }

    /// The scene with its primitives, and the triangles of every mesh, in `kind` structures.
    pub fn with_accel(mut self, kind: AccelKind) -> Scene {
        // Rebuild each distinct mesh once, so instances stay shared.
        let mut rebuilt: std::collections::HashMap<*const TriangleMesh, Arc<TriangleMesh>> =
            Default::default();
        for p in &mut self.primitives {
            if let Shape::Mesh(m) = &mut p.shape {
                let new = rebuilt
                    .entry(Arc::as_ptr(m))
                    .or_insert_with(|| Arc::new(m.with_accel(kind)));
                *m = new.clone();
            }
        }
        let bounds: Vec<Bounds3> = self
            .bounded
            .iter()
            .filter_map(|&i| self.primitives[i as usize].world_bounds())
            .collect();
        self.accel = Accel::build(kind, &bounds, LeafSize::SINGLE);
        self
    }

    /// Which structure holds the primitives (and the triangles of every mesh).
    pub fn accel_kind(&self) -> AccelKind {
        self.accel.kind()
    }

    /// Bytes of the acceleration structures: the scene's and every distinct mesh's (with
    /// the mesh's vertices and indices).
    pub fn accel_memory_bytes(&self) -> usize {
        let mut seen = std::collections::HashSet::new();
        let meshes: usize = self
            .primitives
            .iter()
            .filter_map(|p| match &p.shape {
                Shape::Mesh(m) if seen.insert(Arc::as_ptr(m)) => Some(m.memory_bytes()),
                _ => None,
            })
            .sum();
        self.accel.memory_bytes() + self.bounded.len() * 4 + meshes
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
        let corners = match (&p.vertex_materials, &p.shape) {
            (Some(ids), Shape::Mesh(mesh)) => mesh.vertex_indices(it.hit.part).map(|t| (ids, t)),
            _ => None,
        };
        if let Some((ids, triangle)) = corners {
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
        self.accel.bounds()
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
    light_objects: Vec<Option<u32>>,
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
            motion: None,
            material,
            vertex_materials: None,
        });
        self.object_names.push(name.into());
    }

    /// Places a mesh whose material varies per vertex (one id per mesh vertex). The mesh must
    /// keep its vertex indices ([`crate::geometry::TriangleMesh::new_keeping_indices`]); where
    /// it does not, the first material is shown.
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

    /// Makes the last object added move from its transform at time 0 to `close` at time 1.
    pub fn set_last_motion(&mut self, close: Transform) {
        if let Some(p) = self.primitives.last_mut() {
            let open = p
                .to_world
                .as_deref()
                .copied()
                .unwrap_or(Transform::IDENTITY);
            if open != close {
                p.motion = Some(Box::new(Motion::new(&open, &close)));
            }
        }
    }

    /// Adds an area light and the surface that shows it: a rectangle, disk or sphere that
    /// emits `radiance` (seen by camera, reflected and refracted rays, casting shadows on
    /// other lights' receivers), and `samples` shadow rays per shading point.
    pub fn add_area_light(
        &mut self,
        name: impl Into<String>,
        emitter: Emitter,
        radiance: Color,
        samples: u32,
    ) {
        let name = name.into();
        let shape = match &emitter {
            Emitter::Rectangle {
                corner,
                edge_u,
                edge_v,
            } => Polygon::new(vec![
                *corner,
                *corner + *edge_u,
                *corner + *edge_u + *edge_v,
                *corner + *edge_v,
            ])
            .ok()
            .map(|p| Shape::Polygon(Box::new(p))),
            Emitter::Disk {
                center,
                normal,
                radius,
            } => Some(Shape::Disk(Disk::new(*center, *normal, *radius))),
            Emitter::Sphere { center, radius } => {
                Some(Shape::Sphere(Sphere::new(*center, *radius)))
            }
            Emitter::Triangles { .. } => None,
        };
        let object = shape.map(|shape| {
            let material =
                self.add_material(format!("{name} (emitter)"), Material::emitter(radiance));
            self.add_object(name.clone(), shape, Transform::IDENTITY, material);
            (self.primitives.len() - 1) as u32
        });
        self.add_light(
            name,
            Light::Area {
                shape: emitter,
                radiance,
                samples,
            },
        );
        if let Some(last) = self.light_objects.last_mut() {
            *last = object;
        }
    }

    /// Adds a triangle mesh that emits `radiance` from both sides of every triangle: an
    /// object to see and an area light sampled over its triangles by area.
    pub fn add_mesh_light(
        &mut self,
        name: impl Into<String>,
        mesh: Arc<TriangleMesh>,
        to_world: Transform,
        radiance: Color,
        samples: u32,
    ) {
        let name = name.into();
        let triangles = mesh
            .triangles()
            .map(|(_, t)| t.map(|p| to_world.point(p)))
            .collect();
        let material = self.add_material(format!("{name} (emitter)"), Material::emitter(radiance));
        self.add_object(name.clone(), Shape::Mesh(mesh), to_world, material);
        if let Some(shape) = Emitter::triangles(triangles) {
            self.add_light(
                name,
                Light::Area {
                    shape,
                    radiance,
                    samples,
                },
            );
            if let Some(last) = self.light_objects.last_mut() {
                *last = Some((self.primitives.len() - 1) as u32);
            }
        }
    }

    pub fn add_light(&mut self, name: impl Into<String>, light: Light) {
        self.lights.push(light);
        self.light_names.push(name.into());
        self.light_objects.push(None);
    }

    /// Builds the scene with the default acceleration structure, a BVH.
    pub fn build(self) -> Scene {
        self.build_with(AccelKind::Bvh)
    }

    /// Builds the scene with `kind` structures, over its primitives and inside its meshes.
    pub fn build_with(mut self, kind: AccelKind) -> Scene {
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
        let scene = Scene {
            transmissive,
            needs_uv,
            camera: self.camera,
            accel: Accel::build(AccelKind::Bvh, &bounds, LeafSize::SINGLE),
            bounded,
            unbounded,
            primitives: self.primitives,
            object_names: self.object_names,
            materials: self.materials,
            material_names: self.material_names,
            lights: self.lights,
            light_names: self.light_names,
            light_objects: self.light_objects,
            ambient: self.ambient,
            background: self.background,
        };
        if kind == AccelKind::Bvh {
            scene
        } else {
            scene.with_accel(kind)
        }
    }
}
