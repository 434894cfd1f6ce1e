//! Light tracing, the lecture's "forward ray tracing": paths start on the lights (a light
//! chosen by power, a ray drawn from its emission), scatter by the BSDFs' adjoint, and every
//! vertex that can scatter toward the camera is joined to a point on its lens and splatted
//! onto the film with the camera's importance (Arvo 1986; Veach's thesis §10.2, the t = 1
//! strategies of bidirectional path tracing; pbrt-v4's `LightPathIntegrator`).
//!
//! Each pixel sample traces one light path; a pixel is the sum of the splats landing in it
//! divided by the samples per pixel. The render loop's own camera ray is used only for its
//! time. Depth counts as the path tracer's: `max_depth` D allows paths with up to D + 1
//! surface vertices, so both methods converge to the same image.
//!
//! What it cannot render: light reaching the camera by a specular surface last (a mirror or
//! glass seen directly: the connection would need the one direction that a delta lobe
//! gives), lights at infinity seen directly, and emitters seen through a pinhole by no
//! surface at all are absent from its image; those paths are path tracing's to find.
//!
//! Shading normals: light carried from the lights scatters by the adjoint BSDF with Veach's
//! correction (thesis §5.3), f*(ωo, ωi) = f(ωo, ωi)·|ωo·n_s||ωi·n_g| / (|ωo·n_g||ωi·n_s|),
//! so smooth-shaded surfaces receive the light a camera path would find.

use super::{IntegratorConfig, RayCounts, RayKind, RayNode, RayTree};
use crate::accel::Coherence;
use crate::bxdf::TransportMode;
use crate::camera::Camera;
use crate::color::Color;
use crate::film::SplatBuffer;
use crate::light::{EmissionSample, Light};
use crate::math::{offset_ray_origin, Ray, Vec3};
use crate::sampling::SampleStream;
use crate::scene::{Interaction, Scene};
use plenum_spectrum::{ColorMode, SampledSpectrum, SampledWavelengths};

pub struct LightTracer<'a> {
    scene: &'a Scene,
    camera: &'a Camera,
    splats: &'a SplatBuffer,
    max_depth: u32,
    rr_depth: u32,
    pub(super) color: ColorMode,
    center: Vec3,
    radius: f64,
}

impl<'a> LightTracer<'a> {
    pub fn new(
        scene: &'a Scene,
        config: &IntegratorConfig,
        camera: &'a Camera,
        splats: &'a SplatBuffer,
    ) -> Self {
        let (center, radius) = scene.bounding_sphere();
        LightTracer {
            scene,
            camera,
            splats,
            max_depth: config.max_depth,
            rr_depth: config.rr_depth,
            color: config.color,
            center,
            radius,
        }
    }

    /// Traces one light path for a pixel sample, at the wavelengths `wl`, and splats what
    /// reaches the camera; the pixel's own estimate is black.
    pub(super) fn light_path(
        &self,
        time: f64,
        wl: &mut SampledWavelengths,
        stream: &mut SampleStream,
        counts: &mut RayCounts,
        mut tree: Option<&mut RayTree>,
    ) {
        let scene = self.scene;
        let Some(start) = start_light_path(scene, (self.center, self.radius), wl, stream) else {
            return;
        };
        let LightStart { index, pmf, es, .. } = start;
        let light = &scene.lights[index as usize];
        // The light's own point, seen by the camera.
        let u_lens = stream.next_2d();
        if let Some(l) = self.light_to_camera(light, index, &es, pmf, u_lens, time, wl, counts) {
            self.splat(l.0, l.1, wl, counts);
        }
        let mut beta = start.beta;
        let mut ray = leave_light(&es).at_time(time);
        let mut parent = None;
        for depth in 0..=self.max_depth {
            counts.light += 1;
            let node = tree.as_deref_mut().map(|t| {
                t.push(RayNode::new(
                    parent,
                    RayKind::Light,
                    depth,
                    ray.origin,
                    ray.direction,
                    rgb(beta, wl),
                ))
            });
            parent = node;
            let Some((prim, hit)) = scene.intersect(&ray, f64::INFINITY) else {
                break;
            };
            let it = scene.interaction(&ray, prim, &hit);
            let wo = -ray.direction.normalized();
            let Some(bsdf) = scene.bsdf(&it, wo, wl) else {
                break;
            };
            if bsdf.flags().is_non_specular() {
                if let Some(c) = self.camera.sample_wi(it.p, stream.next_2d(), time) {
                    let f =
                        bsdf.f(wo, c.wi, TransportMode::Importance) * adjoint_cosine(&it, wo, c.wi);
                    if !f.is_black() {
                        counts.connection += 1;
                        let origin = offset_ray_origin(it.p, it.p_error, it.n, c.wi);
                        let shadow = Ray::new(origin, c.lens_point - origin).at_time(time);
                        if !scene.occluded(&shadow, 1.0 - 1e-9, Coherence::Incoherent) {
                            self.splat(c.raster, beta * f * (c.we / c.pdf), wl, counts);
                        }
                    }
                }
            }
            if depth == self.max_depth {
                break;
            }
            let uc = stream.next_1d();
            let Some(bs) = bsdf.sample_f(wo, uc, stream.next_2d(), TransportMode::Importance)
            else {
                break;
            };
            beta *= bs.f * (adjoint_cosine(&it, wo, bs.wi) / bs.pdf);
            if beta.is_black() {
                break;
            }
            // Russian roulette on the throughput (importance needs no η² put back).
            let rr = beta.max_value();
            if depth + 1 > self.rr_depth && rr < 1.0 {
                let q = (1.0 - rr).max(0.0);
                if stream.next_1d() < q {
                    break;
                }
                beta /= 1.0 - q;
            }
            ray = Ray::new(offset_ray_origin(it.p, it.p_error, it.n, bs.wi), bs.wi).at_time(time);
        }
    }

    /// The emitter's sampled point joined to a lens point: its radiance (or intensity)
    /// toward the lens, times W_e, over the densities. Lights at infinity have no point.
    #[allow(clippy::too_many_arguments)]
    fn light_to_camera(
        &self,
        light: &Light,
        index: u32,
        es: &EmissionSample,
        pmf: f64,
        u_lens: [f64; 2],
        time: f64,
        wl: &SampledWavelengths,
        counts: &mut RayCounts,
    ) -> Option<([f64; 2], SampledSpectrum)> {
        if light.is_infinite() || light.is_delta_direction() {
            return None;
        }
        let q = es.ray.origin;
        let c = self.camera.sample_wi(q, u_lens, time)?;
        // c.wi points from q toward the lens.
        let geometric = match es.n {
            Some(n) => {
                if !light.emits_toward(n, c.wi) {
                    return None;
                }
                n.dot(c.wi).abs() / es.pdf.pos
            }
            None => light.spot_falloff(c.wi),
        };
        if geometric <= 0.0 {
            return None;
        }
        counts.connection += 1;
        // From the lens toward the light's point, stopping just short of its surface.
        let shadow = Ray::new(c.lens_point, q - c.lens_point).at_time(time);
        if self
            .scene
            .occluded(&shadow, 1.0 - 1e-4, Coherence::Incoherent)
        {
            return None;
        }
        let l = self.scene.light_spectrum(index, wl);
        Some((c.raster, l * (geometric * c.we / (c.pdf * pmf))))
    }

    fn splat(
        &self,
        raster: [f64; 2],
        l: SampledSpectrum,
        wl: &SampledWavelengths,
        counts: &mut RayCounts,
    ) {
        let c = rgb(l, wl);
        if !(c.r.is_finite() && c.g.is_finite() && c.b.is_finite()) {
            counts.invalid += 1;
            return;
        }
        self.splats.add(raster, c);
    }
}

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
    let (index, pmf) = scene.light_sampler.sample(ul)?;
    let es = scene.lights[index as usize].sample_le(u_pos, u_dir, center, radius)?;
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
pub(super) fn emitted_spectrum(
    scene: &Scene,
    light: u32,
    es: &EmissionSample,
    wl: &SampledWavelengths,
) -> SampledSpectrum {
    match es.radiance {
        Some(c) => scene.rgb_radiance(c, wl),
        None => scene.light_spectrum(light, wl) * es.scale,
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

/// A sample's spectrum as linear sRGB.
pub(super) fn rgb(l: SampledSpectrum, wl: &SampledWavelengths) -> Color {
    let [r, g, b] = l.to_linear_srgb(wl);
    Color::new(r, g, b)
}
