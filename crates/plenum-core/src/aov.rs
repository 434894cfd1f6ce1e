//! What the camera's rays first meet, pixel by pixel: the normal, albedo and position
//! images (`--aov normal,albedo,position`) that a denoiser reads beside the render and that
//! show a student what each pixel looks at. A pixel is the filter-weighted mean over the
//! camera rays of its own samples, the rays the render traces, so edges are anti-aliased
//! as in the image; a ray that meets nothing gives zeros.

use crate::camera::Camera;
use crate::math::Vec3;
use crate::render::camera_sample;
use crate::sampling::SampleStream;
use crate::scene::Scene;
use crate::settings::{Adaptive, RenderSettings};
use plenum_spectrum::SampledWavelengths;
use rayon::prelude::*;

/// The first hits' images, row by row from the top, of the size the render writes.
#[derive(Clone, Debug, Default)]
pub struct FirstHits {
    pub width: u32,
    pub height: u32,
    /// The unit shading normal at the hit, in world space (outward for solids).
    pub normal: Vec<[f32; 3]>,
    /// The fraction of light the surface scatters from the camera's direction, over all
    /// directions: its directional albedo, linear sRGB (1 for clear glass, as denoisers
    /// expect).
    pub albedo: Vec<[f32; 3]>,
    /// The hit point, in world space.
    pub position: Vec<[f32; 3]>,
}

/// BSDF samples per hit for its albedo.
const ALBEDO_SAMPLES: u32 = 16;

/// The first hits of `settings`' render of `scene` (its size, crop, sampler, filter and
/// seed). Adaptive sampling takes its first batch; adaptive subdivision and the SPD
/// corners, which place their rays by other means, the sampler's samples.
pub fn first_hits(scene: &Scene, settings: &RenderSettings) -> FirstHits {
    let camera = Camera::new(&scene.camera, settings.width, settings.height);
    let (w, h) = settings.image_size();
    let (ox, oy) = settings.image_origin();
    let spp = match settings.adaptive {
        Some(Adaptive::Variance { min_spp, .. }) => min_spp,
        _ => settings.sampler.samples_per_pixel(),
    };
    let pixels: Vec<[[f32; 3]; 3]> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % w + ox, i / w + oy);
            let mut sum = [Vec3::ZERO; 3];
            let mut weight = 0.0;
            for index in 0..spp {
                let (ray, w, mut stream) = camera_sample(&camera, settings, (x, y), index);
                weight += w;
                let Some((prim, hit)) = scene.geometry.intersect(&ray, f64::INFINITY) else {
                    continue;
                };
                let it = scene.geometry.interaction(&ray, prim, &hit);
                let wo = -ray.direction.normalized();
                let albedo = albedo(scene, &it, wo, &mut stream);
                for (s, v) in sum.iter_mut().zip([it.shading_n, albedo, it.p]) {
                    *s += v * w;
                }
            }
            let mean = |v: Vec3| {
                if weight == 0.0 {
                    [0.0; 3]
                } else {
                    let m = v / weight;
                    [m.x as f32, m.y as f32, m.z as f32]
                }
            };
            sum.map(mean)
        })
        .collect();
    let layer = |k: usize| pixels.iter().map(|p| p[k]).collect();
    FirstHits {
        width: w,
        height: h,
        normal: layer(0),
        albedo: layer(1),
        position: layer(2),
    }
}

/// The directional albedo of the surface at `it` seen from `wo`: the mean of f·|cos θ|/p
/// over BSDF samples (exact for a smooth surface's one or two delta lobes), in RGB.
fn albedo(
    scene: &Scene,
    it: &crate::scene::Interaction,
    wo: Vec3,
    stream: &mut SampleStream,
) -> Vec3 {
    let mut wl = SampledWavelengths::rgb();
    let Some(bsdf) = scene.bsdf(it, wo, &mut wl) else {
        return Vec3::ZERO;
    };
    let mut sum = Vec3::ZERO;
    // Importance, not radiance: radiance through a refraction is scaled by 1/η², the
    // energy it carries is not.
    let mode = crate::bxdf::TransportMode::Importance;
    for _ in 0..ALBEDO_SAMPLES {
        let (uc, u) = (stream.next_1d(), stream.next_2d());
        if let Some(s) = bsdf.sample_f(wo, uc, u, mode) {
            let [r, g, b] = (s.f * (s.wi.dot(it.shading_n).abs() / s.pdf)).to_linear_srgb(&wl);
            sum += Vec3::new(r, g, b);
        }
    }
    sum / ALBEDO_SAMPLES as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kit;
    use crate::sampling::{PixelSampler, SamplerKind};

    /// The floor under the kit's lamp: every pixel sees the plane y = 0 (normal +Y,
    /// position on it), of albedo 0.5 in every channel; 8 × 8 pixels of 4 samples, a crop of
    /// it the same pixels.
    #[test]
    fn first_hits_see_the_floor_as_it_is() {
        let scene = kit::lamp_over_floor(0.5, true);
        let settings = RenderSettings {
            width: 8,
            height: 8,
            sampler: PixelSampler::new(SamplerKind::Random, 4),
            seed: 1,
            ..RenderSettings::default()
        };
        let hits = first_hits(&scene, &settings);
        assert_eq!(hits.normal.len(), 64);
        for i in 0..64 {
            let (n, a, p) = (hits.normal[i], hits.albedo[i], hits.position[i]);
            assert!((n[1] - 1.0).abs() < 1e-6 && n[0].abs() < 1e-6, "{n:?}");
            assert!(a.iter().all(|c| (c - 0.5).abs() < 1e-3), "{a:?}");
            assert!(p[1].abs() < 1e-6 && p[0].abs() < 2.0, "{p:?}");
        }
        let crop = RenderSettings {
            crop: Some(crate::settings::Crop {
                x0: 2,
                x1: 5,
                y0: 4,
                y1: 8,
            }),
            ..settings
        };
        let part = first_hits(&scene, &crop);
        assert_eq!((part.width, part.height), (3, 4));
        assert_eq!(part.position[0], hits.position[4 * 8 + 2]);
        assert_eq!(part.albedo[11], hits.albedo[7 * 8 + 4]);
    }

    /// Albedo by BSDF sampling: a smooth glass ball before the camera passes or reflects all
    /// the light (1 in every channel), the kit's Cornell box's red wall its reflectance
    /// (0.6, 0.05, 0.05), within 0.5 %.
    #[test]
    fn the_albedo_of_glass_is_one_and_of_a_wall_its_reflectance() {
        use crate::camera::CameraSettings;
        use crate::geometry::{Shape, Sphere};
        use crate::material::{
            DielectricMaterial, Material, Roughness, SpectrumKind, SpectrumValue,
        };
        use crate::math::Transform;
        let mut b = crate::scene::SceneBuilder::default();
        b.camera = CameraSettings {
            position: Vec3::new(0.0, 0.0, 3.0),
            look_at: Vec3::ZERO,
            fov_degrees: 10.0,
            ..CameraSettings::default()
        };
        let glass = b.add_material(
            "glass",
            Material::Dielectric(DielectricMaterial {
                eta: SpectrumValue::from_rgb(crate::Color::gray(1.5), SpectrumKind::Unbounded),
                roughness: Roughness::SMOOTH,
            }),
        );
        let ball = Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0));
        b.add_object("ball", ball, Transform::IDENTITY, glass);
        let settings = RenderSettings {
            width: 4,
            height: 4,
            sampler: PixelSampler::new(SamplerKind::Random, 2),
            ..RenderSettings::default()
        };
        let hits = first_hits(&b.build(), &settings);
        for a in hits.albedo.iter().flatten() {
            assert!((a - 1.0).abs() < 0.005, "{:?}", hits.albedo);
        }
        let box_settings = RenderSettings {
            width: 16,
            height: 16,
            ..settings
        };
        let hits = first_hits(&kit::cornell_box(false), &box_settings);
        let red = [0.6, 0.05, 0.05];
        let walls = hits
            .albedo
            .iter()
            .filter(|a| a.iter().zip(red).all(|(c, r)| (c - r).abs() < 0.005 * r));
        assert!(walls.count() > 16, "{:?}", hits.albedo);
    }
}
