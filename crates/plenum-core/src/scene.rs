//! A scene ready to render: primitives in a BVH, materials, lights, camera and background.
//! Built once by [`SceneBuilder`]; immutable and shared by every render thread.

use crate::accel::{Accel, AccelKind, Coherence, LeafSize};
use crate::bxdf::Bsdf;
use crate::camera::CameraSettings;
use crate::color::Color;
use crate::geometry::{Disk, HitRecord, Polygon, Shape, Sphere, TriangleMesh};
use crate::light::{Emitter, Light};
use crate::light_sampler::{LightSampler, LightSamplerKind};
use crate::material::{Coefficients, Material, Scattering, SpectrumKind, SpectrumValue};
use crate::math::{gamma, Bounds3, Motion, Ray, Transform, Vec3};
use crate::sampling::Rng;
use crate::texture::TextureCoords;
use plenum_spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};
use std::sync::Arc;

pub use crate::material::MaterialId;

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
    /// Per material: it scatters only on the side its surface's normal points to (Mitsuba's
    /// convention; pbrt's, the default, scatters on both).
    one_sided: Vec<bool>,
    /// Per primitive: its material looks something up by texture coordinates.
    needs_uv: Vec<bool>,
    /// I_a: the sum of the scene's ambient lights.
    pub ambient: Color,
    /// Radiance of rays that hit nothing: Whitted's model reads it here; the physically based
    /// methods see it as the light `background_light`.
    pub background: Color,
    /// The background as a light (a uniform infinite light, the last of `lights`), where it
    /// is not black.
    pub background_light: Option<u32>,
    /// Per light: its emission as a spectrum (an RGB light's uplifted as an illuminant).
    light_spectra: Vec<SpectrumValue>,
    /// Per primitive: the area light it is the surface of.
    primitive_lights: Vec<Option<u32>>,
    /// The lights at infinity, which rays that hit nothing see.
    pub infinite_lights: Vec<u32>,
    /// Chooses a light for next-event estimation.
    pub light_sampler: LightSampler,
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

    /// The structures that had to bound their cells' references (see `Grid::capped`,
    /// `Octree::capped`), named for a warning: "the scene's primitives" or the objects whose
    /// mesh it is.
    pub fn capped_structures(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.accel.capped() {
            out.push("the scene's primitives".to_string());
        }
        let mut seen = std::collections::HashSet::new();
        for (p, name) in self.primitives.iter().zip(&self.object_names) {
            if let Shape::Mesh(m) = &p.shape {
                if seen.insert(Arc::as_ptr(m)) && m.accel_capped() {
                    out.push(format!("the triangles of `{name}`"));
                }
            }
        }
        out
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
                (weights[i], m.coefficients(&it.texture))
            });
            return Coefficients::blend(&parts);
        }
        self.coefficients_of(
            self.primitives[it.primitive as usize].material,
            &it.texture,
            0,
        )
    }

    /// Material `id`'s coefficients; a mix blends its two materials' by its amount (a few
    /// mixes deep; a deeper one gives its first material's).
    fn coefficients_of(&self, id: MaterialId, at: &TextureCoords, depth: u32) -> Coefficients {
        match &self.materials[id as usize] {
            Material::Mix { materials, amount } if depth < 16 => {
                let a = amount.evaluate(at).clamp(0.0, 1.0);
                Coefficients::blend(&[
                    (1.0 - a, self.coefficients_of(materials[0], at, depth + 1)),
                    (a, self.coefficients_of(materials[1], at, depth + 1)),
                ])
            }
            m => m.coefficients(at),
        }
    }

    /// Whether material `id` scatters only on its normals' side.
    pub fn is_one_sided(&self, id: MaterialId) -> bool {
        self.one_sided[id as usize]
    }

    /// The area light whose surface the primitive is.
    #[inline]
    pub fn light_of(&self, primitive: u32) -> Option<u32> {
        self.primitive_lights[primitive as usize]
    }

    /// Light `light`'s emission as a spectrum (with its RGB value).
    pub fn light_emission(&self, light: u32) -> &SpectrumValue {
        &self.light_spectra[light as usize]
    }

    /// Light `light`'s radiance (or intensity) at the sample's wavelengths.
    #[inline]
    pub fn light_spectrum(&self, light: u32, wl: &SampledWavelengths) -> SampledSpectrum {
        self.light_spectra[light as usize].sample(wl)
    }

    /// Radiance given as linear RGB (an environment map's), as an illuminant spectrum at
    /// the sample's wavelengths.
    #[inline]
    pub fn rgb_radiance(&self, c: Color, wl: &SampledWavelengths) -> SampledSpectrum {
        if wl.is_rgb() {
            SampledSpectrum([c.r, c.g, c.b, 0.0])
        } else {
            crate::material::uplift_illuminant(c, wl)
        }
    }

    /// What light `light`, one at infinity, sends along -`d` toward the scene.
    pub fn radiance_from_infinity(
        &self,
        light: u32,
        d: Vec3,
        wl: &SampledWavelengths,
    ) -> SampledSpectrum {
        match &self.lights[light as usize] {
            Light::Environment { map, .. } => {
                let [r, g, b] = map.map.radiance(d);
                self.rgb_radiance(Color::new(r, g, b), wl)
            }
            _ => self.light_spectrum(light, wl),
        }
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
        Some(self.rgb_radiance(m.emissive.evaluate(&it.texture), wl))
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
        !self.primitives.is_empty()
            && self.primitives.iter().all(|p| {
                p.vertex_materials.is_none() && {
                    let m = &self.materials[p.material as usize];
                    m.is_physical() || m.is_emitter_only()
                }
            })
    }

    /// What in the scene varies with wavelength beyond what RGB can carry (a dispersive
    /// index, a measured spectrum), named for a warning; `None` if nothing does.
    pub fn needs_wavelengths(&self) -> Option<String> {
        for (m, name) in self.materials.iter().zip(&self.material_names) {
            if let Some(what) = m.wavelength_dependence() {
                return Some(format!("material `{name}` ({what})"));
            }
        }
        None
    }

    /// Chooses how next-event estimation picks lights.
    pub fn set_light_sampler(&mut self, kind: LightSamplerKind) {
        self.light_sampler = match kind {
            LightSamplerKind::Uniform => LightSampler::uniform(self.lights.len()),
            LightSamplerKind::Power => {
                let radius = self.scene_radius();
                let powers: Vec<f64> = self.lights.iter().map(|l| l.power(radius)).collect();
                LightSampler::new(&powers)
            }
        };
    }

    /// The centre of everything bounded (the origin for an empty scene) and the radius of a
    /// sphere about it: where light from infinity enters the scene.
    pub fn bounding_sphere(&self) -> (Vec3, f64) {
        let b = self.bounds();
        let center = if b.min.x.is_finite() && b.max.x.is_finite() {
            (b.min + b.max) * 0.5
        } else {
            Vec3::ZERO
        };
        (center, self.scene_radius())
    }

    /// The radius of a sphere about everything bounded (1 for an empty scene).
    pub fn scene_radius(&self) -> f64 {
        let b = self.bounds();
        let r = 0.5 * (b.max - b.min).length();
        if r.is_finite() && r > 0.0 {
            r
        } else {
            1.0
        }
    }

    /// The BSDF at a hit seen from `wo`, for the sample's wavelengths; `None` where nothing
    /// scatters (an emitter's surface). Per-vertex Phong materials are blended first; a mix
    /// chooses by a hash of the hit and `wo`, so the choice is the same for any thread.
    pub fn bsdf(&self, it: &Interaction, wo: Vec3, wl: &mut SampledWavelengths) -> Option<Bsdf> {
        let p = &self.primitives[it.primitive as usize];
        let solid = p.shape.is_closed();
        if p.vertex_materials.is_some() {
            let k = self.coefficients(it);
            let phong = Material::Phong(crate::material::PhongMaterial::constant(&k));
            return match phong.scattering(&it.texture, wl, solid, 0.5) {
                Scattering::Bxdf(b) => self.finish_bsdf(b, it),
                Scattering::Other(_) => None,
            };
        }
        let mut id = p.material;
        if self.one_sided[id as usize] && wo.dot(it.n) < 0.0 {
            return None;
        }
        // Mixes of mixes, a few deep; a cycle (which the scene reader refuses) ends here.
        let mut rng = None;
        for _ in 0..16 {
            let m = &self.materials[id as usize];
            let u = match m {
                Material::Mix { .. } => rng
                    .get_or_insert_with(|| Rng::new(hash_hit(it.p, wo), 0))
                    .uniform(),
                _ => 0.5,
            };
            match m.scattering(&it.texture, wl, solid, u) {
                Scattering::Bxdf(b) => return self.finish_bsdf(b, it),
                Scattering::Other(next) => id = next,
            }
        }
        None
    }

    fn finish_bsdf(&self, b: crate::bxdf::Bxdf, it: &Interaction) -> Option<Bsdf> {
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
    /// Per light: a spectrum given in place of its RGB value, and a scale.
    light_spectra: Vec<Option<(Spectrum, f64)>>,
    one_sided: Vec<MaterialId>,
    light_sampler: LightSamplerKind,
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

impl SceneBuilder {
    /// Gives the last light added a spectrum (an illuminant) in place of its RGB value; its
    /// RGB value is then that spectrum's, for Whitted's model and RGB mode.
    pub fn set_last_light_spectrum(&mut self, spectrum: Spectrum, scale: f64) {
        if let Some(s) = self.light_spectra.last_mut() {
            *s = Some((spectrum, scale));
        }
    }

    /// Makes the last light added, an area light, emit only toward its normal's side.
    pub fn set_last_light_one_sided(&mut self) {
        if let Some(Light::Area { two_sided, .. }) = self.lights.last_mut() {
            *two_sided = false;
        }
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
            },
        );
        if let Some(last) = self.light_objects.last_mut() {
            *last = Some((self.primitives.len() - 1) as u32);
        }
        true
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
                two_sided: true,
            },
        );
        if let Some(last) = self.light_objects.last_mut() {
            *last = object;
        }
    }

    pub fn add_light(&mut self, name: impl Into<String>, light: Light) {
        self.lights.push(light);
        self.light_names.push(name.into());
        self.light_objects.push(None);
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
        // A light given as a spectrum shows that spectrum's RGB in Whitted's model.
        for (light, spectrum) in self.lights.iter_mut().zip(&self.light_spectra) {
            if let Some((s, scale)) = spectrum {
                let [r, g, b] = s.to_rgb_illuminant();
                light.set_rgb(Color::new(r, g, b) * *scale);
            }
        }
        let light_spectra = self
            .lights
            .iter()
            .zip(&self.light_spectra)
            .map(|(l, s)| match s {
                Some((s, scale)) => {
                    SpectrumValue::new(crate::material::scaled(s, *scale), SpectrumKind::Illuminant)
                }
                None => SpectrumValue::from_rgb(l.rgb(), SpectrumKind::Illuminant),
            })
            .collect();
        let mut primitive_lights = vec![None; self.primitives.len()];
        for (i, o) in self.light_objects.iter().enumerate() {
            if let Some(p) = o {
                primitive_lights[*p as usize] = Some(i as u32);
            }
        }
        let infinite_lights = (0..self.lights.len() as u32)
            .filter(|&i| self.lights[i as usize].is_infinite())
            .collect();
        let mut one_sided = vec![false; self.materials.len()];
        for &id in &self.one_sided {
            if let Some(o) = one_sided.get_mut(id as usize) {
                *o = !self.materials[id as usize].is_transmissive();
            }
        }
        let mut scene = Scene {
            one_sided,
            background_light,
            light_spectra,
            primitive_lights,
            infinite_lights,
            light_sampler: LightSampler::default(),
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
        scene.set_light_sampler(self.light_sampler);
        if kind == AccelKind::Bvh {
            scene
        } else {
            scene.with_accel(kind)
        }
    }
}
