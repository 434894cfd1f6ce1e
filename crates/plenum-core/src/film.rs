//! The film: linear RGB radiance per pixel, row-major from the top-left.
//!
//! It accumulates two kinds of contribution, as pbrt-v4's `RGBFilm` does: weighted samples
//! of a pixel's own estimate (`add_sample`: the pixel is Σ w·L / Σ w), and splats, which
//! integrators that start paths on the lights (light tracing, bidirectional path tracing)
//! add to whatever pixel a path reaches (`add_splat`: summed, then scaled once by
//! `resolve`, by 1/spp for such an integrator).
//!
//! Light paths run on every thread at once, so their splats go first into a
//! [`SplatBuffer`], which sums in fixed point: integer addition does not depend on its order,
//! so the image is the same for any thread count, and the sums of renders split by sample
//! range add up to the sums of the whole.

use crate::color::Color;
use crate::sampling::Filter;
use std::sync::atomic::{AtomicI64, AtomicU64, Ordering};

#[derive(Clone, Debug)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    /// Σ w·L and Σ w per pixel.
    samples: Vec<[f64; 4]>,
    /// Σ L of the splats per pixel.
    splats: Vec<[f64; 3]>,
    /// The resolved image.
    pixels: Vec<[f32; 3]>,
}

impl Film {
    pub fn new(width: u32, height: u32) -> Film {
        let n = width as usize * height as usize;
        Film {
            width,
            height,
            samples: vec![[0.0; 4]; n],
            splats: vec![[0.0; 3]; n],
            pixels: vec![[0.0; 3]; n],
        }
    }

    fn index(&self, x: u32, y: u32) -> usize {
        y as usize * self.width as usize + x as usize
    }

    /// Sets pixel (x, y)'s own estimate to `c`, replacing its samples.
    pub fn set(&mut self, x: u32, y: u32, c: Color) {
        let i = self.index(x, y);
        self.samples[i] = [c.r, c.g, c.b, 1.0];
        self.pixels[i] = [c.r as f32, c.g as f32, c.b as f32];
    }

    /// Adds a sample of radiance `c` with filter weight `w` to pixel (x, y).
    pub fn add_sample(&mut self, x: u32, y: u32, c: Color, w: f64) {
        let i = self.index(x, y);
        let s = &mut self.samples[i];
        s[0] += w * c.r;
        s[1] += w * c.g;
        s[2] += w * c.b;
        s[3] += w;
    }

    /// Adds `c` to the pixel that raster point (px, py) falls in (a box filter); points off
    /// the film are dropped.
    pub fn add_splat(&mut self, px: f64, py: f64, c: Color) {
        if !(px >= 0.0 && py >= 0.0 && px < self.width as f64 && py < self.height as f64) {
            return;
        }
        let i = self.index(px as u32, py as u32);
        let s = &mut self.splats[i];
        s[0] += c.r;
        s[1] += c.g;
        s[2] += c.b;
    }

    /// Makes the image: each pixel's weighted mean of its samples (black without any) plus
    /// its splats times `splat_scale`.
    pub fn resolve(&mut self, splat_scale: f64) {
        for ((p, s), sp) in self.pixels.iter_mut().zip(&self.samples).zip(&self.splats) {
            let inv = if s[3] != 0.0 { 1.0 / s[3] } else { 0.0 };
            for c in 0..3 {
                p[c] = (s[c] * inv + sp[c] * splat_scale) as f32;
            }
        }
    }

    /// Adds the splats summed in `buffer`.
    pub fn add_splats(&mut self, buffer: &SplatBuffer) {
        self.add_splat_sums(&buffer.sums());
    }

    /// Adds splat sums in [`SplatBuffer`]'s fixed point, one per pixel.
    pub fn add_splat_sums(&mut self, sums: &[[i64; 3]]) {
        for (s, b) in self.splats.iter_mut().zip(sums) {
            for c in 0..3 {
                s[c] += b[c] as f64 * SplatBuffer::UNIT;
            }
        }
    }

    /// The resolved pixel (x, y).
    pub fn get(&self, x: u32, y: u32) -> Color {
        let p = self.pixels[self.index(x, y)];
        Color::new(p[0] as f64, p[1] as f64, p[2] as f64)
    }

    /// The resolved image, row by row.
    pub fn pixels(&self) -> &[[f32; 3]] {
        &self.pixels
    }
}

/// Splats from many threads at once, per pixel and channel, in fixed point: 32 bits of
/// fraction and 31 of integer part. Each splat is scaled by the render's splat factor
/// (1/spp) on the way in, so the sums are pixel values.
pub struct SplatBuffer {
    width: u32,
    height: u32,
    scale: f64,
    /// The pixel filter splats are spread by, and 1 / its integral; None: the box of one
    /// pixel, each splat in the pixel it lands in.
    filter: Option<(Filter, f64)>,
    sums: Vec<[AtomicI64; 3]>,
    /// Splats too large for the fixed point, clamped.
    clamped: AtomicU64,
}

impl SplatBuffer {
    const UNIT: f64 = 1.0 / 4_294_967_296.0;
    /// The largest single splat, in units: 2²⁴ in value, far above any pixel.
    const MAX: f64 = (1u64 << 56) as f64;

    pub fn new(width: u32, height: u32, scale: f64) -> SplatBuffer {
        let n = width as usize * height as usize;
        SplatBuffer {
            width,
            height,
            scale,
            filter: None,
            sums: (0..n).map(|_| Default::default()).collect(),
            clamped: AtomicU64::new(0),
        }
    }

    /// Spreads each splat over the pixels within `filter`'s radius, pixel (i, j) taking
    /// f(p − its centre) / ∫∫f of it (pbrt-v4's `RGBFilm::AddSplat`, normalised): the
    /// estimate of the same filtered pixel that camera samples drawn from the filter make.
    pub fn with_filter(mut self, filter: &Filter) -> SplatBuffer {
        if *filter != Filter::box_pixel() {
            self.filter = Some((filter.clone(), 1.0 / filter.integral()));
        }
        self
    }

    /// How far outside the image (in pixels) a splat can still reach a pixel.
    pub fn margin(&self) -> f64 {
        self.filter
            .as_ref()
            .map_or(0.0, |(f, _)| (f.radius() - 0.5).max(0.0))
    }

    /// Adds `c` × the buffer's scale at raster point `p`: to the pixel it falls in, or
    /// spread by the filter; what lands off the film and values that are not finite are
    /// dropped.
    pub fn add(&self, p: [f64; 2], c: Color) {
        let [px, py] = p;
        let Some((filter, norm)) = &self.filter else {
            if px >= 0.0 && py >= 0.0 && px < self.width as f64 && py < self.height as f64 {
                self.add_to(py as usize * self.width as usize + px as usize, c);
            }
            return;
        };
        let r = filter.radius();
        // Pixels whose centre (i + ½, j + ½) lies within r of p.
        let range = |v: f64, n: u32| {
            let lo = (v - 0.5 - r).ceil().max(0.0);
            let hi = (v - 0.5 + r).floor().min(n as f64 - 1.0);
            (lo as i64)..=(hi as i64)
        };
        if !(px.is_finite() && py.is_finite()) {
            return;
        }
        for j in range(py, self.height) {
            let fy = filter.profile(py - (j as f64 + 0.5));
            if fy == 0.0 {
                continue;
            }
            for i in range(px, self.width) {
                let w = fy * filter.profile(px - (i as f64 + 0.5)) * norm;
                if w != 0.0 {
                    self.add_to(j as usize * self.width as usize + i as usize, c * w);
                }
            }
        }
    }

    fn add_to(&self, i: usize, c: Color) {
        for (sum, v) in self.sums[i].iter().zip([c.r, c.g, c.b]) {
            let units = (v * self.scale / Self::UNIT).round();
            if !units.is_finite() || units == 0.0 {
                continue;
            }
            if units.abs() > Self::MAX {
                self.clamped.fetch_add(1, Ordering::Relaxed);
            }
            sum.fetch_add(units.clamp(-Self::MAX, Self::MAX) as i64, Ordering::Relaxed);
        }
    }

    /// The sums so far, per pixel, in fixed point.
    pub fn sums(&self) -> Vec<[i64; 3]> {
        self.sums
            .iter()
            .map(|s| s.each_ref().map(|v| v.load(Ordering::Relaxed)))
            .collect()
    }

    /// Starts from `sums` (a render being continued), one per pixel.
    pub fn preload(&self, sums: &[[i64; 3]]) {
        for (s, v) in self.sums.iter().zip(sums) {
            for c in 0..3 {
                s[c].store(v[c], Ordering::Relaxed);
            }
        }
    }

    /// How many splat values were too large and were clamped.
    pub fn clamped(&self) -> u64 {
        self.clamped.load(Ordering::Relaxed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_average_by_weight_and_splats_add_scaled() {
        let mut film = Film::new(2, 2);
        film.add_sample(0, 0, Color::new(1.0, 2.0, 3.0), 1.0);
        film.add_sample(0, 0, Color::new(3.0, 2.0, 1.0), 3.0);
        film.add_splat(1.5, 0.2, Color::gray(4.0));
        film.add_splat(1.9, 0.9, Color::gray(2.0));
        film.add_splat(-0.1, 0.5, Color::gray(100.0));
        film.add_splat(2.0, 0.5, Color::gray(100.0));
        film.set(0, 1, Color::gray(0.5));
        film.resolve(0.25);
        assert_eq!(film.get(0, 0), Color::new(2.5, 2.0, 1.5));
        assert_eq!(film.get(1, 0), Color::gray(1.5));
        assert_eq!(film.get(0, 1), Color::gray(0.5));
        assert_eq!(film.get(1, 1), Color::BLACK);
    }

    /// A filtered splat spreads over the pixels within the filter's radius with weights
    /// f / ∫∫f: averaged over where in a pixel it lands (a 64×64 grid of points), they sum to
    /// 1 within 10⁻³ for every filter, and a splat in the middle of a pixel gives that pixel
    /// f(0, 0) / ∫∫f.
    #[test]
    fn filtered_splats_keep_their_total() {
        use crate::sampling::FilterKind;
        for kind in [
            FilterKind::Box,
            FilterKind::Tent,
            FilterKind::Gaussian,
            FilterKind::Mitchell,
            FilterKind::Lanczos,
        ] {
            let filter = Filter::new(kind, kind.default_radius().max(0.75)).unwrap();
            let buffer = SplatBuffer::new(9, 9, 1.0).with_filter(&filter);
            let n = 64;
            for j in 0..n {
                for i in 0..n {
                    let p = [
                        4.0 + (i as f64 + 0.5) / n as f64,
                        4.0 + (j as f64 + 0.5) / n as f64,
                    ];
                    buffer.add(p, Color::gray(1.0 / (n * n) as f64));
                }
            }
            let mut film = Film::new(9, 9);
            film.add_splats(&buffer);
            film.resolve(1.0);
            let total: f64 = film.pixels().iter().map(|p| p[0] as f64).sum();
            assert!((total - 1.0).abs() < 1e-3, "{}: total {total}", kind.name());

            let centre = SplatBuffer::new(9, 9, 1.0).with_filter(&filter);
            centre.add([4.5, 4.5], Color::gray(1.0));
            let mut film = Film::new(9, 9);
            film.add_splats(&centre);
            film.resolve(1.0);
            let expected = filter.evaluate(0.0, 0.0) / filter.integral();
            let got = film.get(4, 4).r;
            assert!(
                (got - expected).abs() < 1e-6,
                "{}: {got} for {expected}",
                kind.name()
            );
        }
    }

    /// The fixed-point sums do not depend on the order of the splats.
    #[test]
    fn splat_sums_ignore_order() {
        let values: Vec<f64> = (0..1000)
            .map(|i| ((i * 7919) % 1000) as f64 * 1e-3 + 1e-7)
            .collect();
        let forward = SplatBuffer::new(1, 1, 0.5);
        let backward = SplatBuffer::new(1, 1, 0.5);
        for &v in &values {
            forward.add([0.5, 0.5], Color::new(v, 2.0 * v, 1e6 * v));
        }
        for &v in values.iter().rev() {
            backward.add([0.5, 0.5], Color::new(v, 2.0 * v, 1e6 * v));
        }
        let (mut a, mut b) = (Film::new(1, 1), Film::new(1, 1));
        a.add_splats(&forward);
        b.add_splats(&backward);
        a.resolve(1.0);
        b.resolve(1.0);
        assert_eq!(a.get(0, 0), b.get(0, 0));
        let sum: f64 = values.iter().sum();
        assert!(
            (a.get(0, 0).r - 0.5 * sum).abs() < 1e-4,
            "the resolved film is f32"
        );
        forward.add([0.5, 0.5], Color::gray(1e12));
        assert_eq!(forward.clamped(), 3);
    }
}
