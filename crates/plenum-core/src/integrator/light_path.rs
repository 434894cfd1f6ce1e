//! Light paths, as light tracing, the photon methods and bidirectional path tracing start
//! them: a light chosen by power, a ray drawn from its emission (pbrt-v4's `SampleLe`), and
//! the walk on from there, scattering by the adjoint BSDF with Veach's shading-normal
//! correction and Russian roulette on the throughput.
//!
//! The walk hands every arrival on a surface with a diffuse or glossy lobe to its caller:
//! light tracing joins it to the camera, photon mapping stores it, SPPM splats it onto the
//! visible points near it.

use super::{RayCounts, RayKind, RayNode, RayTree};
use crate::bxdf::{Bsdf, TransportMode};
use crate::camera::Camera;
use crate::light::EmissionSample;
use crate::material::rgb_radiance;
use crate::math::{offset_ray_origin, Ray, Vec3};
use crate::sampling::SampleStream;
use crate::scene::{Interaction, Scene};
use crate::settings::IntegratorConfig;
use plenum_spectrum::{SampledSpectrum, SampledWavelengths};

/// The start of a light path: a light chosen by power, a ray leaving it, the light the ray
/// carries, and the path's throughput over its first segment, Le·|cos θ| / (p_light·p_pos·p_dir).
pub(super) struct LightStart {
    pub index: u32,
    pub pmf: f64,
    pub es: EmissionSample,
    pub le: SampledSpectrum,
    pub beta: SampledSpectrum,
}

/// Draws a [`LightStart`] from three of the stream's dimensions (light, position,
/// direction), in the scene's bounding sphere (`center`, `radius`); `None` if it carries
/// nothing.
pub(super) fn start_light_path(
    scene: &Scene,
    (center, radius): (Vec3, f64),
    wl: &SampledWavelengths,
    stream: &mut SampleStream,
) -> Option<LightStart> {
    let ul = stream.next_1d();
    let (u_pos, u_dir) = (stream.next_2d(), stream.next_2d());
    let (index, pmf) = scene.lights.sampler.sample(ul)?;
    let light = &scene.lights[index as usize];
    let mut es = light.sample_le(u_pos, u_dir, center, radius)?;
    if light.is_infinite() || light.is_delta_direction() {
        es.ray = scene.geometry.from_infinity(es.ray);
    }
    let le = emitted_spectrum(scene, index, &es, wl);
    if le.is_black() || es.pdf.pos == 0.0 || es.pdf.dir == 0.0 {
        return None;
    }
    let cos = es.n.map_or(1.0, |n| n.dot(es.ray.direction).abs());
    let beta = le * (cos / (pmf * es.pdf.pos * es.pdf.dir));
    Some(LightStart {
        index,
        pmf,
        es,
        le,
        beta,
    })
}

/// The light a sampled emission ray carries: the light's spectrum times its falloff, or an
/// environment map's radiance.
fn emitted_spectrum(
    scene: &Scene,
    light: u32,
    es: &EmissionSample,
    wl: &SampledWavelengths,
) -> SampledSpectrum {
    match es.radiance {
        Some(c) => rgb_radiance(c, wl),
        None => scene.lights.spectrum(light, wl) * es.scale,
    }
}

/// The ray leaving a light, its origin lifted off an emitting surface by the rounding of
/// the single-precision meshes that surface may be made of.
pub(super) fn leave_light(es: &EmissionSample) -> Ray {
    let Some(n) = es.n else {
        return es.ray;
    };
    let p = es.ray.origin;
    let scale = p.x.abs().max(p.y.abs()).max(p.z.abs()).max(1.0);
    let error = Vec3::splat(4.0 * f32::EPSILON as f64 * scale);
    Ray::new(
        offset_ray_origin(p, error, n, es.ray.direction),
        es.ray.direction,
    )
}

/// |ωi·n_s| for a path carrying importance, with Veach's shading-normal correction:
/// |ωo·n_s||ωi·n_g| / |ωo·n_g| (thesis §5.3; the |ωi·n_s| of the cosine cancels).
pub(super) fn adjoint_cosine(it: &Interaction, wo: Vec3, wi: Vec3) -> f64 {
    adjoint_cosine_of(it.n, it.shading_n, wo, wi)
}

/// [`adjoint_cosine`] for the geometric normal `n` and shading normal `ns`.
pub(super) fn adjoint_cosine_of(n: Vec3, ns: Vec3, wo: Vec3, wi: Vec3) -> f64 {
    let wo_ng = wo.dot(n).abs();
    if wo_ng == 0.0 {
        return 0.0;
    }
    wo.dot(ns).abs() * wi.dot(n).abs() / wo_ng
}

/// A light path arriving at a surface that can scatter it diffusely or glossily.
pub(super) struct Arrival<'a> {
    pub it: &'a Interaction,
    pub bsdf: &'a Bsdf,
    /// Unit direction back toward where the path came from (the BSDF's ωi for radiance,
    /// its ωo for the importance the path carries).
    pub wi: Vec3,
    /// The path's throughput: the emitted power over the sampling densities.
    pub beta: SampledSpectrum,
    /// Surface vertices from the light, 1 for the first hit.
    pub depth: u32,
    /// The ray tree's node of the ray that arrived, where a tree is recorded.
    pub node: Option<usize>,
    /// Only specular bounces since the light (and at least one): a caustic, L S+ D.
    pub caustic: bool,
    /// The path may still make caustics further on: no diffuse or glossy bounce since the
    /// light, and the surface has a specular lobe to leave by (Phong glass, a mirror with a
    /// highlight).
    pub may_continue_caustic: bool,
}

/// Walks light paths through one scene.
pub(super) struct LightPaths<'a> {
    scene: &'a Scene,
    max_depth: u32,
    rr_depth: u32,
    center: Vec3,
    radius: f64,
}

impl<'a> LightPaths<'a> {
    /// Light paths of `scene` for a render through `camera` (which sets where light from
    /// infinity enters: [`crate::scene::Geometry::entry_sphere`]).
    pub fn new(scene: &'a Scene, config: &IntegratorConfig, camera: &Camera) -> Self {
        let (center, radius) = scene.geometry.entry_sphere(camera);
        LightPaths {
            scene,
            max_depth: config.max_depth,
            rr_depth: config.rr_depth,
            center,
            radius,
        }
    }

    /// Draws the start of a path ([`start_light_path`]).
    pub fn start(&self, wl: &SampledWavelengths, stream: &mut SampleStream) -> Option<LightStart> {
        start_light_path(self.scene, (self.center, self.radius), wl, stream)
    }

    /// Walks the path from `start` at the wavelengths `wl` (which a dispersive interface
    /// may reduce to the hero wavelength), through up to `max_depth` + 1 surface vertices,
    /// calling `arrive` at each diffuse or glossy one; the walk ends where `arrive` returns
    /// false. Its rays count as `kind` (light or photon rays) and, with `tree`, are
    /// recorded there.
    #[allow(clippy::too_many_arguments)]
    pub fn walk(
        &self,
        start: &LightStart,
        time: f64,
        wl: &mut SampledWavelengths,
        stream: &mut SampleStream,
        counts: &mut RayCounts,
        kind: RayKind,
        mut tree: Option<&mut RayTree>,
        mut arrive: impl FnMut(
            &Arrival,
            &SampledWavelengths,
            &mut SampleStream,
            &mut RayCounts,
            Option<&mut RayTree>,
        ) -> bool,
    ) {
        let scene = self.scene;
        let mut beta = start.beta;
        let mut ray = leave_light(&start.es).at_time(time);
        let mut specular_only = true;
        let mut parent = None;
        for depth in 1..=self.max_depth + 1 {
            match kind {
                RayKind::Photon => counts.photon += 1,
                _ => counts.light += 1,
            }
            if let Some(t) = tree.as_deref_mut() {
                let c = super::weight_rgb(beta, wl);
                parent = Some(t.push(RayNode::new(
                    parent,
                    kind,
                    depth - 1,
                    ray.origin,
                    ray.direction,
                    c,
                )));
            }
            let Some((prim, hit)) = scene.geometry.intersect(&ray, f64::INFINITY) else {
                break;
            };
            let it = scene.geometry.interaction(&ray, prim, &hit);
            let wo = -ray.direction.normalized();
            let Some(bsdf) = scene.bsdf(&it, wo, wl) else {
                break;
            };
            let flags = bsdf.flags();
            if flags.is_non_specular() {
                let arrival = Arrival {
                    it: &it,
                    bsdf: &bsdf,
                    wi: wo,
                    beta,
                    depth,
                    node: parent,
                    caustic: specular_only && depth > 1,
                    may_continue_caustic: specular_only && flags.is_specular(),
                };
                if !arrive(&arrival, wl, stream, counts, tree.as_deref_mut()) {
                    break;
                }
            }
            if depth == self.max_depth + 1 {
                break;
            }
            let uc = stream.next_1d();
            let Some(bs) = bsdf.sample_f(wo, uc, stream.next_2d(), TransportMode::Importance)
            else {
                break;
            };
            beta *= bs.f * (adjoint_cosine(&it, wo, bs.wi) / bs.pdf);
            specular_only &= bs.is_specular();
            if beta.is_black() {
                break;
            }
            // Russian roulette on the throughput (importance needs no η² put back).
            let rr = beta.max_value();
            if depth > self.rr_depth && rr < 1.0 {
                let q = (1.0 - rr).max(0.0);
                if stream.next_1d() < q {
                    break;
                }
                beta /= 1.0 - q;
            }
            ray = Ray::new(offset_ray_origin(it.p, it.p_error, it.n, bs.wi), bs.wi).at_time(time);
        }
    }
}
