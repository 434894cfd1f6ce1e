//! Integrators: turn a camera ray into the radiance it carries back.
//!
//! The render loop ([`crate::render`]) does not know which integrator it drives: it asks
//! [`Integrator::camera_ray`] for each camera sample (pbrt-v4's `RayIntegrator::Li` under its
//! `ImageTileIntegrator`). The integrator is chosen once per render, and dispatched by `match`.

mod bdpt;
mod direct;
mod light_tracing;
mod medium;
mod path;
mod photon;
pub mod photon_map;
mod photons;
mod ray_tree;
pub mod sppm;
mod whitted;

pub use bdpt::{BidirectionalPathTracer, StrategyImages};
pub use light_tracing::LightTracer;
pub use medium::MediumStack;
pub use path::PathTracer;
pub use photon::PhotonMapper;
pub use ray_tree::{
    FoundPhoton, PhotonGather, RayKind, RayNode, RayTree, ShadowInfo, Stop, Strategy,
};
pub use whitted::{RayCounts, Whitted, WhittedConfig, MAX_DEPTH};

use crate::camera::Camera;
use crate::color::Color;
use crate::film::SplatBuffer;
use crate::math::Ray;
use crate::sampling::SampleStream;
use crate::scene::Scene;
pub use plenum_spectrum::ColorMode;
use plenum_spectrum::SampledWavelengths;

/// The methods a scene can be rendered with: the lecture's ladder, from local illumination
/// to bidirectional path tracing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum IntegratorKind {
    /// The camera ray's hit shaded by every light with the Phong model: no shadow rays, no
    /// recursion.
    Local,
    /// Appel (1968): local illumination plus one shadow ray to each light.
    Appel,
    /// Whitted's recursive ray tracing with the Phong model (and distribution ray tracing).
    #[default]
    Whitted,
    /// Unidirectional path tracing with next-event estimation and MIS.
    Path,
    /// Light tracing: paths from the lights, each vertex connected to the camera.
    Light,
    /// Photon mapping (Jensen 1996): light stored on surfaces, gathered from the eye.
    Photon,
    /// Stochastic progressive photon mapping (Hachisuka and Jensen 2009).
    Sppm,
    /// Bidirectional path tracing (Veach and Guibas 1995), every strategy under MIS.
    Bdpt,
}

impl IntegratorKind {
    pub const ALL: [IntegratorKind; 8] = [
        IntegratorKind::Local,
        IntegratorKind::Appel,
        IntegratorKind::Whitted,
        IntegratorKind::Path,
        IntegratorKind::Light,
        IntegratorKind::Photon,
        IntegratorKind::Sppm,
        IntegratorKind::Bdpt,
    ];

    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Local => "local",
            IntegratorKind::Appel => "appel",
            IntegratorKind::Whitted => "whitted",
            IntegratorKind::Path => "path",
            IntegratorKind::Light => "light",
            IntegratorKind::Photon => "photon",
            IntegratorKind::Sppm => "sppm",
            IntegratorKind::Bdpt => "bdpt",
        }
    }

    pub fn from_name(name: &str) -> Option<IntegratorKind> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// The method reads the Phong model (RGB), not the physically based materials.
    pub fn is_classic(self) -> bool {
        matches!(
            self,
            IntegratorKind::Local | IntegratorKind::Appel | IntegratorKind::Whitted
        )
    }

    /// The method adds light to pixels other than the one sampled (splats), so each pixel
    /// needs a fixed sample count and a box filter of the pixel's extent.
    pub fn splats(self) -> bool {
        matches!(self, IntegratorKind::Light | IntegratorKind::Bdpt)
    }
}

/// Everything an integrator is configured by.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IntegratorConfig {
    pub kind: IntegratorKind,
    /// Bounces after the camera ray (0: direct light only); at most [`MAX_DEPTH`].
    pub max_depth: u32,
    /// Whitted: rays whose weight in the pixel falls below this are not traced.
    pub min_weight: f64,
    /// Path: Russian roulette from this many bounces on (pbrt-v4 and Mitsuba: after the
    /// first few).
    pub rr_depth: u32,
    /// How light is represented: by sampled wavelengths or by three RGB channels.
    pub color: ColorMode,
    /// Bidirectional path tracing: keep the image of every strategy (s, t).
    pub strategies: bool,
    /// Photon mapping's and SPPM's settings.
    pub photon: PhotonConfig,
}

/// The settings of the photon methods (`photon`, `sppm`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotonConfig {
    /// Photon mapping: photon paths traced for the global map.
    pub photons: u64,
    /// Photon mapping: photon paths traced for the caustic map (0: no caustic map, and no
    /// caustics).
    pub caustic_photons: u64,
    /// Photon mapping: the photons a density estimate gathers (k), 1 to [`MAX_NEAREST`].
    pub nearest: u32,
    /// Photon mapping: the largest gather radius; SPPM: the initial radius (scene units).
    /// 0: automatic (a tenth of the scene's bounding radius; for SPPM, two pixels' footprint
    /// at each pixel's first visible point).
    pub radius: f64,
    /// Photon mapping: final-gather rays per camera sample.
    pub gather_rays: u32,
    /// SPPM: photon paths per iteration (0: as many as the image has pixels).
    pub sppm_photons: u64,
    /// SPPM: the fraction of new photons kept as the radius shrinks, in (0, 1).
    pub alpha: f64,
}

/// The most photons one density estimate may gather (the search keeps one more).
pub const MAX_NEAREST: u32 = photon_map::MAX_NEAREST as u32 - 1;

impl Default for PhotonConfig {
    fn default() -> Self {
        PhotonConfig {
            photons: 200_000,
            caustic_photons: 200_000,
            nearest: 64,
            radius: 0.0,
            gather_rays: 1,
            sppm_photons: 0,
            alpha: 2.0 / 3.0,
        }
    }
}

impl PhotonConfig {
    /// The largest photon count a setting takes: 2³² paths.
    pub const MAX_PHOTONS: u64 = 1 << 32;

    /// Whether the settings make sense; what is wrong where they do not.
    pub fn check(&self) -> Result<(), String> {
        self.check_field().map_err(|(_, e)| e)
    }

    /// [`check`](Self::check), with the setting at fault: its key in a scene file's
    /// `[render]` table (`sppm_alpha`), which the command line spells `--sppm-alpha`.
    pub fn check_field(&self) -> Result<(), (&'static str, String)> {
        let max = Self::MAX_PHOTONS;
        if self.photons == 0 || self.photons > max {
            return Err((
                "photons",
                format!("photons must be between 1 and {max} photon paths"),
            ));
        }
        if self.caustic_photons > max {
            return Err((
                "caustic_photons",
                format!("caustic photons must be at most {max} photon paths (0: no caustic map)"),
            ));
        }
        if self.sppm_photons > max {
            return Err((
                "sppm_photons",
                format!("SPPM photons must be at most {max} photon paths per iteration (0: the pixel count)"),
            ));
        }
        if self.nearest == 0 || self.nearest > MAX_NEAREST {
            return Err((
                "photon_nearest",
                format!("the photons per density estimate must be between 1 and {MAX_NEAREST}"),
            ));
        }
        if !(self.radius >= 0.0 && self.radius.is_finite()) {
            return Err((
                "photon_radius",
                "the photon radius must be a number ≥ 0 (0: automatic)".to_string(),
            ));
        }
        if self.gather_rays == 0 || self.gather_rays > 1024 {
            return Err((
                "gather_rays",
                "the final-gather rays must be between 1 and 1024".to_string(),
            ));
        }
        if !(self.alpha > 0.0 && self.alpha < 1.0) {
            return Err((
                "sppm_alpha",
                "the SPPM alpha must lie strictly between 0 and 1".to_string(),
            ));
        }
        Ok(())
    }
}

impl Default for IntegratorConfig {
    fn default() -> Self {
        let w = WhittedConfig::default();
        IntegratorConfig {
            kind: IntegratorKind::Whitted,
            max_depth: w.max_depth,
            min_weight: w.min_weight,
            rr_depth: 5,
            color: ColorMode::Spectral,
            strategies: false,
            photon: PhotonConfig::default(),
        }
    }
}

impl IntegratorConfig {
    /// Whitted's settings; local illumination and Appel's method are Whitted's without
    /// recursion, local illumination also without shadow rays.
    pub fn whitted(&self) -> WhittedConfig {
        let recursive = self.kind == IntegratorKind::Whitted;
        WhittedConfig {
            max_depth: if recursive { self.max_depth } else { 0 },
            min_weight: self.min_weight,
            shadows: self.kind != IntegratorKind::Local,
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
            // SPPM renders by its own loop (`sppm::render`); its nearest relative here serves
            // trace-pixel, which follows one camera sample.
            IntegratorKind::Photon | IntegratorKind::Sppm => {
                Integrator::Photon(Box::new(PhotonMapper::new(scene, config, camera, seed)))
            }
        }
    }

    /// Linear sRGB radiance along a camera ray; `stream` gives the random numbers of its pixel
    /// sample. With `tree`, every ray traced is recorded in it.
    #[inline]
    pub fn camera_ray(
        &self,
        ray: &Ray,
        stream: &mut SampleStream,
        counts: &mut RayCounts,
        tree: Option<&mut RayTree>,
    ) -> Color {
        match self {
            Integrator::Whitted(w) => w.camera_ray(ray, stream, counts, tree),
            Integrator::Path(p) => p.camera_ray(ray, stream, counts, tree),
            Integrator::Light(l) => l.camera_ray(ray, stream, counts, tree),
            Integrator::Bdpt(b) => b.camera_ray(ray, stream, counts, tree),
            Integrator::Photon(p) => p.camera_ray(ray, stream, counts, tree),
        }
    }

    /// The rays traced before rendering (photon mapping's photon pass).
    pub fn pass_counts(&self) -> RayCounts {
        match self {
            Integrator::Photon(p) => p.pass_counts,
            _ => RayCounts::default(),
        }
    }
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
        n.object = Some(scene.object_names[prim as usize].clone());
        let m = scene.primitives[prim as usize].material as usize;
        n.material = Some(scene.material_names[m].clone());
        n.distance = Some(distance);
    });
}
