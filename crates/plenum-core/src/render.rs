//! Rendering an image: tiles in parallel with rayon, samples per pixel from the sampler,
//! radiance from the integrator.
//!
//! **Invariant:** the image depends only on the scene, the settings and the seed. Every pixel
//! is computed from its own samples whose random streams come from (seed, pixel, sample), and
//! tiles are written back by position, so the thread count changes nothing.

use crate::camera::Camera;
use crate::color::Color;
use crate::film::Film;
use crate::integrator::{RayCounts, RayTree, Whitted, WhittedConfig};
use crate::sampling::{PixelSampler, Rng};
use crate::scene::Scene;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub sampler: PixelSampler,
    pub integrator: WhittedConfig,
    pub seed: u64,
    /// The SPD test procedure (Haines 1987): one ray through every pixel corner, (W+1)×(H+1)
    /// rays in all, each pixel the average of its four corners. Replaces the sampler.
    pub corners: bool,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 640,
            height: 480,
            sampler: PixelSampler::Grid { n: 1 },
            integrator: WhittedConfig::default(),
            seed: 0,
            corners: false,
        }
    }
}

/// Side of the square tiles the image is cut into.
pub const TILE_SIZE: u32 = 16;

#[derive(Clone, Debug)]
pub struct RenderOutput {
    pub film: Film,
    pub counts: RayCounts,
    /// False when the render was cancelled: tiles not yet rendered are black.
    pub complete: bool,
}

/// Renders the scene. `cancel` stops the render between tiles; `progress(done, total)` is
/// called after each tile.
pub fn render(
    scene: &Scene,
    settings: &RenderSettings,
    cancel: &AtomicBool,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> RenderOutput {
    let camera = Camera::new(&scene.camera, settings.width, settings.height);
    let whitted = Whitted::new(scene, settings.integrator);
    // In corner mode the grid rendered is that of the corners, one ray each.
    let extra = u32::from(settings.corners);
    let (w, h) = (settings.width + extra, settings.height + extra);
    let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE_SIZE))
        .flat_map(|ty| (0..w.div_ceil(TILE_SIZE)).map(move |tx| (tx * TILE_SIZE, ty * TILE_SIZE)))
        .collect();
    let total = tiles.len();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let film = Mutex::new(Film::new(w, h));
    let counts = Mutex::new(RayCounts::default());
    let complete = AtomicBool::new(true);
    tiles.par_iter().for_each(|&(x0, y0)| {
        if cancel.load(Ordering::Relaxed) {
            complete.store(false, Ordering::Relaxed);
            return;
        }
        let (x1, y1) = ((x0 + TILE_SIZE).min(w), (y0 + TILE_SIZE).min(h));
        let mut tile_counts = RayCounts::default();
        let mut pixels = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
        for y in y0..y1 {
            for x in x0..x1 {
                let c = if settings.corners {
                    whitted.camera_ray(&camera.ray(x as f64, y as f64), &mut tile_counts, None)
                } else {
                    render_pixel(&whitted, &camera, settings, x, y, &mut tile_counts, None)
                };
                pixels.push((x, y, c));
            }
        }
        {
            let mut film = film.lock().unwrap_or_else(|e| e.into_inner());
            for (x, y, c) in pixels {
                film.set(x, y, c);
            }
        }
        counts
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .add(&tile_counts);
        progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
    });
    let film = film.into_inner().unwrap_or_else(|e| e.into_inner());
    RenderOutput {
        film: if settings.corners {
            average_corners(&film)
        } else {
            film
        },
        counts: counts.into_inner().unwrap_or_else(|e| e.into_inner()),
        complete: complete.load(Ordering::Relaxed),
    }
}

/// Each pixel of a corner grid's image: the mean of its four corners.
fn average_corners(corners: &Film) -> Film {
    let (w, h) = (corners.width - 1, corners.height - 1);
    let mut film = Film::new(w, h);
    for y in 0..h {
        for x in 0..w {
            let sum = corners.get(x, y)
                + corners.get(x + 1, y)
                + corners.get(x, y + 1)
                + corners.get(x + 1, y + 1);
            film.set(x, y, sum * 0.25);
        }
    }
    film
}

/// The average radiance of one pixel's samples (a box filter).
fn render_pixel(
    whitted: &Whitted,
    camera: &Camera,
    settings: &RenderSettings,
    x: u32,
    y: u32,
    counts: &mut RayCounts,
    mut tree: Option<&mut RayTree>,
) -> Color {
    if settings.corners {
        let mut sum = Color::BLACK;
        for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
            let ray = camera.ray(x as f64 + dx, y as f64 + dy);
            sum += whitted.camera_ray(&ray, counts, tree.as_deref_mut());
        }
        return sum * 0.25;
    }
    let spp = settings.sampler.samples_per_pixel();
    let mut sum = Color::BLACK;
    for index in 0..spp {
        let mut rng = Rng::for_sample(settings.seed, x, y, index);
        let (dx, dy) = settings.sampler.offset(index, &mut rng);
        let ray = camera.ray(x as f64 + dx, y as f64 + dy);
        sum += whitted.camera_ray(&ray, counts, tree.as_deref_mut());
    }
    sum / spp as f64
}

/// The ray tree of one pixel: every ray of every sample, and the pixel's colour.
pub fn trace_pixel(scene: &Scene, settings: &RenderSettings, x: u32, y: u32) -> (RayTree, Color) {
    let camera = Camera::new(&scene.camera, settings.width, settings.height);
    let whitted = Whitted::new(scene, settings.integrator);
    let mut tree = RayTree::default();
    let mut counts = RayCounts::default();
    let c = render_pixel(
        &whitted,
        &camera,
        settings,
        x,
        y,
        &mut counts,
        Some(&mut tree),
    );
    (tree, c)
}
