//! What photon mapping (Jensen 1996) and stochastic progressive photon mapping (Hachisuka and
//! Jensen 2009) share: photon paths traced from the lights, and the eye side's direct light.
//!
//! A photon path is the light tracer's path without the camera connections: a light chosen
//! by power, a ray from its emission (pbrt-v4's `SampleLe`), scattering by the adjoint BSDF
//! with Veach's shading-normal correction, Russian roulette on the throughput. Every arrival
//! on a surface with a diffuse or glossy lobe is handed to the caller, which stores it (a
//! photon map) or splats it onto the visible points near it (SPPM).
//!
//! Depth: a photon's `depth` counts its surface vertices from the light, 1 for the first
//! hit. An eye vertex at depth e (1: the camera ray's hit) joined to a photon of depth d makes
//! a path of e + d − 1 scattering vertices; the path tracer's longest have `max_depth` + 1,
//! so the photon methods use a photon at an eye vertex only where d ≤ `max_depth` + 2 − e,
//! and render the same paths as the path tracer.

use super::light_tracing::{adjoint_cosine, leave_light, start_light_path};
use super::{IntegratorConfig, RayCounts};
use crate::bxdf::TransportMode;
use crate::math::{offset_ray_origin, Ray, Vec3};
use crate::sampling::{Rng, SampleStream};
use crate::scene::{Interaction, Scene};
use plenum_spectrum::{SampledSpectrum, SampledWavelengths};

/// A photon arriving at a surface that can scatter it diffusely or glossily.
pub(super) struct Arrival<'a> {
    pub it: &'a Interaction,
    /// Unit direction back toward where the photon came from (the BSDF's ωi).
    pub wi: Vec3,
    /// The photon's flux weight: the emitted power over the sampling densities, not yet
    /// divided by the number of photon paths.
    pub beta: SampledSpectrum,
    /// Surface vertices from the light, 1 for the first hit.
    pub depth: u32,
    /// Only specular bounces since the light (and at least one): a caustic photon, L S+ D.
    pub caustic: bool,
    /// The path may still make caustics further on: no diffuse or glossy bounce since the
    /// light, and the surface has a specular lobe to leave by (Phong glass, a mirror with a
    /// highlight).
    pub may_continue_caustic: bool,
}

/// Traces photon paths through one scene.
pub(super) struct PhotonTracer<'a> {
    scene: &'a Scene,
    max_depth: u32,
    rr_depth: u32,
    center: Vec3,
    radius: f64,
}

impl<'a> PhotonTracer<'a> {
    pub fn new(scene: &'a Scene, config: &IntegratorConfig) -> Self {
        let (center, radius) = scene.bounding_sphere();
        PhotonTracer {
            scene,
            max_depth: config.max_depth,
            rr_depth: config.rr_depth,
            center,
            radius,
        }
    }

    /// The random numbers of photon path `index` of pass `pass`: they depend on nothing
    /// else, so a pass gives the same photons on any number of threads.
    pub fn stream(seed: u64, pass: u32, index: u64) -> SampleStream {
        SampleStream::random(Rng::for_sample(
            seed ^ 0x5048_4f54_4f4e_5321,
            index as u32,
            (index >> 32) as u32,
            pass,
        ))
    }

    /// Traces one photon path at the wavelengths `wl` (which a dispersive interface may
    /// reduce to the hero wavelength), calling `arrive` at each diffuse or glossy surface it
    /// reaches; the path ends where `arrive` returns false.
    pub fn trace(
        &self,
        time: f64,
        wl: &mut SampledWavelengths,
        stream: &mut SampleStream,
        counts: &mut RayCounts,
        mut arrive: impl FnMut(&Arrival, &SampledWavelengths) -> bool,
    ) {
        let scene = self.scene;
        let Some(start) = start_light_path(scene, (self.center, self.radius), wl, stream) else {
            return;
        };
        let mut beta = start.beta;
        let mut ray = leave_light(&start.es).at_time(time);
        let mut specular_only = true;
        for depth in 1..=self.max_depth + 1 {
            counts.photon += 1;
            let Some((prim, hit)) = scene.intersect(&ray, f64::INFINITY) else {
                break;
            };
            let it = scene.interaction(&ray, prim, &hit);
            let wo = -ray.direction.normalized();
            let Some(bsdf) = scene.bsdf(&it, wo, wl) else {
                break;
            };
            let flags = bsdf.flags();
            if flags.is_non_specular() {
                let arrival = Arrival {
                    it: &it,
                    wi: wo,
                    beta,
                    depth,
                    caustic: specular_only && depth > 1,
                    may_continue_caustic: specular_only && flags.is_specular(),
                };
                if !arrive(&arrival, wl) {
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

/// The photon methods' density estimates count photon flux through the geometric surface;
/// radiance leaving by the shading normal's cosine needs |ωi·n_s| / |ωi·n_g| (the camera
/// side of Veach's correction, thesis §5.3).
#[inline]
pub(super) fn shading_correction(it: &Interaction, wi: Vec3) -> f64 {
    let ng = wi.dot(it.n).abs();
    if ng == 0.0 {
        return 0.0;
    }
    wi.dot(it.shading_n).abs() / ng
}

/// What an emitter hit by the camera ray or a specular chain shows toward `wo` (a light's
/// surface, or a Phong material's k_e), in full.
pub(super) fn emitted(
    scene: &Scene,
    prim: u32,
    it: &Interaction,
    wo: Vec3,
    wl: &SampledWavelengths,
) -> SampledSpectrum {
    if let Some(light) = scene.light_of(prim) {
        if scene.lights[light as usize].emits_toward(it.n, wo) {
            return scene.light_spectrum(light, wl);
        }
    } else if let Some(ke) = scene.phong_emission(it, wl) {
        return ke;
    }
    SampledSpectrum::ZERO
}

/// Radiance from infinity along `d`: the lights at infinity (the background among them)
/// where no other strategy finds them (`lights`: the ray came by specular bounces only).
pub(super) fn escaped(
    scene: &Scene,
    d: Vec3,
    wl: &SampledWavelengths,
    lights: bool,
) -> SampledSpectrum {
    let mut le = SampledSpectrum::ZERO;
    if lights {
        for &i in &scene.infinite_lights {
            le += scene.radiance_from_infinity(i, d, wl);
        }
    }
    le
}
