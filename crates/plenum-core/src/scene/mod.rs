//! A scene ready to render: its geometry (primitives in an acceleration structure), its
//! material table, its lights, the camera and the background. Built once by
//! [`SceneBuilder`]; immutable and shared by every render thread.

mod alpha;
mod builder;
mod bump;
mod geometry;
mod lights;
mod materials;
mod primitive;

pub use crate::material::MaterialId;
pub use alpha::Alpha;
pub use builder::SceneBuilder;
pub use bump::{Bitangent, Bump, UvDerivatives};
pub use geometry::Geometry;
pub use lights::Lights;
pub use materials::Materials;
pub use primitive::{Interaction, Primitive};

use crate::accel::AccelKind;
use crate::bxdf::{Bsdf, Bxdf};
use crate::camera::CameraSettings;
use crate::color::Color;
use crate::geometry::{HitRecord, Shape};
use crate::light_sampler::LightSamplerKind;
use crate::material::{rgb_radiance, Coefficients, Material, PhongMaterial, Scattering};
use crate::math::{Ray, Vec3};
use plenum_spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct Scene {
    pub camera: CameraSettings,
    /// Where rays hit: the primitives, their names, the acceleration structure.
    pub geometry: Geometry,
    pub materials: Materials,
    pub lights: Lights,
    /// I_a: the sum of the scene's ambient lights.
    pub ambient: Color,
    /// Radiance of rays that hit nothing: Whitted's model reads it here; the physically based
    /// methods see it as the light `lights.background`.
    pub background: Color,
}

impl Scene {
    /// The scene with its primitives, and the triangles of every mesh, in `kind` structures.
    pub fn with_accel(mut self, kind: AccelKind) -> Scene {
        self.geometry = self.geometry.with_accel(kind);
        self
    }

    /// The area light whose surface `primitive` is.
    #[inline]
    pub fn area_light(&self, primitive: u32) -> Option<u32> {
        self.geometry.primitives[primitive as usize].light
    }

    /// The material of `primitive` (the first of a mesh with per-vertex materials).
    pub fn material_of(&self, primitive: u32) -> &Material {
        &self.materials[self.geometry.primitives[primitive as usize].material as usize]
    }

    /// The material's coefficients at a hit; per-vertex materials are blended by the hit's
    /// barycentric coordinates.
    pub fn coefficients(&self, it: &Interaction) -> Coefficients {
        let p = &self.geometry.primitives[it.primitive as usize];
        let corners = match (&p.vertex_materials, &p.shape) {
            (Some(ids), Shape::Mesh(mesh)) => mesh.vertex_indices(it.hit.part).map(|t| (ids, t)),
            _ => None,
        };
        if let Some((ids, triangle)) = corners {
            let (b1, b2) = (it.hit.u, it.hit.v);
            let weights = [1.0 - b1 - b2, b1, b2];
            let parts = [0, 1, 2].map(|i| {
                let m = &self.materials[ids[triangle[i] as usize] as usize];
                (weights[i], m.coefficients(&it.texture()))
            });
            return Coefficients::blend(&parts);
        }
        self.materials.coefficients(p.material, &it.texture())
    }

    /// The k_t of `primitive` at `hit` along `ray`: what light a shadow ray keeps passing
    /// through it. Read from the material where it is uniform, without working out the hit's
    /// surface (most of the cost of a shadow ray through glass).
    pub fn transmissive(&self, ray: &Ray, primitive: u32, hit: &HitRecord) -> Color {
        let p = &self.geometry.primitives[primitive as usize];
        if p.vertex_materials.is_none() {
            if let Some(t) = self.materials[p.material as usize].uniform_transmissive() {
                return t;
            }
        }
        let it = self.geometry.interaction(ray, primitive, hit);
        self.coefficients(&it).transmissive
    }

    /// The emission k_e of a Phong material at a hit on a primitive that is not a light's
    /// surface, at the sample's wavelengths; `None` where there is none.
    pub fn phong_emission(
        &self,
        it: &Interaction,
        wl: &SampledWavelengths,
    ) -> Option<SampledSpectrum> {
        let m = self.material_of(it.primitive).phong()?;
        if m.emissive.is_black() {
            return None;
        }
        Some(rgb_radiance(m.emissive.evaluate(&it.texture()), wl))
    }

    /// Whether nothing in the scene gives light (no light source or emitting surface, no
    /// Phong k_e, a black background, no ambient light): its image is black by any method.
    pub fn emits_nothing(&self) -> bool {
        self.lights.is_empty()
            && self.ambient.is_black()
            && self.background.is_black()
            && self
                .materials
                .iter()
                .all(|m| m.phong().is_none_or(|p| p.emissive.is_black()))
    }

    /// The scene has objects, and all of them are of physically based materials (emitters
    /// that only show their light aside).
    pub fn is_physically_based(&self) -> bool {
        let primitives = &self.geometry.primitives;
        !primitives.is_empty()
            && primitives.iter().all(|p| {
                p.vertex_materials.is_none() && {
                    let m = &self.materials[p.material as usize];
                    m.is_physical() || m.reflects_nothing()
                }
            })
    }

    /// Chooses how next-event estimation picks lights.
    pub fn set_light_sampler(&mut self, kind: LightSamplerKind) {
        self.lights.set_sampler(kind, self.geometry.radius());
    }

    /// The BSDF at a hit seen from `wo`, for the sample's wavelengths; `None` where nothing
    /// scatters (an emitter's surface). Per-vertex Phong materials are blended first; a mix
    /// chooses by a hash of the hit and `wo`, so the choice is the same for any thread.
    pub fn bsdf(&self, it: &Interaction, wo: Vec3, wl: &mut SampledWavelengths) -> Option<Bsdf> {
        let p = &self.geometry.primitives[it.primitive as usize];
        let solid = p.shape.is_closed();
        if p.vertex_materials.is_some() {
            let k = self.coefficients(it);
            let phong = Material::Phong(PhongMaterial::constant(&k));
            return match phong.scattering(&it.texture(), wl, solid, 0.5) {
                Scattering::Bxdf(b) => self.finish_bsdf(b, it),
                Scattering::Other(_) => None,
            };
        }
        if self.materials.is_one_sided(p.material) && wo.dot(it.n) < 0.0 {
            return None;
        }
        let b = self
            .materials
            .bxdf(p.material, &it.texture(), wl, solid, || hash_hit(it.p, wo))?;
        self.finish_bsdf(b, it)
    }

    fn finish_bsdf(&self, b: Bxdf, it: &Interaction) -> Option<Bsdf> {
        // The shading frame's x, along which anisotropic roughness takes its u value: around
        // the world's y axis (the scenes' up), or its x axis on surfaces facing up or down.
        // It turns continuously with the normal, so a brushed surface shows no seam.
        let n = it.shading_n;
        let around_y = Vec3::Y.cross(n);
        let hint = if around_y.length_squared() > 1e-12 {
            around_y
        } else {
            Vec3::X.cross(n)
        };
        let bsdf = Bsdf::new(n, Some(hint), b);
        (!bsdf.flags().is_empty()).then_some(bsdf)
    }
}

/// A seed from a hit point and direction, for choices that must not depend on the thread.
fn hash_hit(p: Vec3, w: Vec3) -> u64 {
    let mut h: u64 = 0x9E37_79B9_7F4A_7C15;
    for v in [p.x, p.y, p.z, w.x, w.y, w.z] {
        h = (h ^ v.to_bits()).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        h ^= h >> 31;
    }
    h
}
