//! Integrators: turn a camera ray into the radiance it carries back.
//!
//! The render loop ([`crate::render`]) does not know which integrator it drives: it asks
//! [`Integrator::camera_ray`] for each camera sample (pbrt-v4's `RayIntegrator::Li` under its
//! `ImageTileIntegrator`). The integrator is chosen once per render, and dispatched by `match`.

mod bdpt;
mod light_tracing;
mod medium;
mod path;
mod ray_tree;
mod whitted;

pub use bdpt::{BidirectionalPathTracer, StrategyImages};
pub use light_tracing::LightTracer;
pub use medium::MediumStack;
pub use path::PathTracer;
pub use ray_tree::{RayKind, RayNode, RayTree, ShadowInfo, Stop, Strategy};
pub use whitted::{RayCounts, Whitted, WhittedConfig, MAX_DEPTH};

use crate::camera::Camera;
use crate::color::Color;
use crate::film::SplatBuffer;
use crate::math::Ray;
use crate::sampling::SampleStream;
use crate::scene::Scene;
pub use plenum_spectrum::ColorMode;

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

/// The integrator of one render.
pub enum Integrator<'a> {
    Whitted(Whitted<'a>),
    Path(PathTracer<'a>),
    Light(LightTracer<'a>),
    Bdpt(BidirectionalPathTracer<'a>),
}

impl<'a> Integrator<'a> {
    /// The integrator for `config`; those that splat add to `splats`, through `camera`;
    /// bidirectional path tracing also writes each strategy's image to `strategies`.
    pub fn new(
        scene: &'a Scene,
        config: &IntegratorConfig,
        camera: &'a Camera,
        splats: &'a SplatBuffer,
        strategies: Option<&'a StrategyImages>,
    ) -> Self {
        match config.kind {
            IntegratorKind::Local | IntegratorKind::Appel | IntegratorKind::Whitted => {
                Integrator::Whitted(Whitted::new(scene, config.whitted()))
            }
            IntegratorKind::Path => Integrator::Path(PathTracer::new(scene, config)),
            IntegratorKind::Light => {
                Integrator::Light(LightTracer::new(scene, config, camera, splats))
            }
            // Not yet written: the path tracer stands in.
            IntegratorKind::Bdpt => Integrator::Bdpt(BidirectionalPathTracer::new(
                scene, config, camera, splats, strategies,
            )),
            IntegratorKind::Photon | IntegratorKind::Sppm => {
                Integrator::Path(PathTracer::new(scene, config))
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
        }
    }
}
