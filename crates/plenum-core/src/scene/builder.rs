//! Collects the parts of a scene (objects, materials, lights, camera), then builds it.

use super::alpha::Alpha;
use super::bump::Bump;
use super::geometry::Geometry;
use super::lights::Lights;
use super::materials::Materials;
use super::primitive::Primitive;
use super::Scene;
use crate::accel::AccelKind;
use crate::camera::CameraSettings;
use crate::color::Color;
use crate::geometry::{Disk, Polygon, Shape, Sphere};
use crate::light::{EmissionTexture, Emitter, Light};
use crate::light_sampler::LightSamplerKind;
use crate::material::{Material, MaterialId, PhongMaterial};
use crate::math::{Motion, Transform};
use crate::texture::Texture;
use plenum_spectrum::Spectrum;
use std::collections::HashMap;
use std::sync::Arc;

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
    /// The material of surfaces that only show their area light's emission.
    black: Option<MaterialId>,
    /// Per light: a spectrum given in place of its RGB value, and a scale.
    light_spectra: Vec<Option<(Spectrum, f64)>>,
    one_sided: Vec<MaterialId>,
    /// Normal and bump maps by material: every object of the material is given its map.
    bumps: HashMap<MaterialId, Arc<Bump>>,
    light_sampler: LightSamplerKind,
}

impl SceneBuilder {
    /// Gives the last light added a spectrum (an illuminant) in place of its RGB value; its
    /// RGB value is then that spectrum's, for Whitted's model and RGB mode.
    pub fn set_last_light_spectrum(&mut self, spectrum: Spectrum, scale: f64) {
        if let Some(s) = self.light_spectra.last_mut() {
            *s = Some((spectrum, scale));
        }
    }

    /// The last light added.
    pub fn last_light(&self) -> Option<&Light> {
        self.lights.last()
    }

    /// Multiplies the RGB value (radiance or intensity) of the last light added by `k`.
    pub fn scale_last_light(&mut self, k: f64) {
        if let Some(l) = self.lights.last_mut() {
            l.set_rgb(l.rgb() * k);
        }
    }

    /// Makes the last light added, an area light, emit only toward its normal's side.
    pub fn set_last_light_one_sided(&mut self) {
        if let Some(Light::Area { two_sided, .. }) = self.lights.last_mut() {
            *two_sided = false;
        }
    }

    /// Makes the last light added, an area light shown on the last object added (by
    /// [`SceneBuilder::add_emissive_object`] or [`SceneBuilder::add_area_light`]), emit its
    /// radiance times `texture`, looked up at its surface's (u, v). `false` where the last
    /// light is not on the last object.
    pub fn set_last_light_texture(&mut self, texture: Texture) -> bool {
        let (
            Some(p),
            Some(Light::Area {
                shape,
                texture: slot,
                ..
            }),
        ) = (self.primitives.last(), self.lights.last_mut())
        else {
            return false;
        };
        if p.light.map(|l| l as usize + 1) != Some(self.light_names.len()) {
            return false;
        }
        let to_world = p
            .to_world
            .as_deref()
            .copied()
            .unwrap_or(Transform::IDENTITY);
        *slot = EmissionTexture::new(texture, shape, &p.shape, &to_world).map(Arc::new);
        slot.is_some()
    }

    /// Turns the shading normal of every object of material `id` placed from now on by a
    /// normal or bump map (see [`Bump`]): the formats give these maps with the material.
    pub fn set_bump(&mut self, id: MaterialId, bump: Bump) {
        self.bumps.insert(id, Arc::new(bump));
    }

    /// Makes material `id` scatter only on the side its surfaces' normals point to (seen
    /// from behind it is black), as Mitsuba's BSDFs do. Transmissive materials stay
    /// two-sided.
    pub fn set_one_sided(&mut self, id: MaterialId) {
        self.one_sided.push(id);
    }

    /// How next-event estimation chooses lights (by power unless told).
    pub fn set_light_sampler(&mut self, kind: LightSamplerKind) {
        self.light_sampler = kind;
    }

    /// Places a shape that emits `radiance` (one- or two-sided) and scatters by `material`:
    /// a physically based area light on any shape that can be sampled (a mesh, sphere, disk
    /// or polygon). Other shapes are placed without emitting, and `false` comes back.
    #[allow(clippy::too_many_arguments)]
    pub fn add_emissive_object(
        &mut self,
        name: impl Into<String>,
        shape: Shape,
        to_world: Transform,
        material: MaterialId,
        radiance: Color,
        two_sided: bool,
        samples: u32,
    ) -> bool {
        let name = name.into();
        let emitter = Emitter::of_shape(&shape, &to_world);
        self.add_object(name.clone(), shape, to_world, material);
        let Some(shape) = emitter else {
            return false;
        };
        self.add_light(
            name,
            Light::Area {
                shape,
                radiance,
                samples,
                two_sided,
                texture: None,
            },
        );
        self.show_last_light_on_last_object();
        true
    }

    /// The material of a surface that only shows its area light's emission: black, it
    /// reflects and transmits nothing (Mitsuba's choice for an emitter without a BSDF). One
    /// for the scene, added when first asked for.
    pub fn black_material(&mut self) -> MaterialId {
        match self.black {
            Some(id) => id,
            None => {
                let id = self.add_material("black", Material::Phong(PhongMaterial::black()));
                self.black = Some(id);
                id
            }
        }
    }

    /// The last object added is the surface of the last light added, an area light.
    fn show_last_light_on_last_object(&mut self) {
        let light = self.lights.len() as u32 - 1;
        if let Some(p) = self.primitives.last_mut() {
            p.light = Some(light);
        }
    }

    pub fn add_material(
        &mut self,
        name: impl Into<String>,
        material: impl Into<Material>,
    ) -> MaterialId {
        self.materials.push(material.into());
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
            light: None,
            alpha: None,
            bump: self.bumps.get(&material).cloned(),
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

    /// Cuts the last object added out where `alpha` says (see [`Alpha`]). An alpha that keeps
    /// the whole surface is dropped, so that it costs nothing.
    pub fn set_last_alpha(&mut self, alpha: Alpha) {
        if let Some(p) = self.primitives.last_mut() {
            p.alpha = (!alpha.is_opaque()).then(|| Arc::new(alpha));
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
        if let Some(shape) = &shape {
            let material = self.black_material();
            self.add_object(name.clone(), shape.clone(), Transform::IDENTITY, material);
        }
        self.add_light(
            name,
            Light::Area {
                shape: emitter,
                radiance,
                samples,
                two_sided: true,
                texture: None,
            },
        );
        if shape.is_some() {
            self.show_last_light_on_last_object();
        }
    }

    pub fn add_light(&mut self, name: impl Into<String>, light: Light) {
        self.lights.push(light);
        self.light_names.push(name.into());
        self.light_spectra.push(None);
    }

    /// Builds the scene with the default acceleration structure, a BVH.
    pub fn build(self) -> Scene {
        self.build_with(AccelKind::Bvh)
    }

    /// Builds the scene with `kind` structures, over its primitives and inside its meshes.
    pub fn build_with(mut self, kind: AccelKind) -> Scene {
        // Under the physically based methods the background is a light like any other: a
        // uniform infinite light (Mitsuba's `constant` emitter), sampled for direct light,
        // emitting light paths and photons, and seen (with MIS) by rays that leave the
        // scene. Whitted's model reads `background` itself, and no infinite light.
        let background_light = (!self.background.is_black()).then(|| {
            let radiance = self.background;
            self.add_light("background", Light::Infinite { radiance });
            self.lights.len() as u32 - 1
        });
        // An opaque polyhedron is never entered, so its back faces can be culled.
        for p in &mut self.primitives {
            if let Shape::Polyhedron(poly) = &mut p.shape {
                poly.cull_back_faces = !self.materials[p.material as usize].is_transmissive();
            }
        }
        // Per primitive, what any of its materials needs.
        let any = |p: &Primitive, what: fn(&Material) -> bool| match &p.vertex_materials {
            Some(ids) => ids.iter().any(|&m| what(&self.materials[m as usize])),
            None => what(&self.materials[p.material as usize]),
        };
        let transmissive = self
            .primitives
            .iter()
            .map(|p| any(p, Material::is_transmissive))
            .collect();
        // A textured light's surface is looked up where rays meet it.
        let textured = |p: &Primitive| {
            p.light.is_some_and(|l| {
                matches!(
                    self.lights[l as usize],
                    Light::Area {
                        texture: Some(_),
                        ..
                    }
                )
            })
        };
        let needs_uv = self
            .primitives
            .iter()
            .map(|p| any(p, Material::needs_uv) || textured(p))
            .collect();
        let lights = Lights::new(
            self.lights,
            self.light_names,
            &self.light_spectra,
            background_light,
        );
        let geometry = Geometry::new(
            self.primitives,
            self.object_names,
            transmissive,
            needs_uv,
            kind,
        );
        let mut scene = Scene {
            camera: self.camera,
            geometry,
            materials: Materials::new(self.materials, self.material_names, &self.one_sided),
            lights,
            ambient: self.ambient,
            background: self.background,
        };
        scene.set_light_sampler(self.light_sampler);
        scene
    }
}
