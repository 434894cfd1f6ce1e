//! What photon mapping (Jensen 1996) and stochastic progressive photon mapping (Hachisuka and
//! Jensen 2009) share: photon paths traced from the lights, and the eye side's direct light.
//!
//! A photon path is the light tracer's path without the camera connections
//! ([`super::light_path`]): every arrival on a surface with a diffuse or glossy lobe is
//! handed to the caller, which stores it (a photon map) or splats it onto the visible
//! points near it (SPPM).
//!
//! Depth: a photon's `depth` counts its surface vertices from the light, 1 for the first
//! hit. An eye vertex at depth e (1: the camera ray's hit) joined to a photon of depth d makes
//! a path of e + d − 1 scattering vertices; the path tracer's longest have `max_depth` + 1,
//! so the photon methods use a photon at an eye vertex only where d ≤ `max_depth` + 2 − e,
//! and render the same paths as the path tracer.

pub(super) use super::light_path::Arrival;
use super::light_path::LightPaths;
use super::{IntegratorConfig, RayCounts, RayKind};
use crate::camera::Camera;
use crate::math::Vec3;
use crate::sampling::{Rng, SampleStream};
use crate::scene::{Interaction, Scene};
use plenum_spectrum::{SampledSpectrum, SampledWavelengths};

/// Traces photon paths through one scene: light paths whose rays count as photon rays.
pub(super) struct PhotonTracer<'a> {
    paths: LightPaths<'a>,
}

impl<'a> PhotonTracer<'a> {
    pub fn new(scene: &'a Scene, config: &IntegratorConfig, camera: &Camera) -> Self {
        PhotonTracer {
            paths: LightPaths::new(scene, config, camera),
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
        let Some(start) = self.paths.start(wl, stream) else {
            return;
        };
        let kind = RayKind::Photon;
        self.paths.walk(
            &start,
            time,
            wl,
            stream,
            counts,
            kind,
            None,
            |a, wl, _, _, _| arrive(a, wl),
        );
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
    if let Some(light) = scene.area_light(prim) {
        if scene.lights[light as usize].emits_toward(it.n, wo) {
            return scene.lights.emitted(light, &it.texture(), wl);
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
        for &i in &scene.lights.infinite {
            le += scene.lights.radiance_from_infinity(i, d, wl);
        }
    }
    le
}
