//! What a render is asked to do and what it reports: the image's settings (size, sampler,
//! filter, adaptive sampling, seed), the method and its settings, the controls a caller
//! holds while it runs, and what it returns (the film and the rays traced).
//!
//! Plain data with the checks of their values, below both the render loop
//! ([`crate::render`]) and the integrators ([`crate::integrator`]), which both read it.

use crate::accel::{cost, Cost};
use crate::film::Film;
use crate::raw_film::RawFilm;
use crate::sampling::{Filter, PixelSampler};
pub use plenum_spectrum::ColorMode;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

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

impl IntegratorConfig {
    /// Whether the render keeps each strategy's image (a method with strategies, asked to).
    pub fn writes_strategies(&self) -> bool {
        self.strategies && self.kind == IntegratorKind::Bdpt
    }
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
    /// 0: automatic (a tenth of the scene's bounding radius; for SPPM, one pixel's footprint
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
pub const MAX_NEAREST: u32 = 511;

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
        IntegratorConfig {
            kind: IntegratorKind::Whitted,
            max_depth: 5,
            min_weight: 1.0 / 256.0,
            rr_depth: 5,
            color: ColorMode::Spectral,
            strategies: false,
            photon: PhotonConfig::default(),
        }
    }
}

/// The deepest recursion allowed: each bounce is a stack frame, and past a few hundred
/// bounces the render threads' stacks would overflow.
pub const MAX_DEPTH: u32 = 100;

/// Rays traced, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    pub camera: u64,
    pub shadow: u64,
    pub reflection: u64,
    pub refraction: u64,
    /// Rays of light paths: leaving a light and scattered along the path.
    pub light: u64,
    /// Connections between a path's vertex and the camera or another path's vertex.
    pub connection: u64,
    /// Photon rays (photon mapping's passes).
    pub photon: u64,
    /// Samples that came out NaN or infinite and were left out of the film.
    pub invalid: u64,
    /// The depth of the deepest reflected or refracted ray of the camera's paths (the
    /// camera ray's is 0; the BSDF ray of a path's last vertex, which ends it, does not
    /// count): the most, not a sum, which [`RayCounts::add`] keeps.
    pub deepest: u64,
    /// What the rays cost the acceleration structures: nodes visited, primitives tested.
    pub cost: Cost,
}

impl RayCounts {
    pub fn total(&self) -> u64 {
        self.camera
            + self.shadow
            + self.reflection
            + self.refraction
            + self.light
            + self.connection
            + self.photon
    }

    pub fn add(&mut self, o: &RayCounts) {
        self.camera += o.camera;
        self.shadow += o.shadow;
        self.reflection += o.reflection;
        self.refraction += o.refraction;
        self.light += o.light;
        self.connection += o.connection;
        self.photon += o.photon;
        self.invalid += o.invalid;
        self.deepest = self.deepest.max(o.deepest);
        self.cost += o.cost;
    }

    /// Runs `work` on this thread, adding the acceleration structures' cost it spends to
    /// `cost` (work that calls into the thread pool would be charged what it steals).
    pub fn charging<R>(&mut self, work: impl FnOnce(&mut RayCounts) -> R) -> R {
        let (r, spent) = cost::spent(|| work(self));
        self.cost += spent;
        r
    }

    /// Notes a reflected or refracted ray of depth `depth` on a camera path.
    pub fn bounce(&mut self, depth: u32) {
        self.deepest = self.deepest.max(depth as u64);
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub sampler: PixelSampler,
    /// How samples are weighted into pixels.
    pub filter: Filter,
    /// Spend samples where the image needs them; replaces the sampler's fixed count.
    pub adaptive: Option<Adaptive>,
    /// Which integrator, and its settings.
    pub integrator: IntegratorConfig,
    pub seed: u64,
    /// The SPD test procedure (Haines 1987): one ray through every pixel corner, (W+1)×(H+1)
    /// rays in all, each pixel the average of its four corners. Replaces the sampler.
    pub corners: bool,
    /// Render this part of the `width` × `height` image alone, each pixel as the whole
    /// render makes it (pbrt's crop window); the image is the part's size.
    pub crop: Option<Crop>,
    /// Keep each pixel's rays ([`RenderOutput::pixel_rays`]): what the `rays` and `spp`
    /// views show.
    pub pixel_rays: bool,
}

/// The rays traced for one pixel's samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PixelRays {
    /// Camera rays: the samples taken (adaptive sampling's count, or the corner rays of
    /// adaptive subdivision).
    pub camera: u64,
    /// Every ray, of every kind ([`RayCounts::total`]).
    pub total: u64,
    /// The depth of the deepest reflected or refracted ray of its camera paths
    /// ([`RayCounts::deepest`]).
    pub deepest: u64,
    /// What its rays cost the acceleration structures ([`RayCounts::cost`]).
    pub cost: Cost,
}

impl PixelRays {
    /// Adds the rays of more of the pixel's samples (the deepest is the most of both).
    pub fn add(&mut self, o: &PixelRays) {
        self.camera += o.camera;
        self.total += o.total;
        self.deepest = self.deepest.max(o.deepest);
        self.cost += o.cost;
    }
}

/// A part of the image: the pixel columns `x0..x1` and rows `y0..y1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crop {
    pub x0: u32,
    pub x1: u32,
    pub y0: u32,
    pub y1: u32,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 640,
            height: 480,
            sampler: PixelSampler::Grid { n: 1 },
            filter: Filter::default(),
            adaptive: None,
            integrator: IntegratorConfig::default(),
            seed: 0,
            corners: false,
            crop: None,
            pixel_rays: false,
        }
    }
}

impl RenderSettings {
    /// The size of the image rendered: the crop's, or the whole.
    pub fn image_size(&self) -> (u32, u32) {
        self.crop
            .map_or((self.width, self.height), |c| (c.x1 - c.x0, c.y1 - c.y0))
    }

    /// Where the rendered image's pixel (0, 0) lies in the whole image.
    pub fn image_origin(&self) -> (u32, u32) {
        self.crop.map_or((0, 0), |c| (c.x0, c.y0))
    }

    /// Whether the integrator can work with these settings; the reason where it cannot.
    pub fn check(&self) -> Result<(), String> {
        let kind = self.integrator.kind;
        if let Some(c) = self.crop {
            let (w, h) = (self.width, self.height);
            if !(c.x0 < c.x1 && c.x1 <= w && c.y0 < c.y1 && c.y1 <= h) {
                return Err(format!("the crop {},{},{},{} is not a part of the {w}×{h} image: columns x0 < x1 ≤ {w}, rows y0 < y1 ≤ {h}", c.x0, c.x1, c.y0, c.y1));
            }
            if kind.splats() {
                return Err(format!("integrator `{}` cannot render a part of the image: its pixels take light from the light paths of every pixel's samples", kind.name()));
            }
            if matches!(self.adaptive, Some(Adaptive::Variance { .. })) {
                return Err("adaptive sampling by variance cannot render a part of the image: its second pass looks at each pixel's neighbours, some beyond the part".to_string());
            }
        }
        if matches!(kind, IntegratorKind::Photon | IntegratorKind::Sppm) {
            self.integrator.photon.check()?;
        }
        if kind == IntegratorKind::Sppm {
            if self.adaptive.is_some() || self.corners {
                return Err("integrator `sppm` renders a fixed number of iterations (--spp): adaptive sampling and the SPD corners are not available with it".to_string());
            }
            if self.filter != Filter::default() {
                return Err("integrator `sppm` gathers each pixel over its own square (a box filter of one pixel); other filters are not available with it".to_string());
            }
        }
        if kind.splats() {
            let name = kind.name();
            if self.adaptive.is_some() {
                return Err(format!("integrator `{name}` adds light to pixels other than the one sampled, so it needs a fixed number of samples per pixel: adaptive sampling is not available with it"));
            }
            if self.corners {
                return Err(format!(
                    "integrator `{name}` cannot trace the SPD pixel corners (--nff-corners)"
                ));
            }
            if self.integrator.strategies && self.filter != Filter::default() {
                return Err("--write-strategies needs the box filter of one pixel: a strategy image takes each contribution where it lands".to_string());
            }
        }
        Ok(())
    }
}

/// Adaptive sampling.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Adaptive {
    /// Whitted (1980): trace the pixel's four corners; where they differ by more than
    /// `contrast` (Mitchell's (max − min)/(max + min) of luminance), split the square in four
    /// and trace the new corners, down to `depth` levels (at most [`MAX_SUBDIVISION`]). The
    /// pixel is the area-weighted mean of its smallest squares' corner means (a box filter).
    Subdivide { contrast: f64, depth: u32 },
    /// Sample every pixel with `min_spp` Sobol points; then, in batches of `min_spp`, every
    /// pixel whose error estimate or a neighbour's is still too high, until the standard error
    /// of its luminance falls below `threshold` × max(mean, 0.05) — relative error in lit
    /// pixels, absolute in dark ones — or `max_spp` samples are spent. A pixel refined
    /// because of its neighbour takes at least one batch more.
    Variance {
        threshold: f64,
        min_spp: u32,
        max_spp: u32,
    },
}

/// The deepest subdivision `Adaptive::Subdivide` may ask for: 16 × 16 squares per pixel.
pub const MAX_SUBDIVISION: u32 = 4;

#[derive(Clone, Debug)]
pub struct RenderOutput {
    pub film: Film,
    pub counts: RayCounts,
    /// False when the render was cancelled: tiles not yet rendered are black.
    pub complete: bool,
    /// Bidirectional path tracing with `strategies` set: for each strategy (s, t), its
    /// image weighted by MIS and unweighted.
    pub strategies: Vec<(usize, usize, Film, Film)>,
    /// With [`RenderSettings::pixel_rays`], each pixel's rays of this render, row by row
    /// (of the film: the crop's pixels; empty for methods with a loop of their own, the
    /// SPD corners, and otherwise). They add up to `counts`, less the rays of passes that
    /// belong to no pixel (photon mapping's photons).
    pub pixel_rays: Vec<PixelRays>,
}

/// What the caller of [`render_film`] may do while it runs.
pub struct RenderControl<'a> {
    /// Set: the render stops between tiles (the film keeps what is done).
    pub cancel: &'a AtomicBool,
    /// Called after each tile with (tiles done, tiles in all).
    pub progress: &'a (dyn Fn(usize, usize) + Sync),
    /// Every so often, between tiles with none in flight, the film so far: what a
    /// checkpoint saves.
    pub checkpoint: Option<(Duration, &'a mut dyn FnMut(&RawFilm))>,
}
