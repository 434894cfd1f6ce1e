//! Integrators: turn a camera ray into the radiance it carries back.
//!
//! The render loop ([`crate::render`]) does not know which integrator it drives: it asks
//! [`Integrator::camera_ray`] for each camera sample (pbrt-v4's `RayIntegrator::Li` under its
//! `ImageTileIntegrator`). The integrator is chosen once per render, and dispatched by `match`.

mod medium;
mod path;
mod ray_tree;
mod whitted;

pub use medium::MediumStack;
pub use path::PathTracer;
pub use ray_tree::{RayKind, RayNode, RayTree, ShadowInfo, Stop};
pub use whitted::{RayCounts, Whitted, WhittedConfig, MAX_DEPTH};

use crate::color::Color;
use crate::math::Ray;
use crate::sampling::SampleStream;
use crate::scene::Scene;
pub use plenum_spectrum::ColorMode;

/// The methods a scene can be rendered with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum IntegratorKind {
    /// Whitted's recursive ray tracing with the Phong model (and distribution ray tracing).
    #[default]
    Whitted,
    /// Unidirectional path tracing with next-event estimation and MIS.
    Path,
}

impl IntegratorKind {
    pub const ALL: [IntegratorKind; 2] = [IntegratorKind::Whitted, IntegratorKind::Path];

    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Whitted => "whitted",
            IntegratorKind::Path => "path",
        }
    }

    pub fn from_name(name: &str) -> Option<IntegratorKind> {
        Self::ALL.into_iter().find(|k| k.name() == name)
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
        }
    }
}

impl IntegratorConfig {
    pub fn whitted(&self) -> WhittedConfig {
        WhittedConfig {
            max_depth: self.max_depth,
            min_weight: self.min_weight,
        }
    }
}

/// The integrator of one render.
pub enum Integrator<'a> {
    Whitted(Whitted<'a>),
    Path(PathTracer<'a>),
}

impl<'a> Integrator<'a> {
    pub fn new(scene: &'a Scene, config: &IntegratorConfig) -> Self {
        match config.kind {
            IntegratorKind::Whitted => Integrator::Whitted(Whitted::new(scene, config.whitted())),
            IntegratorKind::Path => Integrator::Path(PathTracer::new(scene, config)),
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
        }
    }
}
