//! The raw film: what a render has summed so far, exactly, so that it can be saved,
//! continued and added to other renders' sums.
//!
//! Each pixel keeps Σ w·L, Σ w and Σ L of its samples in fixed point: every sample is
//! rounded to a multiple of 2⁻³² first and the sums are integers, so they do not depend on
//! the order the samples were added in. A render stopped and continued, or split into sample
//! ranges on several machines and merged, therefore sums to the same integers as one
//! uninterrupted render and resolves to the same bytes. (Splats are summed the same way, in
//! [`SplatBuffer`](crate::film::SplatBuffer).)
//!
//! Stochastic progressive photon mapping keeps other state: per pixel its gather radius, the
//! photons and flux it has kept, and the light its camera passes found, after whole
//! iterations ([`Progressive`]). Each iteration continues from the last one's radii, so an
//! SPPM film can be continued but not split.

use crate::color::Color;
use crate::film::Film;
use std::ops::Range;

/// Fixed-point units per unit of radiance (or filter weight): 2³².
const SCALE: f64 = 4_294_967_296.0;
/// The largest sample, in units (2⁶⁸ in value): 2¹⁶ of them still fit an `i128`.
const MAX_UNITS: i128 = 1 << 100;

#[inline]
fn units(v: f64) -> i128 {
    let x = (v * SCALE).round();
    // Nearly every sample fits an i64 (below 2³¹ in value), whose conversion is one
    // instruction where an i128's is a library call; the same integer either way.
    if x.abs() < I64_EXACT {
        // SAFETY: an integer below 2⁶² in magnitude (not NaN, which fails the test) is an
        // i64: the conversion needs none of `as`'s saturation checks.
        return unsafe { x.to_int_unchecked::<i64>() } as i128;
    }
    // `as` saturates (and maps NaN to 0); the integrators have already left out samples
    // that are not finite.
    (x as i128).clamp(-MAX_UNITS, MAX_UNITS)
}

/// 2⁶²: every integer-valued f64 below it in magnitude converts to an i64 exactly.
const I64_EXACT: f64 = 4_611_686_018_427_387_904.0;

fn value(units: i128) -> f64 {
    units as f64 / SCALE
}

/// One pixel's samples so far.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelSums {
    /// Σ w·L per channel, in units of 2⁻³².
    pub weighted: [i128; 3],
    /// Σ w, in units of 2⁻³².
    pub weight: i128,
    /// Σ L per channel, in units of 2⁻³².
    pub plain: [i128; 3],
    /// Σ (w·L)² per channel, for the variance of the pixel's value: in floating point (half
    /// the memory of the exact sums), so a resumed or merged render's variance image may
    /// differ from one render's in its last bits; its image does not.
    pub weighted_squared: [f64; 3],
    pub count: u32,
    /// Σ Y and Σ Y² of the samples' luminance, for adaptive sampling, in the order the
    /// samples were taken (adaptive renders are continued, never split).
    pub luminance: f64,
    pub luminance_squared: f64,
}

impl PixelSums {
    /// A pixel computed whole (adaptive subdivision, a corner ray): one sample of `c`.
    pub fn single(c: Color) -> PixelSums {
        let mut s = PixelSums::default();
        s.add(c, 1.0);
        s
    }

    pub fn add(&mut self, c: Color, weight: f64) {
        if weight == 1.0 {
            // A box filter's sample (and any sample of weight 1): w·L is L, so one
            // conversion serves both sums, with the integers the general case gives.
            for (i, v) in [c.r, c.g, c.b].into_iter().enumerate() {
                let u = units(v);
                self.weighted[i] += u;
                self.plain[i] += u;
                self.weighted_squared[i] += v * v;
            }
            self.weight += 1 << 32;
        } else {
            for (i, v) in [c.r, c.g, c.b].into_iter().enumerate() {
                let wl = v * weight;
                self.weighted[i] += units(wl);
                self.plain[i] += units(v);
                self.weighted_squared[i] += wl * wl;
            }
            self.weight += units(weight);
        }
        self.count += 1;
        let y = c.luminance();
        self.luminance += y;
        self.luminance_squared += y * y;
    }

    /// Σ w·L / Σ w; should the weights of a filter with negative lobes cancel out (a few
    /// samples, all unlucky), the plain mean instead of a division by nearly zero.
    /// The samples' plain mean, without the filter's weights: for one sample, its colour
    /// (to 2⁻³²).
    pub fn plain_mean(&self) -> Color {
        let n = self.count.max(1) as f64;
        let [r, g, b] = self.plain.map(|s| value(s) / n);
        Color::new(r, g, b)
    }

    pub fn value(&self) -> Color {
        let w = self.weight as f64;
        if value(self.weight) > 0.25 * self.count as f64 {
            let [r, g, b] = self.weighted.map(|s| s as f64 / w);
            Color::new(r, g, b)
        } else {
            let n = self.count.max(1) as f64;
            let [r, g, b] = self.plain.map(|s| value(s) / n);
            Color::new(r, g, b)
        }
    }

    /// The variance of [`value`](Self::value) as an estimate of the pixel's true value, per
    /// channel, from its own samples: the sample variance of w·L over n, divided by the
    /// mean weight squared (the ratio estimator's first-order variance; exact for filters
    /// whose samples all weigh the same, the box among them). 0 below two samples.
    pub fn variance(&self) -> Color {
        let n = self.count as f64;
        let mean_weight = value(self.weight) / n;
        if self.count < 2 || mean_weight <= 0.0 {
            return Color::BLACK;
        }
        let v = |c: usize| {
            let sum = value(self.weighted[c]);
            let squares = self.weighted_squared[c];
            let sample_variance = ((squares - sum * sum / n) / (n - 1.0)).max(0.0);
            sample_variance / n / (mean_weight * mean_weight)
        };
        Color::new(v(0), v(1), v(2))
    }

    /// Whether the standard error of the luminance is at most `threshold` × max(mean, 0.05).
    pub fn converged(&self, threshold: f64) -> bool {
        let n = self.count as f64;
        if self.count < 2 {
            return false;
        }
        let mean = self.luminance / n;
        let variance = ((self.luminance_squared - n * mean * mean) / (n - 1.0)).max(0.0);
        (variance / n).sqrt() <= threshold * mean.max(0.05)
    }

    fn merge(&mut self, o: &PixelSums) {
        for i in 0..3 {
            self.weighted[i] += o.weighted[i];
            self.plain[i] += o.plain[i];
            self.weighted_squared[i] += o.weighted_squared[i];
        }
        self.weight += o.weight;
        self.count += o.count;
        self.luminance += o.luminance;
        self.luminance_squared += o.luminance_squared;
    }
}

/// A render's state: every pixel's sums, how far each pixel has got, and the splats.
#[derive(Clone, Debug, PartialEq)]
pub struct RawFilm {
    /// Of the grid sampled: the image, or its corner lattice (one more each way).
    pub width: u32,
    pub height: u32,
    /// The SPD corner grid: each pixel of the image is the mean of four of these.
    pub corners: bool,
    /// The sample indices this film is to hold of every pixel (a fixed-count render);
    /// pixel p holds `samples.start .. samples.start + count`.
    pub samples: Range<u32>,
    /// The samples per pixel of the whole render, `samples` being part of them: the
    /// splats were divided by it.
    pub spp: u32,
    pub pixels: Vec<PixelSums>,
    /// Per pixel, the passes finished: a pixel is done after 1 (after 2 when sampling by
    /// variance). Tiles are rendered whole, so a checkpoint holds whole tiles.
    pub stages: Vec<u8>,
    /// Sampling by variance, once its first pass is done: the pixels not converged after it.
    pub open: Vec<bool>,
    /// Splat sums per pixel, in [`SplatBuffer`](crate::film::SplatBuffer)'s fixed point;
    /// empty for integrators that do not splat.
    pub splats: Vec<[i64; 3]>,
    /// SPPM's state, whose iterations are `samples`; its `pixels` and `stages` are empty.
    pub progressive: Option<Progressive>,
}

/// One pixel of stochastic progressive photon mapping (Hachisuka and Jensen 2009) between
/// iterations.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhotonStatistics {
    /// The gather radius r; 0 until the pixel's first visible point sets it.
    pub radius: f64,
    /// The photons kept, N.
    pub photons: f64,
    /// The flux kept, τ, linear sRGB.
    pub flux: [f64; 3],
    /// The sum over iterations of the light the camera passes found, linear sRGB.
    pub direct: [f64; 3],
}

/// SPPM's film: every pixel's statistics after `iterations` whole iterations.
#[derive(Clone, Debug, PartialEq)]
pub struct Progressive {
    pub iterations: u32,
    /// Photon paths traced per iteration.
    pub photons_per_iteration: u64,
    pub pixels: Vec<PhotonStatistics>,
}

impl Progressive {
    /// A pixel's estimate: L_d / iterations + τ / (N_e π r²), N_e the photon paths of all
    /// iterations.
    pub fn value(&self, px: &PhotonStatistics) -> Color {
        let done = self.iterations.max(1) as f64;
        let area = std::f64::consts::PI * px.radius * px.radius;
        let emitted = done * self.photons_per_iteration as f64;
        let l = |c: usize| {
            let gathered = if area > 0.0 && emitted > 0.0 {
                px.flux[c] / (emitted * area)
            } else {
                0.0
            };
            px.direct[c] / done + gathered
        };
        Color::new(l(0), l(1), l(2))
    }
}

impl RawFilm {
    pub fn new(width: u32, height: u32, corners: bool, samples: Range<u32>) -> RawFilm {
        let n = width as usize * height as usize;
        RawFilm {
            pixels: vec![PixelSums::default(); n],
            stages: vec![0; n],
            ..RawFilm::empty(width, height, corners, samples)
        }
    }

    /// A film of that size holding no pixels yet, for a reader to fill.
    pub fn empty(width: u32, height: u32, corners: bool, samples: Range<u32>) -> RawFilm {
        RawFilm {
            width,
            height,
            corners,
            spp: samples.end,
            samples,
            pixels: Vec::new(),
            stages: Vec::new(),
            open: Vec::new(),
            splats: Vec::new(),
            progressive: None,
        }
    }

    /// An empty SPPM film of `iterations` iterations, `photons` photon paths each.
    pub fn progressive(width: u32, height: u32, iterations: u32, photons: u64) -> RawFilm {
        RawFilm {
            progressive: Some(Progressive {
                iterations: 0,
                photons_per_iteration: photons,
                pixels: vec![PhotonStatistics::default(); width as usize * height as usize],
            }),
            ..RawFilm::empty(width, height, false, 0..iterations)
        }
    }

    /// Whether every pixel has finished `passes` passes.
    pub fn is_complete(&self, passes: u8) -> bool {
        match &self.progressive {
            Some(p) => p.iterations >= self.samples.end,
            None => self.stages.iter().all(|&s| s >= passes),
        }
    }

    /// The image: each pixel's weighted mean plus its splats; for a corner grid, each pixel
    /// the mean of its four corners. Splats were divided by the whole render's samples per
    /// pixel; a film of part of them is scaled up to its own.
    pub fn image(&self) -> Film {
        let mut film = Film::new(self.width, self.height);
        if let Some(p) = &self.progressive {
            for (i, px) in p.pixels.iter().enumerate() {
                let w = self.width as usize;
                film.set((i % w) as u32, (i / w) as u32, p.value(px));
            }
            return film;
        }
        for y in 0..self.height {
            for x in 0..self.width {
                let i = y as usize * self.width as usize + x as usize;
                film.set(x, y, self.pixels[i].value());
            }
        }
        if !self.splats.is_empty() {
            film.add_splat_sums(&self.splats);
        }
        let held = self.samples.len() as f64;
        film.resolve(if held > 0.0 {
            self.spp as f64 / held
        } else {
            1.0
        });
        if !self.corners {
            return film;
        }
        let (w, h) = (self.width - 1, self.height - 1);
        let mut image = Film::new(w, h);
        for y in 0..h {
            for x in 0..w {
                let sum = film.get(x, y)
                    + film.get(x + 1, y)
                    + film.get(x, y + 1)
                    + film.get(x + 1, y + 1);
                image.set(x, y, sum * 0.25);
            }
        }
        image
    }

    /// Each pixel's variance of its value, from its own samples (a Mitsuba `moment`-style
    /// variance image, so that one render can be z-tested); `None` where the pixels' own
    /// samples do not make the image: splats (light tracing, BDPT), SPPM's iterations, the
    /// SPD corners.
    pub fn variance_image(&self) -> Option<Film> {
        if !self.splats.is_empty() || self.progressive.is_some() || self.corners {
            return None;
        }
        let mut film = Film::new(self.width, self.height);
        for (i, px) in self.pixels.iter().enumerate() {
            let w = self.width as usize;
            film.set((i % w) as u32, (i / w) as u32, px.variance());
        }
        film.resolve(1.0);
        Some(film)
    }

    /// The sum of renders of consecutive sample ranges of one image, each complete: the
    /// film of their whole range. Parts are added in the order of their ranges.
    pub fn merge(mut parts: Vec<RawFilm>) -> Result<RawFilm, String> {
        parts.sort_by_key(|p| (p.samples.start, p.samples.end));
        let mut parts = parts.into_iter();
        let Some(mut sum) = parts.next() else {
            return Err("nothing to merge".to_string());
        };
        if sum.progressive.is_some() {
            return Err(SPPM_UNSPLIT.to_string());
        }
        if sum.corners || !sum.open.is_empty() {
            return Err("only renders with a fixed number of samples per pixel can be merged (not adaptive sampling or the SPD corners)".to_string());
        }
        if !sum.is_complete(1) {
            return Err(format!(
                "the part of samples {}..{} is not finished: resume it first",
                sum.samples.start, sum.samples.end
            ));
        }
        for part in parts {
            let (a, b) = (&sum.samples, &part.samples);
            if (part.width, part.height) != (sum.width, sum.height) {
                return Err(format!(
                    "the parts differ in size: {}×{} and {}×{}",
                    sum.width, sum.height, part.width, part.height
                ));
            }
            if b.start < a.end {
                return Err(format!(
                    "sample ranges {}..{} and {}..{} overlap: their samples would count twice",
                    a.start, a.end, b.start, b.end
                ));
            }
            if b.start > a.end {
                return Err(format!(
                    "samples {}..{} are missing between the parts",
                    a.end, b.start
                ));
            }
            if part.progressive.is_some() {
                return Err(SPPM_UNSPLIT.to_string());
            }
            if part.splats.len() != sum.splats.len()
                || part.corners
                || !part.open.is_empty()
                || part.spp != sum.spp
            {
                return Err("the parts were rendered differently".to_string());
            }
            if !part.is_complete(1) {
                return Err(format!(
                    "the part of samples {}..{} is not finished: resume it first",
                    b.start, b.end
                ));
            }
            for (s, p) in sum.pixels.iter_mut().zip(&part.pixels) {
                s.merge(p);
            }
            for (s, p) in sum.splats.iter_mut().zip(&part.splats) {
                for c in 0..3 {
                    s[c] = s[c].wrapping_add(p[c]);
                }
            }
            sum.samples = sum.samples.start..part.samples.end;
        }
        Ok(sum)
    }
}

const SPPM_UNSPLIT: &str = "SPPM renders cannot be merged: each iteration gathers within the radii the iterations before it left, so iterations cannot be rendered apart (render it whole; --checkpoint keeps it safe)";

#[cfg(test)]
mod tests {
    use super::*;

    /// A sample of weight 1 sums to the integers of the general case (weight 1 + 2⁻⁵², one
    /// ulp off, takes it; its weight's units round to 2³² too).
    #[test]
    fn a_sample_of_weight_one_sums_as_any_weight_does() {
        let colors = [
            Color::new(0.25, 1.0 / 3.0, 7.5),
            Color::new(0.0, 1e-12, 123456.789),
            Color::new(3e9, 0.1, 0.7),
        ];
        let (mut one, mut general) = (PixelSums::default(), PixelSums::default());
        for c in colors {
            one.add(c, 1.0);
            // The general case, by hand, at weight exactly 1.
            for (i, v) in [c.r, c.g, c.b].into_iter().enumerate() {
                general.weighted[i] += units(v * 1.0);
                general.plain[i] += units(v);
                general.weighted_squared[i] += (v * 1.0) * (v * 1.0);
            }
            general.weight += units(1.0);
            general.count += 1;
            let y = c.luminance();
            general.luminance += y;
            general.luminance_squared += y * y;
        }
        assert_eq!(one, general);
        let mut near = PixelSums::default();
        near.add(colors[0], 1.0 + f64::EPSILON);
        assert_eq!(near.weight, one.weight / 3);
    }

    /// The i64 shortcut gives the integer the i128 conversion gives, on both sides of
    /// where it stops applying, and saturates and maps NaN as before.
    #[test]
    fn units_convert_as_i128_does() {
        let edge = I64_EXACT / SCALE;
        for v in [
            0.0,
            -0.0,
            0.5 / SCALE,
            -1.5 / SCALE,
            1.0,
            -3.25,
            1e9,
            -2.0e9,
            edge,
            edge * (1.0 - f64::EPSILON),
            -edge,
            edge * 2.0,
            1e30,
            -1e30,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ] {
            let slow = ((v * SCALE).round() as i128).clamp(-MAX_UNITS, MAX_UNITS);
            assert_eq!(units(v), slow, "{v}");
        }
    }

    /// Sums do not depend on the order samples arrive in, nor on how they are split up.
    #[test]
    fn sums_are_exact_in_any_order() {
        let samples: Vec<(Color, f64)> = (0..200)
            .map(|i| {
                let t = i as f64;
                (
                    Color::new((t * 0.37).sin().abs() * 1e3, 1.0 / (t + 1.0), t.sqrt()),
                    0.1 + (t * 0.11).cos().abs(),
                )
            })
            .collect();
        let mut forward = PixelSums::default();
        samples.iter().for_each(|&(c, w)| forward.add(c, w));
        let mut backward = PixelSums::default();
        samples.iter().rev().for_each(|&(c, w)| backward.add(c, w));
        assert_eq!(forward.weighted, backward.weighted);
        assert_eq!(forward.weight, backward.weight);
        assert_eq!(forward.plain, backward.plain);
        let mut parts = Vec::new();
        for range in [0..70, 70..71, 71..200] {
            let mut film = RawFilm::new(1, 1, false, range.start as u32..range.end as u32);
            samples[range]
                .iter()
                .for_each(|&(c, w)| film.pixels[0].add(c, w));
            film.stages[0] = 1;
            film.spp = 200;
            parts.push(film);
        }
        parts.swap(0, 2);
        let merged = RawFilm::merge(parts).unwrap();
        assert_eq!(merged.samples, 0..200);
        assert_eq!(merged.pixels[0].weighted, forward.weighted);
        assert_eq!(merged.pixels[0].count, 200);
        assert_eq!(merged.image().get(0, 0), {
            let mut f = RawFilm::new(1, 1, false, 0..200);
            f.pixels[0] = forward;
            f.image().get(0, 0)
        });
        // Within the rounding of 2⁻³² per sample of the floating-point weighted mean.
        let (sw, swl) = samples
            .iter()
            .fold((0.0, 0.0), |(sw, swl), &(c, w)| (sw + w, swl + w * c.g));
        assert!((forward.value().g - swl / sw).abs() < 1e-9);
    }

    /// With equal weights the variance is the samples' sample variance over n, exactly
    /// (to the 2⁻³² rounding); with other constant weights the same; below two samples 0.
    #[test]
    fn variance_of_the_mean_from_the_samples() {
        let values = [0.5, 1.5, 4.0, 2.0, 0.25];
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let expected = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0) / n;
        for weight in [1.0, 0.37] {
            let mut px = PixelSums::default();
            for v in values {
                px.add(Color::new(v, 2.0 * v, 0.0), weight);
            }
            let var = px.variance();
            assert!(
                (var.r - expected).abs() < 1e-8,
                "{weight}: {} for {expected}",
                var.r
            );
            assert!((var.g - 4.0 * expected).abs() < 1e-8);
            assert_eq!(var.b, 0.0);
        }
        assert_eq!(
            PixelSums::single(Color::new(3.0, 3.0, 3.0)).variance(),
            Color::BLACK
        );
    }

    #[test]
    fn merge_refuses_overlaps_and_gaps() {
        let part = |r: Range<u32>| {
            let mut f = RawFilm::new(2, 2, false, r);
            f.stages.fill(1);
            f.spp = 8;
            f
        };
        let e = RawFilm::merge(vec![part(0..4), part(3..8)]).unwrap_err();
        assert!(e.contains("overlap"), "{e}");
        let e = RawFilm::merge(vec![part(0..4), part(5..8)]).unwrap_err();
        assert!(e.contains("4..5 are missing"), "{e}");
        let e = RawFilm::merge(vec![part(0..4), RawFilm::new(2, 3, false, 4..8)]).unwrap_err();
        assert!(e.contains("size"), "{e}");
        let mut unfinished = part(4..8);
        unfinished.stages[3] = 0;
        let e = RawFilm::merge(vec![part(0..4), unfinished]).unwrap_err();
        assert!(e.contains("4..8 is not finished"), "{e}");
    }
}
