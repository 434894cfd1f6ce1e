//! Integrators: turn a camera ray into the radiance it carries back.
//!
//! The render loop ([`crate::render`]) does not know which integrator it drives: it asks
//! [`Integrator::camera_ray`] for each camera sample (pbrt-v4's `RayIntegrator::Li` under its
//! `ImageTileIntegrator`). The integrator is chosen once per render, and dispatched by `match`.
//! A method whose image is not a sum of pixel samples (SPPM's iterations) renders by a loop
//! of its own, which the render loop finds through [`whole_image`] (pbrt-v4's integrators
//! that override `Render`).

mod bdpt;
mod direct;
mod eye_path;
mod light_path;
mod light_tracing;
mod medium;
mod path;
mod photon;
pub mod photon_map;
mod photons;
mod ray_tree;
mod sppm;
mod whitted;

pub use bdpt::{BidirectionalPathTracer, StrategyImages};
pub use light_tracing::LightTracer;
pub use medium::MediumStack;
pub use path::PathTracer;
pub use photon::PhotonMapper;
pub use ray_tree::{
    FoundPhoton, Optics, PhotonGather, RayKind, RayNode, RayTree, ShadowInfo, Stop, Strategy,
};
pub use whitted::{Whitted, WhittedConfig};

use crate::camera::Camera;
use crate::color::Color;
use crate::film::SplatBuffer;
use crate::math::Ray;
use crate::raw_film::RawFilm;
use crate::sampling::SampleStream;
use crate::scene::Scene;
pub use crate::settings::{
    ColorMode, IntegratorConfig, IntegratorKind, PhotonConfig, RayCounts, MAX_DEPTH, MAX_NEAREST,
};
use crate::settings::{RenderControl, RenderOutput, RenderSettings};
use plenum_spectrum::{SampledSpectrum, SampledWavelengths};

impl IntegratorKind {
    /// The method a scene renders with unless told: `path` for a scene of physically
    /// based materials only, `whitted` otherwise.
    pub fn default_for(scene: &Scene) -> IntegratorKind {
        if scene.is_physically_based() {
            IntegratorKind::Path
        } else {
            IntegratorKind::Whitted
        }
    }
}

/// A sample's wavelengths: drawn from the stream's next number in spectral mode (so the
/// sampler stratifies them across a pixel's samples), the RGB lanes otherwise.
pub(crate) fn sample_wavelengths(
    color: ColorMode,
    stream: &mut SampleStream,
) -> SampledWavelengths {
    match color {
        ColorMode::Spectral => SampledWavelengths::sample_visible(stream.next_1d()),
        ColorMode::Rgb => SampledWavelengths::rgb(),
    }
}

/// A physically based method's estimate `li` at the wavelengths the stream draws, as a
/// colour; a tree notes the wavelengths.
#[inline]
fn spectral(
    color: ColorMode,
    stream: &mut SampleStream,
    mut tree: Option<&mut RayTree>,
    li: impl FnOnce(&mut SampledWavelengths, &mut SampleStream, Option<&mut RayTree>) -> SampledSpectrum,
) -> Color {
    let mut wl = sample_wavelengths(color, stream);
    if let (Some(t), ColorMode::Spectral) = (tree.as_deref_mut(), color) {
        t.wavelengths.push(*wl.lambda());
    }
    let l = li(&mut wl, stream, tree);
    rgb(l, &wl)
}

/// A method that renders the whole image by a loop of its own rather than pixel sample by
/// pixel sample: the film it needs, the render into it, and the ray tree of one pixel.
pub trait WholeImage: Sync {
    /// An empty film for `settings`.
    fn new_film(&self, settings: &RenderSettings) -> RawFilm;
    /// Renders what `film` (from `new_film`, or a checkpoint of it) does not yet hold, then
    /// the image of all it holds.
    fn render_film(
        &self,
        scene: &Scene,
        settings: &RenderSettings,
        film: &mut RawFilm,
        control: RenderControl,
    ) -> RenderOutput;
    /// The ray tree of pixel (x, y), and the pixel's colour.
    fn trace_pixel(
        &self,
        scene: &Scene,
        settings: &RenderSettings,
        x: u32,
        y: u32,
    ) -> (RayTree, Color);
}

/// The loop of its own that method `kind` renders by; `None` for a method whose pixels are
/// sums of pixel samples, which [`Integrator`] evaluates.
pub fn whole_image(kind: IntegratorKind) -> Option<&'static dyn WholeImage> {
    match kind {
        IntegratorKind::Sppm => Some(&sppm::Sppm),
        _ => None,
    }
}

/// The integrator of one render.
pub enum Integrator<'a> {
    Whitted(Whitted<'a>),
    Path(PathTracer<'a>),
    Light(LightTracer<'a>),
    Bdpt(BidirectionalPathTracer<'a>),
    Photon(Box<PhotonMapper<'a>>),
}

impl<'a> Integrator<'a> {
    /// The integrator for `config`; those that splat add to `splats`, through `camera`;
    /// bidirectional path tracing also writes each strategy's image to `strategies`.
    /// Photon mapping traces its photon pass here, its random numbers from `seed`.
    pub fn new(
        scene: &'a Scene,
        config: &IntegratorConfig,
        camera: &'a Camera,
        splats: &'a SplatBuffer,
        strategies: Option<&'a StrategyImages>,
        seed: u64,
    ) -> Self {
        match config.kind {
            IntegratorKind::Local | IntegratorKind::Appel | IntegratorKind::Whitted => {
                Integrator::Whitted(Whitted::new(scene, config.whitted()))
            }
            IntegratorKind::Path => Integrator::Path(PathTracer::new(scene, config)),
            IntegratorKind::Light => {
                Integrator::Light(LightTracer::new(scene, config, camera, splats))
            }
            IntegratorKind::Bdpt => Integrator::Bdpt(BidirectionalPathTracer::new(
                scene, config, camera, splats, strategies,
            )),
            // SPPM renders by its own loop ([`whole_image`]); were it asked for pixel samples,
            // its nearest relative would give them.
            IntegratorKind::Photon | IntegratorKind::Sppm => {
                Integrator::Photon(Box::new(PhotonMapper::new(scene, config, camera, seed)))
            }
        }
    }

    /// Linear sRGB radiance along a camera ray; `stream` gives the random numbers of its pixel
    /// sample. With `tree`, every ray traced is recorded in it.
    ///
    /// Every method's pixel sample is evaluated here alike: its wavelengths are the stream's
    /// next number (spectral mode, so that the sampler stratifies them across the pixel's
    /// samples), its radiance comes from the method, and a value that is not finite counts
    /// as invalid and adds black.
    #[inline]
    pub fn camera_ray(
        &self,
        ray: &Ray,
        stream: &mut SampleStream,
        counts: &mut RayCounts,
        tree: Option<&mut RayTree>,
    ) -> Color {
        let c = match self {
            // Whitted's model is RGB, its tree of colours: no wavelengths, no spectrum.
            Integrator::Whitted(w) => {
                counts.camera += 1;
                w.camera_ray(ray, stream, counts, tree)
            }
            Integrator::Path(p) => {
                counts.camera += 1;
                spectral(p.color, stream, tree, |wl, s, t| {
                    p.li(ray, wl, s, counts, t)
                })
            }
            // A light path per sample; what reaches the camera is splatted.
            Integrator::Light(l) => spectral(l.color, stream, tree, |wl, s, t| {
                l.light_path(ray.time, wl, s, counts, t);
                SampledSpectrum::ZERO
            }),
            Integrator::Bdpt(b) => {
                counts.camera += 1;
                spectral(b.color, stream, tree, |wl, s, t| {
                    b.li(ray, wl, s, counts, t)
                })
            }
            Integrator::Photon(p) => {
                counts.camera += 1;
                spectral(p.color, stream, tree, |wl, s, t| {
                    p.li(ray, wl, s, counts, t)
                })
            }
        };
        if !(c.r.is_finite() && c.g.is_finite() && c.b.is_finite()) {
            counts.invalid += 1;
            return Color::BLACK;
        }
        c
    }

    /// The rays traced before rendering (photon mapping's photon pass).
    pub fn pass_counts(&self) -> RayCounts {
        match self {
            Integrator::Photon(p) => p.pass_counts,
            _ => RayCounts::default(),
        }
    }
}

/// A sample's spectrum as linear sRGB.
fn rgb(l: SampledSpectrum, wl: &SampledWavelengths) -> Color {
    let [r, g, b] = l.to_linear_srgb(wl);
    Color::new(r, g, b)
}

/// A path's throughput as the ray tree shows it: the colour it filters light by, its linear
/// sRGB over that of a spectrum of 1 at the same wavelengths. A few wavelengths' estimate of
/// white is not white (a camera ray's throughput of 1 read (1.03, 0.98, 0.42)); this shows
/// it as (1, 1, 1), and is the plain colour in RGB mode.
fn weight_rgb(beta: SampledSpectrum, wl: &SampledWavelengths) -> Color {
    let white = SampledSpectrum::splat(1.0).to_linear_srgb(wl);
    let c = beta.to_linear_srgb(wl);
    let [r, g, b] = std::array::from_fn(|i| {
        if white[i].abs() > 1e-9 {
            c[i] / white[i]
        } else {
            c[i]
        }
    });
    Color::new(r, g, b)
}

/// Applies `f` to node `node` of the ray tree, where a tree is being recorded.
fn record(tree: &mut Option<&mut RayTree>, node: Option<usize>, f: impl FnOnce(&mut RayNode)) {
    if let (Some(t), Some(i)) = (tree.as_deref_mut(), node) {
        f(&mut t.nodes[i]);
    }
}

/// Records in node `node` the object and material of primitive `prim`, hit at `distance`.
fn record_hit(
    tree: &mut Option<&mut RayTree>,
    node: Option<usize>,
    scene: &Scene,
    prim: u32,
    distance: f64,
) {
    record(tree, node, |n| {
        n.object = Some(scene.geometry.names[prim as usize].clone());
        let m = scene.geometry.primitives[prim as usize].material as usize;
        n.material = Some(scene.materials.names[m].clone());
        n.distance = Some(distance);
    });
}

/// For the integrators' tests: the green channel's mean over an image of `size`² pixels,
/// `spp` random samples each (seed `seed`), with the splats of methods that write other
/// pixels.
#[cfg(test)]
pub(crate) fn test_image_mean(
    scene: &Scene,
    config: &IntegratorConfig,
    size: u32,
    spp: u32,
    seed: u64,
) -> f64 {
    use crate::sampling::Rng;
    let camera = Camera::new(&scene.camera, size, size);
    let splats = SplatBuffer::new(size, size, 1.0 / spp as f64);
    let integrator = Integrator::new(scene, config, &camera, &splats, None, seed);
    let mut film = crate::film::Film::new(size, size);
    let mut counts = RayCounts::default();
    for (x, y) in (0..size * size).map(|i| (i % size, i / size)) {
        for i in 0..spp {
            let mut stream = SampleStream::random(Rng::for_sample(seed, x, y, i));
            let (dx, dy) = (stream.next_1d(), stream.next_1d());
            let ray = camera.sample_ray(x as f64 + dx, y as f64 + dy, [0.5; 2], 0.0);
            let c = integrator.camera_ray(&ray, &mut stream, &mut counts, None);
            film.add_sample(x, y, c, 1.0);
        }
    }
    film.add_splats(&splats);
    film.resolve(1.0);
    let pixels = film.pixels();
    pixels.iter().map(|p| p[1] as f64).sum::<f64>() / pixels.len() as f64
}

/// For the integrators' tests: `kind`'s image of the kit's floor under a disk lamp and under
/// a point light, direct light only (`max_depth` 0), 16 × 16 pixels of `spp` samples (seed
/// 9), within `tolerance` (relative) of the closed forms of
/// [`crate::kit::lamp_over_floor_radiance`].
#[cfg(test)]
pub(crate) fn assert_lamp_over_floor(kind: IntegratorKind, spp: u32, tolerance: f64) {
    for point in [false, true] {
        let scene = crate::kit::lamp_over_floor(0.5, point);
        let config = IntegratorConfig {
            kind,
            max_depth: 0,
            color: plenum_spectrum::ColorMode::Rgb,
            ..IntegratorConfig::default()
        };
        let mean = test_image_mean(&scene, &config, 16, spp, 9);
        let expected = crate::kit::lamp_over_floor_image_mean(0.5, point, 16);
        assert!(
            (mean / expected - 1.0).abs() < tolerance,
            "{}, point light {point}: {mean:.5}, expected {expected:.5}",
            kind.name()
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::Film;
    use crate::kit;
    use crate::sampling::{PixelSampler, Rng, SamplerKind};
    use std::sync::atomic::AtomicBool;

    /// A ray tree shows a throughput of 1 at every wavelength as (1, 1, 1), in spectral mode
    /// too: the camera ray of every method that records one, in the kit's Cornell box, for
    /// 16 samples' wavelengths (before, four wavelengths' estimate of white, such as
    /// (1.03, 0.98, 0.42)).
    #[test]
    fn a_camera_rays_weight_is_white_in_spectral_mode() {
        use crate::sampling::Rng;
        let scene = kit::cornell_box(false);
        let camera = Camera::new(&scene.camera, 8, 8);
        let splats = SplatBuffer::new(8, 8, 1.0);
        for kind in [
            IntegratorKind::Path,
            IntegratorKind::Bdpt,
            IntegratorKind::Photon,
        ] {
            let config = IntegratorConfig {
                kind,
                color: ColorMode::Spectral,
                photon: PhotonConfig {
                    photons: 1000,
                    caustic_photons: 1000,
                    ..PhotonConfig::default()
                },
                ..IntegratorConfig::default()
            };
            let integrator = Integrator::new(&scene, &config, &camera, &splats, None, 1);
            for i in 0..16 {
                let mut stream = SampleStream::random(Rng::for_sample(1, 4, 4, i));
                let ray = camera.ray(4.5, 4.5);
                let mut tree = RayTree::default();
                let mut counts = RayCounts::default();
                integrator.camera_ray(&ray, &mut stream, &mut counts, Some(&mut tree));
                let w = tree.nodes[0].weight;
                assert!(
                    [w.r, w.g, w.b].iter().all(|c| (c - 1.0).abs() < 1e-9),
                    "{}: {w:?}",
                    kind.name()
                );
            }
        }
    }

    /// Light from infinity over two infinite planes at a right angle, a floor and a wall
    /// under a uniform sky ([`kit::corner_under_sky`], reflectances 0.5 and 0.8), against
    /// the closed form. Light paths from the sky start on a disk outside what the camera
    /// sees; started there, not beyond the planes behind it (`Geometry::from_infinity`),
    /// light from below the horizon reached the wall through the floor: light tracing's
    /// direct light came out 44 % too bright, BDPT 3.1 % at `max_depth` 2. 16 × 16 pixels,
    /// 1024 spp, seed 3: light tracing at `max_depth` 0 within 2 % (measured −0.6 %, its
    /// noise 0.4 %); path and BDPT at `max_depth` 2 within 1 % (measured −0.24 % and −0.28 %,
    /// noise 0.2 %). Photon mapping and SPPM, and light tracing beyond direct light, miss
    /// what the planes send each other from beyond that disk (docs/integrators.md).
    #[test]
    fn light_from_infinity_does_not_leak_past_infinite_planes() {
        const SIZE: u32 = 16;
        let scene = kit::corner_under_sky(0.5, 0.8);
        for (kind, depth, spp, tolerance) in [
            (IntegratorKind::Light, 0, 1024, 0.02),
            (IntegratorKind::Path, 2, 1024, 0.01),
            (IntegratorKind::Bdpt, 2, 1024, 0.01),
        ] {
            let config = IntegratorConfig {
                kind,
                max_depth: depth,
                rr_depth: 1000,
                color: ColorMode::Rgb,
                ..IntegratorConfig::default()
            };
            let mean = test_image_mean(&scene, &config, SIZE, spp, 3);
            let expected = kit::corner_under_sky_image_mean(0.5, 0.8, depth, SIZE);
            assert!(
                (mean / expected - 1.0).abs() < tolerance,
                "{}, max_depth {depth}: {mean:.4}, expected {expected:.4}",
                kind.name()
            );
        }
    }

    /// Every method counts emission and depth alike: in a furnace of reflectance ½ and
    /// emission 1, `max_depth` D gives Σ_{k≤D+1} 2^−k (D + 1 scattering vertices, the
    /// emitter met after the last; D = 0 is direct light, Mitsuba's `max_depth` 2).
    /// Means over 8×8 pixels, seed 5, without Russian roulette; one bounce more or less is
    /// 7 % or more at D ≤ 1. Path and BDPT, 16 spp: within 0.2 % (measured: 0 and 0.06 %);
    /// light tracing, 64 spp: within 1 % (0.42 %); photon mapping, 20,000 photon paths and
    /// k = 200 (a density estimate is exact for light spread evenly, as here), 4 spp: within
    /// 1 % (0.18 %); SPPM, 16 iterations of 20,000 photon paths: within 1 % (0.13 %).
    #[test]
    fn every_method_counts_emission_and_depth_alike_in_a_furnace() {
        const SIZE: u32 = 8;
        let scene = kit::furnace(0.5, 1.0);
        for depth in [0, 1, 3] {
            let expected: f64 = (0..=depth + 1).map(|k| 0.5f64.powi(k as i32)).sum();
            for (kind, spp, tolerance) in [
                (IntegratorKind::Path, 16, 0.002),
                (IntegratorKind::Bdpt, 16, 0.002),
                (IntegratorKind::Light, 64, 0.01),
                (IntegratorKind::Photon, 4, 0.01),
            ] {
                let config = IntegratorConfig {
                    kind,
                    max_depth: depth,
                    rr_depth: 1000,
                    color: ColorMode::Rgb,
                    photon: PhotonConfig {
                        photons: 20_000,
                        caustic_photons: 0,
                        nearest: 200,
                        ..PhotonConfig::default()
                    },
                    ..IntegratorConfig::default()
                };
                let mean = test_image_mean(&scene, &config, SIZE, spp, 5);
                assert!(
                    (mean / expected - 1.0).abs() < tolerance,
                    "{}, max_depth {depth}: {mean:.4}, expected {expected:.4}",
                    kind.name()
                );
            }
            // SPPM, by its own loop: 16 iterations of 20,000 photon paths.
            let settings = RenderSettings {
                width: SIZE,
                height: SIZE,
                sampler: PixelSampler::new(SamplerKind::Random, 16),
                integrator: IntegratorConfig {
                    kind: IntegratorKind::Sppm,
                    max_depth: depth,
                    rr_depth: 1000,
                    color: ColorMode::Rgb,
                    photon: PhotonConfig {
                        sppm_photons: 20_000,
                        ..PhotonConfig::default()
                    },
                    ..IntegratorConfig::default()
                },
                seed: 5,
                ..RenderSettings::default()
            };
            let sppm = whole_image(IntegratorKind::Sppm).expect("SPPM has its own loop");
            let mut film = sppm.new_film(&settings);
            let control = RenderControl {
                cancel: &AtomicBool::new(false),
                progress: &|_, _| {},
                checkpoint: None,
            };
            let mean = green_mean(&sppm.render_film(&scene, &settings, &mut film, control).film);
            assert!(
                (mean / expected - 1.0).abs() < 0.01,
                "sppm, max_depth {depth}: {mean:.4}, expected {expected:.4}"
            );
        }
    }

    /// An area light's surface is a black primitive that names its light: every method
    /// sees the light's own emission on the side it emits to and nothing behind it. Two
    /// one-sided lamps of radiance (2, 3, 4) side by side, the left facing the camera, the
    /// right facing away; each pixel's camera ray must return exactly the radiance or zero.
    /// Light tracing is left out: it sees emitters only through splats (the references
    /// test those).
    #[test]
    fn every_method_sees_an_area_light_on_its_emitting_side_only() {
        use crate::camera::CameraSettings;
        use crate::geometry::{Polygon, Shape};
        use crate::math::{Transform, Vec3};
        use crate::scene::SceneBuilder;
        const SIZE: u32 = 16;
        let mut b = SceneBuilder::default();
        b.camera = CameraSettings {
            position: Vec3::new(0.0, 0.0, 4.0),
            look_at: Vec3::ZERO,
            fov_degrees: 40.0,
            ..CameraSettings::default()
        };
        let radiance = Color::new(2.0, 3.0, 4.0);
        let quad = |x0: f64, x1: f64| {
            let c = [
                Vec3::new(x0, -1.0, 0.0),
                Vec3::new(x1, -1.0, 0.0),
                Vec3::new(x1, 1.0, 0.0),
                Vec3::new(x0, 1.0, 0.0),
            ];
            // Counter-clockwise seen from +z: the normal points to the camera.
            let corners = if x0 < 0.0 {
                c.to_vec()
            } else {
                c.iter().rev().copied().collect()
            };
            Shape::Polygon(Box::new(Polygon::new(corners).expect("a square")))
        };
        for (name, x0, x1) in [("front", -1.2, -0.1), ("back", 0.1, 1.2)] {
            let black = b.black_material();
            let placed = b.add_emissive_object(
                name,
                quad(x0, x1),
                Transform::IDENTITY,
                black,
                radiance,
                false,
                1,
            );
            assert!(placed);
        }
        let scene = b.build();
        // The light's radiance lives in the light alone: the one material is black.
        assert_eq!(scene.materials.len(), 1);
        assert!(scene.materials[0].reflects_nothing());
        let camera = Camera::new(&scene.camera, SIZE, SIZE);
        let facing = scene.geometry.primitives[0]
            .light
            .expect("the front lamp's light");
        assert!(scene.lights[facing as usize].emits_toward(Vec3::Z, Vec3::Z));
        for kind in [
            IntegratorKind::Local,
            IntegratorKind::Appel,
            IntegratorKind::Whitted,
            IntegratorKind::Path,
            IntegratorKind::Bdpt,
            IntegratorKind::Photon,
        ] {
            let config = IntegratorConfig {
                kind,
                color: ColorMode::Rgb,
                photon: PhotonConfig {
                    photons: 1000,
                    ..PhotonConfig::default()
                },
                ..IntegratorConfig::default()
            };
            let splats = SplatBuffer::new(SIZE, SIZE, 1.0);
            let integrator = Integrator::new(&scene, &config, &camera, &splats, None, 5);
            let mut counts = RayCounts::default();
            let mut seen = [0; 3];
            for (x, y) in (0..SIZE * SIZE).map(|i| (i % SIZE, i / SIZE)) {
                let mut stream = SampleStream::random(Rng::for_sample(5, x, y, 0));
                let ray = camera.sample_ray(x as f64 + 0.5, y as f64 + 0.5, [0.5; 2], 0.0);
                let c = integrator.camera_ray(&ray, &mut stream, &mut counts, None);
                let hit = scene
                    .geometry
                    .intersect(&ray, f64::INFINITY)
                    .map(|(p, _)| p);
                let expected = match hit {
                    Some(0) => radiance,
                    _ => Color::BLACK,
                };
                seen[hit.map_or(2, |p| p as usize)] += 1;
                let error = [c.r - expected.r, c.g - expected.g, c.b - expected.b];
                assert!(
                    error.iter().all(|e| e.abs() < 1e-9),
                    "{}: pixel ({x}, {y}) on {hit:?} gives {c:?}, expected {expected:?}",
                    kind.name()
                );
            }
            assert!(seen.iter().all(|&n| n > 0), "{seen:?}");
        }
    }

    fn green_mean(film: &Film) -> f64 {
        let pixels = film.pixels();
        pixels.iter().map(|p| p[1] as f64).sum::<f64>() / pixels.len() as f64
    }
}
