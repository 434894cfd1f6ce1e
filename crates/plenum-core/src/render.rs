//! Rendering an image: tiles in parallel with rayon, samples per pixel from the sampler,
//! radiance from the integrator, weighted by the reconstruction filter.
//!
//! A pixel is Σ w_i·L_i / Σ w_i over its own samples, their offsets drawn from the filter
//! itself (filter importance sampling; see [`crate::sampling::Filter`]). Adaptive sampling
//! decides per pixel how many samples that takes: by Whitted's subdivision of the pixel
//! where its corners differ, or by sampling until the estimated error is small enough.
//!
//! **Invariant:** the image depends only on the scene, the settings and the seed. Every pixel
//! is computed from its own samples whose random streams come from (seed, pixel, sample), and
//! tiles are written back by position, so the thread count changes nothing. Pixels sum their
//! samples in fixed point ([`RawFilm`]), so a render stopped and continued from a checkpoint,
//! or split into sample ranges and merged, gives the same bytes as one uninterrupted render.

use crate::camera::Camera;
use crate::color::Color;
use crate::film::{Film, SplatBuffer};
use crate::integrator::{whole_image, Integrator, RayCounts, RayTree, StrategyImages};
use crate::math::Ray;
use crate::raw_film::{PixelSums, RawFilm};
use crate::sampling::{PixelSampler, Rng, SampleStream};
use crate::scene::Scene;
pub use crate::settings::{
    Adaptive, Crop, PixelRays, RenderControl, RenderOutput, RenderSettings, MAX_SUBDIVISION,
};
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Side of the square tiles the image is cut into.
pub const TILE_SIZE: u32 = 16;

/// An empty film for `settings`, to hold sample indices `samples` of every pixel (of all
/// `settings.sampler`'s samples; ignored by adaptive sampling and the SPD corners). A method
/// with a loop of its own ([`whole_image`]) gets its own film.
pub fn new_film(settings: &RenderSettings, samples: Range<u32>) -> RawFilm {
    if let Some(method) = whole_image(settings.integrator.kind) {
        return method.new_film(settings);
    }
    let extra = u32::from(settings.corners);
    let (w, h) = settings.image_size();
    let mut film = RawFilm::new(w + extra, h + extra, settings.corners, samples);
    film.spp = settings.sampler.samples_per_pixel();
    if settings.integrator.kind.splats() {
        film.splats = vec![[0; 3]; settings.width as usize * settings.height as usize];
    }
    film
}

/// Renders the scene. `cancel` stops the render between tiles; `progress(done, total)` is
/// called after each tile.
pub fn render(
    scene: &Scene,
    settings: &RenderSettings,
    cancel: &AtomicBool,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> RenderOutput {
    let mut film = new_film(settings, 0..settings.sampler.samples_per_pixel());
    let control = RenderControl {
        cancel,
        progress,
        checkpoint: None,
    };
    render_film(scene, settings, &mut film, control)
}

/// Renders into `film` (from [`new_film`], or a checkpoint of the same scene and settings):
/// the pixels it does not yet hold in full, then the image of all it holds.
pub fn render_film(
    scene: &Scene,
    settings: &RenderSettings,
    film: &mut RawFilm,
    mut control: RenderControl,
) -> RenderOutput {
    if let Some(method) = whole_image(settings.integrator.kind) {
        return method.render_film(scene, settings, film, control);
    }
    // Splats are pixel values once divided by the light paths per pixel; the camera's
    // importance reaches as far beyond the image as the filter spreads them.
    let spp = settings.sampler.samples_per_pixel().max(1);
    let splats = if settings.integrator.kind.splats() {
        SplatBuffer::new(settings.width, settings.height, 1.0 / spp as f64)
            .with_filter(&settings.filter)
    } else {
        SplatBuffer::new(0, 0, 0.0)
    };
    splats.preload(&film.splats);
    let camera = Camera::new(&scene.camera, settings.width, settings.height)
        .with_margin(splats.margin())
        .with_still_scene(!scene.geometry.moves());
    let strategies = settings.integrator.writes_strategies().then(|| {
        StrategyImages::new(
            settings.width,
            settings.height,
            1.0 / spp as f64,
            settings.integrator.max_depth,
        )
    });
    let integrator = Integrator::new(
        scene,
        &settings.integrator,
        &camera,
        &splats,
        strategies.as_ref(),
        settings.seed,
    );
    let (w, h) = (film.width, film.height);
    let passes = if let Some(Adaptive::Variance { .. }) = settings.adaptive {
        2
    } else {
        1
    };
    let mut tiles = Tiles {
        width: w,
        height: h,
        origin: settings.image_origin(),
        pixel_rays: (settings.pixel_rays && !settings.corners)
            .then(|| vec![PixelRays::default(); (w * h) as usize]),
        cancel: control.cancel,
        progress: control.progress,
        passes,
        checkpoint: control.checkpoint.take(),
    };
    let mut counts = integrator.pass_counts();
    let samples = film.samples.clone();
    let complete = match settings.adaptive {
        Some(Adaptive::Variance {
            threshold, min_spp, ..
        }) => {
            // First pass: min_spp samples everywhere. Second: more where the pixel or a
            // neighbour is not yet converged (a pixel whose first samples all missed a
            // nearby edge looks converged on its own; its neighbour gives it away).
            let first = tiles.run(0, film, &splats, &mut counts, |x, y, sums, c| {
                sample_pixel(
                    &integrator,
                    &camera,
                    settings,
                    (x, y),
                    0..min_spp,
                    sums,
                    c,
                    None,
                );
            });
            first && {
                if film.open.is_empty() {
                    film.open = film
                        .pixels
                        .iter()
                        .map(|p| !p.converged(threshold))
                        .collect();
                }
                // Kept in the film too: a checkpoint in the second pass must know which
                // pixels the first left open, which their refined sums no longer tell.
                let open = film.open.clone();
                // (A crop is refused here: the neighbours beyond its edge are not rendered.)
                let (ox, oy) = settings.image_origin();
                let near_open = |x: u32, y: u32| {
                    let (x, y) = (x - ox, y - oy);
                    let (x0, x1) = (x.saturating_sub(1), (x + 1).min(w - 1));
                    let (y0, y1) = (y.saturating_sub(1), (y + 1).min(h - 1));
                    (y0..=y1).any(|j| (x0..=x1).any(|i| open[(j * w + i) as usize]))
                };
                // Pixels a cancel kept from the second pass keep what the first found.
                let second = tiles.run(1, film, &splats, &mut counts, |x, y, sums, c| {
                    if near_open(x, y) {
                        refine_pixel(&integrator, &camera, settings, (x, y), sums, c, None);
                    }
                });
                second
            }
        }
        _ => tiles.run(0, film, &splats, &mut counts, |x, y, sums, c| {
            if settings.corners {
                let mut stream = corner_stream(settings.seed, x, y);
                let ray = camera.ray(x as f64, y as f64);
                *sums = PixelSums::single(integrator.camera_ray(&ray, &mut stream, c, None));
            } else if let Some(Adaptive::Subdivide { contrast, depth }) = settings.adaptive {
                *sums = PixelSums::single(subdivide_pixel(
                    &integrator,
                    &camera,
                    settings,
                    (x, y),
                    contrast,
                    depth,
                    c,
                    None,
                ));
            } else {
                let indices = samples.clone();
                sample_pixel(
                    &integrator,
                    &camera,
                    settings,
                    (x, y),
                    indices,
                    sums,
                    c,
                    None,
                );
            }
        }),
    };
    if !film.splats.is_empty() {
        film.splats = splats.sums();
    }
    counts.invalid += splats.clamped();
    let strategies = strategies.map_or_else(Vec::new, |si| {
        let film_of = |b: &SplatBuffer| {
            let mut f = Film::new(settings.width, settings.height);
            f.add_splats(b);
            f.resolve(1.0);
            f
        };
        si.strategies()
            .map(|(s, t)| {
                let (weighted, plain) = &si.images[si.index(s, t)];
                (s, t, film_of(weighted), film_of(plain))
            })
            .collect()
    });
    RenderOutput {
        strategies,
        film: film.image(),
        counts,
        complete,
        pixel_rays: tiles.pixel_rays.unwrap_or_default(),
    }
}

/// The image cut into tiles, rendered in parallel, pass after pass, into a [`RawFilm`].
struct Tiles<'a> {
    width: u32,
    height: u32,
    /// Where the film's pixel (0, 0) lies in the whole image (a crop's corner).
    origin: (u32, u32),
    /// Each film pixel's rays, where they are kept, summed over the passes.
    pixel_rays: Option<Vec<PixelRays>>,
    cancel: &'a AtomicBool,
    progress: &'a (dyn Fn(usize, usize) + Sync),
    passes: usize,
    checkpoint: Option<(Duration, &'a mut dyn FnMut(&RawFilm))>,
}

impl Tiles<'_> {
    /// Runs `pixel(x, y, sums, counts)` on every pixel of `film` that has not finished pass
    /// `pass` ((x, y) in the whole image), tiles in parallel, and marks it finished; whether every tile was done (those
    /// skipped after a cancel keep their sums). When a checkpoint is due, the tiles in flight
    /// finish, no new one starts, the film (with `splats`, the render's) is handed to the
    /// checkpoint, and the rest follow.
    fn run(
        &mut self,
        pass: usize,
        film: &mut RawFilm,
        splats: &SplatBuffer,
        counts: &mut RayCounts,
        pixel: impl Fn(u32, u32, &mut PixelSums, &mut RayCounts) + Sync,
    ) -> bool {
        let (w, h) = (self.width, self.height);
        let stage = pass as u8 + 1;
        let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE_SIZE))
            .flat_map(|ty| {
                (0..w.div_ceil(TILE_SIZE)).map(move |tx| (tx * TILE_SIZE, ty * TILE_SIZE))
            })
            .collect();
        let bounds = |(x0, y0): (u32, u32)| {
            let (x1, y1) = ((x0 + TILE_SIZE).min(w), (y0 + TILE_SIZE).min(h));
            (y0..y1).flat_map(move |y| (x0..x1).map(move |x| (x, y)))
        };
        let total = tiles.len() * self.passes;
        loop {
            let pending: Vec<(u32, u32)> = tiles
                .iter()
                .copied()
                .filter(|&t| bounds(t).any(|(x, y)| film.stages[(y * w + x) as usize] < stage))
                .collect();
            if pending.is_empty() {
                return true;
            }
            let deadline = self
                .checkpoint
                .as_ref()
                .map(|(every, _)| Instant::now() + *every);
            let paused = AtomicBool::new(false);
            let round = std::sync::atomic::AtomicUsize::new(0);
            let done = std::sync::atomic::AtomicUsize::new(
                tiles.len() * pass + tiles.len() - pending.len(),
            );
            let all_counts = Mutex::new(RayCounts::default());
            let keep_rays = self.pixel_rays.is_some();
            {
                let shared = Mutex::new((&mut *film, self.pixel_rays.as_mut()));
                pending.par_iter().for_each(|&tile| {
                    if self.cancel.load(Ordering::Relaxed) {
                        return;
                    }
                    // A checkpoint is due: start no more tiles, once one has been done
                    // this round (however short the interval, the render goes on).
                    if deadline.is_some_and(|d| Instant::now() >= d)
                        && round.load(Ordering::Relaxed) > 0
                    {
                        paused.store(true, Ordering::Relaxed);
                        return;
                    }
                    let mut sums: Vec<(u32, u32, PixelSums, PixelRays)> = {
                        let (f, _) = &*shared.lock().unwrap_or_else(|e| e.into_inner());
                        bounds(tile)
                            .map(|(x, y)| {
                                let i = (y * w + x) as usize;
                                (x, y, f.pixels[i], PixelRays::default())
                            })
                            .collect()
                    };
                    let mut tile_counts = RayCounts::default();
                    let (ox, oy) = self.origin;
                    for (x, y, s, rays) in &mut sums {
                        let before = tile_counts;
                        // The deepest ray is the most, not a sum: the pixel's own, kept apart.
                        tile_counts.deepest = 0;
                        tile_counts.charging(|c| pixel(*x + ox, *y + oy, s, c));
                        if keep_rays {
                            rays.camera = tile_counts.camera - before.camera;
                            rays.total = tile_counts.total() - before.total();
                            rays.deepest = tile_counts.deepest;
                            rays.cost = tile_counts.cost - before.cost;
                        }
                        tile_counts.deepest = tile_counts.deepest.max(before.deepest);
                    }
                    {
                        let (f, kept) = &mut *shared.lock().unwrap_or_else(|e| e.into_inner());
                        for (x, y, s, rays) in sums {
                            let i = (y * w + x) as usize;
                            f.pixels[i] = s;
                            f.stages[i] = stage;
                            if let Some(kept) = kept.as_deref_mut() {
                                kept[i].add(&rays);
                            }
                        }
                    }
                    all_counts
                        .lock()
                        .unwrap_or_else(|e| e.into_inner())
                        .add(&tile_counts);
                    round.fetch_add(1, Ordering::Relaxed);
                    (self.progress)(done.fetch_add(1, Ordering::Relaxed) + 1, total);
                });
            }
            counts.add(&all_counts.into_inner().unwrap_or_else(|e| e.into_inner()));
            if self.cancel.load(Ordering::Relaxed) {
                return false;
            }
            if paused.load(Ordering::Relaxed) {
                if let Some((_, save)) = self.checkpoint.as_mut() {
                    if !film.splats.is_empty() {
                        film.splats = splats.sums();
                    }
                    save(film);
                }
            }
        }
    }
}

/// The average radiance of one pixel's samples (a box filter).
fn render_pixel(
    integrator: &Integrator,
    camera: &Camera,
    settings: &RenderSettings,
    x: u32,
    y: u32,
    counts: &mut RayCounts,
    mut tree: Option<&mut RayTree>,
) -> Color {
    if settings.corners {
        let mut sum = Color::BLACK;
        for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let mut stream = corner_stream(settings.seed, x + dx, y + dy);
            let ray = camera.ray((x + dx) as f64, (y + dy) as f64);
            sum += integrator.camera_ray(&ray, &mut stream, counts, tree.as_deref_mut());
        }
        return sum * 0.25;
    }
    match settings.adaptive {
        Some(Adaptive::Subdivide { contrast, depth }) => subdivide_pixel(
            integrator,
            camera,
            settings,
            (x, y),
            contrast,
            depth,
            counts,
            tree,
        ),
        Some(Adaptive::Variance { min_spp, .. }) => {
            let mut e = PixelSums::default();
            let first = 0..min_spp;
            sample_pixel(
                integrator,
                camera,
                settings,
                (x, y),
                first,
                &mut e,
                counts,
                tree.as_deref_mut(),
            );
            refine_pixel(integrator, camera, settings, (x, y), &mut e, counts, tree);
            e.value()
        }
        None => {
            let mut e = PixelSums::default();
            let all = 0..settings.sampler.samples_per_pixel();
            sample_pixel(
                integrator,
                camera,
                settings,
                (x, y),
                all,
                &mut e,
                counts,
                tree,
            );
            e.value()
        }
    }
}

/// Adds samples `indices` of pixel (x, y) to `estimate`: in adaptive variance mode from the
/// Sobol sequence, otherwise from the settings' sampler.
#[allow(clippy::too_many_arguments)]
fn sample_pixel(
    integrator: &Integrator,
    camera: &Camera,
    settings: &RenderSettings,
    (x, y): (u32, u32),
    indices: std::ops::Range<u32>,
    estimate: &mut PixelSums,
    counts: &mut RayCounts,
    mut tree: Option<&mut RayTree>,
) {
    for index in indices {
        let (ray, weight, mut stream) = camera_sample(camera, settings, (x, y), index);
        let c = integrator.camera_ray(&ray, &mut stream, counts, tree.as_deref_mut());
        estimate.add(c, weight);
    }
}

/// Sample `index` of pixel (x, y) of the whole image: its camera ray, its filter weight,
/// and its stream, where the integrator goes on drawing. In adaptive variance mode from
/// the Sobol sequence, otherwise from the settings' sampler.
pub fn camera_sample(
    camera: &Camera,
    settings: &RenderSettings,
    (x, y): (u32, u32),
    index: u32,
) -> (Ray, f64, SampleStream) {
    let sampler = match settings.adaptive {
        Some(Adaptive::Variance { max_spp, .. }) => PixelSampler::Sobol { spp: max_spp },
        _ => settings.sampler,
    };
    let mut stream = sampler.stream(settings.seed, x, y, index);
    let f = settings.filter.sample(stream.pixel());
    // A pinhole reads no lens point: its dimension is passed over, the stream left as
    // drawing it would, so the image is the same either way.
    let lens = if camera.is_pinhole() {
        stream.skip_2d();
        [0.5; 2]
    } else {
        stream.next_2d()
    };
    // Where nothing moves, no ray's time matters: the same for the shutter's dimension.
    let shutter = if camera.is_still() {
        stream.skip_1d();
        0.0
    } else {
        stream.next_1d()
    };
    let (px, py) = (x as f64 + 0.5 + f.dx, y as f64 + 0.5 + f.dy);
    (camera.sample_ray(px, py, lens, shutter), f.weight, stream)
}

/// Adaptive variance mode: at least one more batch of samples, then more batches until the
/// pixel's error estimate is below the threshold or its budget is spent.
fn refine_pixel(
    integrator: &Integrator,
    camera: &Camera,
    settings: &RenderSettings,
    pixel: (u32, u32),
    estimate: &mut PixelSums,
    counts: &mut RayCounts,
    mut tree: Option<&mut RayTree>,
) {
    let Some(Adaptive::Variance {
        threshold,
        min_spp,
        max_spp,
    }) = settings.adaptive
    else {
        return;
    };
    let batch = min_spp.max(1);
    loop {
        let start = estimate.count;
        let end = (start + batch).min(max_spp);
        if start >= end {
            return;
        }
        let (c, t) = (&mut *counts, tree.as_deref_mut());
        sample_pixel(
            integrator,
            camera,
            settings,
            pixel,
            start..end,
            estimate,
            c,
            t,
        );
        if estimate.converged(threshold) {
            return;
        }
    }
}

/// Whitted's adaptive subdivision of pixel (x, y); see [`Adaptive::Subdivide`].
#[allow(clippy::too_many_arguments)]
fn subdivide_pixel(
    integrator: &Integrator,
    camera: &Camera,
    settings: &RenderSettings,
    (x, y): (u32, u32),
    contrast: f64,
    depth: u32,
    counts: &mut RayCounts,
    mut tree: Option<&mut RayTree>,
) -> Color {
    const SIDE: usize = (1 << MAX_SUBDIVISION) + 1;
    let depth = depth.min(MAX_SUBDIVISION);
    let step = 1usize << MAX_SUBDIVISION;
    // Corners on the finest lattice, traced once each when first needed.
    let mut corners = [[None::<Color>; SIDE]; SIDE];
    let mut corner = |i: usize, j: usize, counts: &mut RayCounts| -> Color {
        *corners[j][i].get_or_insert_with(|| {
            let (fx, fy) = (i as f64 / step as f64, j as f64 / step as f64);
            let index = (j * SIDE + i) as u32;
            let mut stream = SampleStream::random(Rng::for_sample(settings.seed, x, y, index));
            let ray = camera.sample_ray(
                x as f64 + fx,
                y as f64 + fy,
                stream.next_2d(),
                stream.next_1d(),
            );
            integrator.camera_ray(&ray, &mut stream, counts, tree.as_deref_mut())
        })
    };
    // Squares still to look at: lattice corner (i, j), side in lattice steps, level.
    // Depth-first, so at most three waiting squares per level plus the current one.
    let mut stack = [(0usize, 0usize, step, 0u32); 3 * MAX_SUBDIVISION as usize + 2];
    let mut waiting = 1;
    let mut sum = Color::BLACK;
    while waiting > 0 {
        waiting -= 1;
        let (i, j, side, level) = stack[waiting];
        let c = [
            corner(i, j, counts),
            corner(i + side, j, counts),
            corner(i, j + side, counts),
            corner(i + side, j + side, counts),
        ];
        let lum = c.map(|c| c.luminance());
        let (lo, hi) = lum
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        let differ = hi - lo > contrast * (hi + lo).max(1e-6);
        if differ && level < depth {
            let half = side / 2;
            for (di, dj) in [(0, 0), (half, 0), (0, half), (half, half)] {
                stack[waiting] = (i + di, j + dj, half, level + 1);
                waiting += 1;
            }
        } else {
            let area = (side * side) as f64 / (step * step) as f64;
            sum += (c[0] + c[1] + c[2] + c[3]) * (0.25 * area);
        }
    }
    sum
}

/// The random numbers of the ray through corner (x, y) of the SPD corner grid.
fn corner_stream(seed: u64, x: u32, y: u32) -> SampleStream {
    SampleStream::random(Rng::for_sample(seed, x, y, u32::MAX))
}

/// The ray tree of one pixel: every ray of every sample, and the pixel's colour (a method
/// with a loop of its own says what it traces for a pixel).
pub fn trace_pixel(scene: &Scene, settings: &RenderSettings, x: u32, y: u32) -> (RayTree, Color) {
    if let Some(method) = whole_image(settings.integrator.kind) {
        return method.trace_pixel(scene, settings, x, y);
    }
    traced(scene, settings, |integrator, camera, counts, tree| {
        render_pixel(integrator, camera, settings, x, y, counts, Some(tree))
    })
}

/// The samples of a pixel that [`trace_sample`] can pick one of: the sampler's (adaptive
/// sampling's budget); `None` where a pixel is not a list of samples (SPPM's iterations,
/// Whitted's adaptive subdivision, the SPD corners).
pub fn samples_per_pixel(settings: &RenderSettings) -> Option<u32> {
    if whole_image(settings.integrator.kind).is_some() || settings.corners {
        return None;
    }
    match settings.adaptive {
        Some(Adaptive::Subdivide { .. }) => None,
        Some(Adaptive::Variance { max_spp, .. }) => Some(max_spp),
        None => Some(settings.sampler.samples_per_pixel()),
    }
}

/// The ray tree of sample `index` of pixel (x, y), the very sample a render takes there, and
/// its colour (before the filter weighs it); `None` where [`samples_per_pixel`] is, or
/// `index` is not below it.
pub fn trace_sample(
    scene: &Scene,
    settings: &RenderSettings,
    x: u32,
    y: u32,
    index: u32,
) -> Option<(RayTree, Color)> {
    if index >= samples_per_pixel(settings)? {
        return None;
    }
    Some(traced(
        scene,
        settings,
        |integrator, camera, counts, tree| {
            let mut sums = PixelSums::default();
            let range = index..index + 1;
            sample_pixel(
                integrator,
                camera,
                settings,
                (x, y),
                range,
                &mut sums,
                counts,
                Some(tree),
            );
            sums.plain_mean()
        },
    ))
}

/// Runs `f` with the render's integrator and camera (as `render` makes them) and a tree to
/// record in.
fn traced(
    scene: &Scene,
    settings: &RenderSettings,
    f: impl FnOnce(&Integrator, &Camera, &mut RayCounts, &mut RayTree) -> Color,
) -> (RayTree, Color) {
    let splats =
        SplatBuffer::new(settings.width, settings.height, 1.0).with_filter(&settings.filter);
    let camera =
        Camera::new(&scene.camera, settings.width, settings.height).with_margin(splats.margin());
    let integrator = Integrator::new(
        scene,
        &settings.integrator,
        &camera,
        &splats,
        None,
        settings.seed,
    );
    let mut tree = RayTree::default();
    let mut counts = RayCounts::default();
    let c = f(&integrator, &camera, &mut counts, &mut tree);
    (tree, c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::Cost;
    use crate::integrator::{IntegratorConfig, IntegratorKind, PhotonConfig, RayKind, Stop};
    use crate::kit;
    use crate::sampling::{PixelSampler, SamplerKind};

    /// One function evaluates every method's pixel samples: each of the eight renders the
    /// Cornell box of the kit (12 × 12, 4 spp, seed 2) to the same image on one thread and
    /// on three, with no sample that is not finite, and a lit box.
    #[test]
    fn every_method_renders_the_same_image_on_any_number_of_threads() {
        let scene = kit::cornell_box(true);
        for kind in IntegratorKind::ALL {
            let settings = RenderSettings {
                width: 12,
                height: 12,
                sampler: PixelSampler::new(SamplerKind::Random, 4),
                integrator: IntegratorConfig {
                    kind,
                    photon: PhotonConfig {
                        photons: 5000,
                        caustic_photons: 5000,
                        sppm_photons: 2000,
                        ..PhotonConfig::default()
                    },
                    ..IntegratorConfig::default()
                },
                seed: 2,
                ..RenderSettings::default()
            };
            let images: Vec<Vec<[f32; 3]>> = [1, 3]
                .iter()
                .map(|&n| {
                    let pool = rayon::ThreadPoolBuilder::new()
                        .num_threads(n)
                        .build()
                        .unwrap();
                    let cancel = AtomicBool::new(false);
                    let out = pool.install(|| render(&scene, &settings, &cancel, &|_, _| {}));
                    assert!(out.complete);
                    out.film.pixels().to_vec()
                })
                .collect();
            assert_eq!(images[0], images[1], "{}", kind.name());
            let pixels = &images[0];
            assert!(
                pixels.iter().flatten().all(|c| c.is_finite()),
                "{}",
                kind.name()
            );
            let mean = pixels.iter().map(|p| p[1] as f64).sum::<f64>() / pixels.len() as f64;
            assert!(mean > 0.01, "{}: mean {mean}", kind.name());
        }
    }

    /// A crop is the whole render's pixels there, bit for bit: every method that renders
    /// pixel by pixel, SPPM (whose photon passes are the whole image's), a Gaussian filter,
    /// Whitted's adaptive subdivision and the SPD corners (the kit's Cornell box, 12 × 10,
    /// the crop columns 3..9 and rows 2..7); the methods that splat and adaptive sampling by
    /// variance are refused.
    #[test]
    fn a_crop_is_the_whole_renders_pixels_there() {
        let scene = kit::cornell_box(true);
        let crop = Crop {
            x0: 3,
            x1: 9,
            y0: 2,
            y1: 7,
        };
        let cancel = AtomicBool::new(false);
        let photon = PhotonConfig {
            photons: 5000,
            caustic_photons: 5000,
            sppm_photons: 2000,
            ..PhotonConfig::default()
        };
        let base = |kind| RenderSettings {
            width: 12,
            height: 10,
            sampler: PixelSampler::new(SamplerKind::Random, 4),
            integrator: IntegratorConfig {
                kind,
                photon,
                ..IntegratorConfig::default()
            },
            seed: 3,
            ..RenderSettings::default()
        };
        let mut cases: Vec<(&str, RenderSettings)> = IntegratorKind::ALL
            .into_iter()
            .filter(|k| !k.splats())
            .map(|k| (k.name(), base(k)))
            .collect();
        let mut gaussian = base(IntegratorKind::Path);
        gaussian.filter =
            crate::sampling::Filter::new(crate::sampling::FilterKind::Gaussian, 1.5).unwrap();
        let mut subdivide = base(IntegratorKind::Whitted);
        subdivide.adaptive = Some(Adaptive::Subdivide {
            contrast: 0.05,
            depth: 2,
        });
        let mut corners = base(IntegratorKind::Whitted);
        corners.corners = true;
        cases.extend([
            ("gaussian", gaussian),
            ("subdivide", subdivide),
            ("corners", corners),
        ]);
        for (name, settings) in cases {
            let whole = render(&scene, &settings, &cancel, &|_, _| {}).film;
            let part_settings = RenderSettings {
                crop: Some(crop),
                ..settings.clone()
            };
            part_settings.check().unwrap();
            let part = render(&scene, &part_settings, &cancel, &|_, _| {}).film;
            assert_eq!((part.width, part.height), (6, 5), "{name}");
            for y in 0..5 {
                for x in 0..6 {
                    assert_eq!(
                        part.get(x, y),
                        whole.get(x + 3, y + 2),
                        "{name}: pixel ({}, {})",
                        x + 3,
                        y + 2
                    );
                }
            }
        }
        for kind in [IntegratorKind::Light, IntegratorKind::Bdpt] {
            let settings = RenderSettings {
                crop: Some(crop),
                ..base(kind)
            };
            assert!(settings.check().is_err(), "{}", kind.name());
        }
        let variance = RenderSettings {
            crop: Some(crop),
            adaptive: Some(Adaptive::Variance {
                threshold: 0.01,
                min_spp: 4,
                max_spp: 16,
            }),
            ..base(IntegratorKind::Path)
        };
        assert!(variance.check().is_err());
        let outside = RenderSettings {
            crop: Some(Crop { x1: 13, ..crop }),
            ..base(IntegratorKind::Path)
        };
        assert!(outside.check().is_err());
    }

    /// Each pixel's rays, kept when asked: they and their cost to the acceleration
    /// structures add up to the render's counts less the photon pass (photon mapping), the
    /// camera rays to the samples taken, the deepest
    /// bounce to the render's (its `max_depth` in a closed box, under path tracing and
    /// BDPT), for a fixed sampler, adaptive sampling by variance and adaptive subdivision,
    /// and a crop keeps the whole render's there (the kit's Cornell box, 10 × 8, seed 4).
    #[test]
    fn each_pixels_rays_add_up_to_the_renders() {
        let scene = kit::cornell_box(true);
        let base = RenderSettings {
            width: 10,
            height: 8,
            sampler: PixelSampler::new(SamplerKind::Random, 4),
            seed: 4,
            pixel_rays: true,
            ..RenderSettings::default()
        };
        let cancel = AtomicBool::new(false);
        let variance = Adaptive::Variance {
            threshold: 0.02,
            min_spp: 4,
            max_spp: 32,
        };
        let subdivide = Adaptive::Subdivide {
            contrast: 0.05,
            depth: 2,
        };
        let mut cases = Vec::new();
        for kind in [
            IntegratorKind::Whitted,
            IntegratorKind::Path,
            IntegratorKind::Bdpt,
            IntegratorKind::Photon,
        ] {
            let mut settings = base.clone();
            settings.integrator.kind = kind;
            settings.integrator.photon.photons = 3000;
            settings.integrator.photon.caustic_photons = 3000;
            cases.push(settings);
        }
        for adaptive in [variance, subdivide] {
            let mut settings = base.clone();
            settings.integrator.kind = IntegratorKind::Path;
            settings.adaptive = Some(adaptive);
            cases.push(settings);
        }
        for settings in cases {
            let out = render(&scene, &settings, &cancel, &|_, _| {});
            let what = format!(
                "{} {:?}",
                settings.integrator.kind.name(),
                settings.adaptive
            );
            assert_eq!(out.pixel_rays.len(), 80, "{what}");
            let total: u64 = out.pixel_rays.iter().map(|r| r.total).sum();
            let camera: u64 = out.pixel_rays.iter().map(|r| r.camera).sum();
            let pass = match settings.integrator.kind {
                IntegratorKind::Photon => out.counts.photon,
                _ => 0,
            };
            assert_eq!(total, out.counts.total() - pass, "{what}");
            assert_eq!(camera, out.counts.camera, "{what}");
            // The acceleration structures' cost: the photon pass's belongs to no pixel.
            let cost = out
                .pixel_rays
                .iter()
                .fold(Cost::default(), |c, r| c + r.cost);
            assert!(cost.nodes > 0 && cost.tests > 0, "{what}");
            if pass == 0 {
                assert_eq!(cost, out.counts.cost, "{what}");
            } else {
                assert!(cost.nodes < out.counts.cost.nodes, "{what}");
            }
            let deepest = out.pixel_rays.iter().map(|r| r.deepest).max();
            assert_eq!(deepest, Some(out.counts.deepest), "{what}");
            let max_depth = settings.integrator.max_depth as u64;
            match settings.integrator.kind {
                IntegratorKind::Path | IntegratorKind::Bdpt => {
                    assert_eq!(deepest, Some(max_depth), "{what}")
                }
                _ => assert!(deepest <= Some(max_depth), "{what}"),
            }
            if settings.adaptive.is_none() {
                assert!(out.pixel_rays.iter().all(|r| r.camera == 4), "{what}");
            } else {
                let (least, most) = out.pixel_rays.iter().fold((u64::MAX, 0), |(a, b), r| {
                    (a.min(r.camera), b.max(r.camera))
                });
                assert!(least < most, "{what}: every pixel took {least} camera rays");
            }
            // (A crop is refused to both: their pixels are not rendered alone.)
            if settings.adaptive == Some(variance)
                || settings.integrator.kind == IntegratorKind::Bdpt
            {
                continue;
            }
            let part = RenderSettings {
                crop: Some(Crop {
                    x0: 2,
                    x1: 7,
                    y0: 3,
                    y1: 8,
                }),
                ..settings.clone()
            };
            let cropped = render(&scene, &part, &cancel, &|_, _| {}).pixel_rays;
            for (i, r) in cropped.iter().enumerate() {
                let (x, y) = (i % 5 + 2, i / 5 + 3);
                assert_eq!(*r, out.pixel_rays[y * 10 + x], "{what}: pixel ({x}, {y})");
            }
        }
    }

    /// Each ray tree adds up. Path tracing and photon mapping: the colours its rays
    /// return (each vertex's emission, light sample and photon estimates) sum to the
    /// sample's value. Light tracing: each sample's joins to the lens, summed where they
    /// land over every sample of every pixel, are the image (box filter). The kit's Cornell
    /// box, 8 × 8, 4 spp, RGB, seed 6. And BDPT's tree shows every light subpath, one whose
    /// first ray met nothing too (a point light over the kit's floor).
    #[test]
    fn every_methods_ray_tree_adds_up_to_what_it_renders() {
        let scene = kit::cornell_box(true);
        let settings = |kind| RenderSettings {
            width: 8,
            height: 8,
            sampler: PixelSampler::new(SamplerKind::Random, 4),
            integrator: IntegratorConfig {
                kind,
                color: plenum_spectrum::ColorMode::Rgb,
                photon: PhotonConfig {
                    photons: 3000,
                    caustic_photons: 3000,
                    ..PhotonConfig::default()
                },
                ..IntegratorConfig::default()
            },
            seed: 6,
            ..RenderSettings::default()
        };
        let close = |a: Color, b: Color, tolerance: f64| {
            [(a.r, b.r), (a.g, b.g), (a.b, b.b)]
                .iter()
                .all(|(x, y)| (x - y).abs() <= tolerance * (1.0 + y.abs()))
        };
        for kind in [IntegratorKind::Path, IntegratorKind::Photon] {
            let settings = settings(kind);
            let mut lit = 0;
            for (x, y, i) in (0..256).map(|k| (k % 8, (k / 8) % 8, k / 64)) {
                let (tree, value) = trace_sample(&scene, &settings, x, y, i).unwrap();
                let sum = tree.nodes.iter().fold(Color::BLACK, |s, n| s + n.color);
                assert!(
                    close(sum, value, 1e-9),
                    "{} ({x}, {y}) sample {i}: the tree gives {sum:?}, the sample {value:?}",
                    kind.name()
                );
                lit += usize::from(value.max_component() > 0.0);
            }
            assert!(lit > 128, "{}: {lit} samples lit", kind.name());
        }
        let light = settings(IntegratorKind::Light);
        let cancel = AtomicBool::new(false);
        let image = render(&scene, &light, &cancel, &|_, _| {}).film;
        let mut splats = vec![Color::BLACK; 64];
        for (x, y, i) in (0..256).map(|k| (k % 8, (k / 8) % 8, k / 64)) {
            let (tree, value) = trace_sample(&scene, &light, x, y, i).unwrap();
            assert_eq!(value, Color::BLACK, "light tracing's own estimate");
            for n in &tree.nodes {
                if let Some([rx, ry]) = n.strategy.and_then(|s| s.splat) {
                    let (px, py) = (rx.floor() as usize, ry.floor() as usize);
                    if px < 8 && py < 8 {
                        splats[py * 8 + px] += n.color * 0.25;
                    }
                }
            }
        }
        for (i, s) in splats.iter().enumerate() {
            let pixel = image.get(i as u32 % 8, i as u32 / 8);
            assert!(
                close(*s, pixel, 1e-6),
                "pixel {i}: trees {s:?}, image {pixel:?}"
            );
        }
        assert!(splats.iter().any(|s| s.max_component() > 0.0));
        // BDPT's tree shows every sample's light subpath, also one whose first ray left
        // the scene (half the point light's rays over the kit's floor go up and away).
        let scene = kit::lamp_over_floor(0.5, true);
        let bdpt = settings(IntegratorKind::Bdpt);
        let mut escaped = 0;
        for i in 0..4 {
            for (x, y) in [(1, 1), (4, 6), (7, 2), (5, 5)] {
                let (tree, _) = trace_sample(&scene, &bdpt, x, y, i).unwrap();
                let light: Vec<_> = tree
                    .nodes
                    .iter()
                    .filter(|n| n.kind == RayKind::Light)
                    .collect();
                assert!(!light.is_empty(), "({x}, {y}) sample {i}: no light subpath");
                escaped += usize::from(light.len() == 1 && light[0].stops.contains(&Stop::Miss));
            }
        }
        assert!(escaped > 0, "no light subpath escaped");
    }
}
