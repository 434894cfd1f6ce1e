//! Pixel reconstruction filters, applied by filter importance sampling (Ernst, Stamminger
//! and Greiner 2006, "Filter importance sampling"; pbrt-v4 §8.8).
//!
//! Rather than splatting each sample into every pixel within the filter's radius, Plenum
//! draws each pixel sample's offset from the pixel centre with density ∝ |f|, and gives it
//! the weight sign(f) = ±1; the pixel value is Σ weight·L / Σ weight over its own samples.
//! Why:
//!
//! - Every pixel is computed from its own samples only. Tiles are independent, with no
//!   shared accumulation buffer, no locks or atomics, and no seams at tile borders, so the
//!   image is bit-identical for any thread count.
//! - The warp from [0, 1)² to the offset is continuous and monotone along each axis, so the
//!   stratification of the pixel sampler (jittered, Sobol) carries through to the offsets.
//! - Adaptive sampling stays per pixel: a pixel's estimate and its error depend on nothing
//!   but the samples it took.
//!
//! The cost: for filters with negative lobes (Mitchell, Lanczos) the ±1 weights add some
//! variance compared with splatting the exact filter values, and with very few samples
//! Σ weight can be small (or zero), which the film must guard against.
//!
//! Every filter is separable, f(x, y) = f₁(x) f₁(y), with the 1-D profile f₁ supported on
//! [−r, r] (x in pixels); see [`FilterKind`] for each profile.

use std::f64::consts::PI;
use std::fmt;
use std::str::FromStr;

/// The shape of a pixel filter. Each profile f₁ below is zero outside [−r, r].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FilterKind {
    /// f₁ = 1: plain averaging over the square of half-width r.
    Box,
    /// f₁ = max(0, 1 − |x|/r).
    Tent,
    /// f₁ = exp(−αx²) − exp(−αr²) with α = 2, a Gaussian of standard deviation 1/2 pixel
    /// shifted down to reach zero at r.
    Gaussian,
    /// Mitchell & Netravali 1988 with B = C = 1/3, its natural support [−2, 2] scaled to
    /// [−r, r]; it has small negative lobes.
    Mitchell,
    /// Lanczos-r: sinc(x) sinc(x/r), sinc(x) = sin(πx)/(πx); negative lobes.
    Lanczos,
}

impl FilterKind {
    pub const ALL: [FilterKind; 5] = [
        FilterKind::Box,
        FilterKind::Tent,
        FilterKind::Gaussian,
        FilterKind::Mitchell,
        FilterKind::Lanczos,
    ];

    /// The names [`FromStr`] accepts, for messages.
    pub const NAMES: &'static str = "box, tent, gaussian, mitchell or lanczos";

    pub fn name(self) -> &'static str {
        match self {
            FilterKind::Box => "box",
            FilterKind::Tent => "tent",
            FilterKind::Gaussian => "gaussian",
            FilterKind::Mitchell => "mitchell",
            FilterKind::Lanczos => "lanczos",
        }
    }

    /// The radius, in pixels, the filter is usually run at.
    pub fn default_radius(self) -> f64 {
        match self {
            FilterKind::Box => 0.5,
            FilterKind::Tent => 1.0,
            FilterKind::Gaussian => 1.5,
            FilterKind::Mitchell => 2.0,
            FilterKind::Lanczos => 3.0,
        }
    }
}

impl FromStr for FilterKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        FilterKind::ALL
            .into_iter()
            .find(|kind| kind.name() == s)
            .ok_or_else(|| format!("unknown filter `{s}`: expected {}", FilterKind::NAMES))
    }
}

impl fmt::Display for FilterKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// α of the Gaussian profile exp(−αx²): 1/(2σ²) for σ = 1/2 pixel.
const GAUSSIAN_ALPHA: f64 = 2.0;

/// Mitchell–Netravali's B and C: the pair they recommend, on the line B + 2C = 1.
const MITCHELL_B: f64 = 1.0 / 3.0;
const MITCHELL_C: f64 = 1.0 / 3.0;

/// Segments of the tabulated cumulative distribution over [−r, r]. With 512, the piecewise
/// constant density departs from |f₁| only within segments of r/256 pixels.
const SEGMENTS: usize = 512;

/// A pixel filter of one kind and radius, ready to evaluate and to sample.
#[derive(Clone, Debug, PartialEq)]
pub struct Filter {
    kind: FilterKind,
    radius: f64,
    /// The cumulative distribution of |f₁| at the SEGMENTS + 1 evenly spaced points of
    /// [−r, r], from 0 to 1; empty for box and tent, which invert in closed form.
    cdf: Box<[f64]>,
}

/// One sampled offset from the pixel centre, in pixels, with its weight sign(f(dx, dy)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterSample {
    pub dx: f64,
    pub dy: f64,
    /// +1 or −1; the pixel value is Σ weight·L / Σ weight.
    pub weight: f64,
}

impl Default for Filter {
    fn default() -> Filter {
        Filter::box_pixel()
    }
}

impl Filter {
    /// A filter of `kind` with `radius` in pixels, which must be finite and positive.
    pub fn new(kind: FilterKind, radius: f64) -> Result<Filter, String> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(format!(
                "filter radius must be finite and greater than 0, got {radius}"
            ));
        }
        let mut filter = Filter {
            kind,
            radius,
            cdf: Box::new([]),
        };
        if !matches!(kind, FilterKind::Box | FilterKind::Tent) {
            filter.cdf = filter
                .tabulate()
                .ok_or_else(|| format!("filter radius {radius} is too small to sample"))?;
        }
        Ok(filter)
    }

    /// The box of radius ½: each sample uniform over its own pixel, equally weighted.
    pub fn box_pixel() -> Filter {
        Filter {
            kind: FilterKind::Box,
            radius: 0.5,
            cdf: Box::new([]),
        }
    }

    pub fn kind(&self) -> FilterKind {
        self.kind
    }

    /// The radius, in pixels.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The filter's value at offset (x, y) pixels from the pixel centre; 1 at the centre for
    /// box, tent and Lanczos.
    pub fn evaluate(&self, x: f64, y: f64) -> f64 {
        self.profile(x) * self.profile(y)
    }

    /// ∫∫ f over the plane, in pixels²: what a splat's weights are divided by, so that the
    /// weights a splat gives the pixels around it sum to 1 (on average over its position).
    pub fn integral(&self) -> f64 {
        let r = self.radius;
        let one_d = match self.kind {
            FilterKind::Box => 2.0 * r,
            FilterKind::Tent => r,
            // Simpson's rule on 4096 intervals: the profiles are smooth within [−r, r].
            _ => {
                let n = 4096;
                let h = 2.0 * r / n as f64;
                let sum: f64 = (0..=n)
                    .map(|i| {
                        let w = match i {
                            0 => 1.0,
                            i if i == n => 1.0,
                            i if i % 2 == 1 => 4.0,
                            _ => 2.0,
                        };
                        w * self.profile(-r + h * i as f64)
                    })
                    .sum();
                sum * h / 3.0
            }
        };
        one_d * one_d
    }

    /// The 1-D profile f₁ at offset `x` pixels.
    pub fn profile(&self, x: f64) -> f64 {
        let r = self.radius;
        let a = x.abs();
        if a > r {
            return 0.0;
        }
        match self.kind {
            FilterKind::Box => 1.0,
            FilterKind::Tent => 1.0 - a / r,
            // e^(−αa²) − e^(−αr²) as e^(−αr²)·(e^(α(r−a)(r+a)) − 1): no cancellation for
            // small radii.
            FilterKind::Gaussian => {
                let tail = (-GAUSSIAN_ALPHA * r * r).exp();
                tail * (GAUSSIAN_ALPHA * (r - a) * (r + a)).exp_m1()
            }
            FilterKind::Mitchell => mitchell(2.0 * a / r),
            FilterKind::Lanczos => sinc(a) * sinc(a / r),
        }
    }

    /// An offset from the pixel centre drawn with density |f(dx, dy)| / ∫∫|f| from `u` in
    /// [0, 1)², and its weight sign(f). Each axis is warped monotonically and continuously,
    /// so strata of `u` stay strata of offsets; u = (½, ½) gives the centre.
    pub fn sample(&self, u: [f64; 2]) -> FilterSample {
        let r = self.radius;
        let (dx, dy) = match self.kind {
            FilterKind::Box => (r * (2.0 * u[0] - 1.0), r * (2.0 * u[1] - 1.0)),
            FilterKind::Tent => (r * tent_inverse(u[0]), r * tent_inverse(u[1])),
            _ => (self.invert(u[0]), self.invert(u[1])),
        };
        let weight = match self.kind {
            FilterKind::Box | FilterKind::Tent | FilterKind::Gaussian => 1.0,
            // Signs multiply; comparing them avoids underflow in the product of small values.
            _ if (self.profile(dx) < 0.0) != (self.profile(dy) < 0.0) => -1.0,
            _ => 1.0,
        };
        FilterSample { dx, dy, weight }
    }

    /// The offset at which the tabulated cumulative distribution reaches `u`: the segment by
    /// binary search, then linear within it.
    fn invert(&self, u: f64) -> f64 {
        let cdf = &self.cdf;
        // The last point at or below u; u < 1 = cdf[SEGMENTS], so the segment has mass.
        let i = cdf
            .partition_point(|&c| c <= u)
            .saturating_sub(1)
            .min(SEGMENTS - 1);
        let (low, high) = (cdf[i], cdf[i + 1]);
        let t = if high > low {
            ((u - low) / (high - low)).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let width = 2.0 * self.radius / SEGMENTS as f64;
        -self.radius + width * (i as f64 + t)
    }

    /// The normalised cumulative distribution of |f₁| over [−r, r], each segment's mass by
    /// Simpson's rule on four intervals.
    /// None if the profile's mass underflows.
    fn tabulate(&self) -> Option<Box<[f64]>> {
        let r = self.radius;
        let width = 2.0 * r / SEGMENTS as f64;
        let mut cdf = Vec::with_capacity(SEGMENTS + 1);
        let mut total = 0.0;
        cdf.push(0.0);
        for i in 0..SEGMENTS {
            let x0 = -r + width * i as f64;
            let h = width / 4.0;
            let f = |k: f64| self.profile(x0 + h * k).abs();
            total += h / 3.0 * (f(0.0) + 4.0 * f(1.0) + 2.0 * f(2.0) + 4.0 * f(3.0) + f(4.0));
            cdf.push(total);
        }
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        for c in &mut cdf {
            *c /= total;
        }
        // Exactly 1, so that every u < 1 lies inside a segment.
        cdf[SEGMENTS] = 1.0;
        Some(cdf.into_boxed_slice())
    }
}

/// Mitchell–Netravali's cubic at |t| ≤ 2.
fn mitchell(t: f64) -> f64 {
    let (b, c) = (MITCHELL_B, MITCHELL_C);
    let t2 = t * t;
    let t3 = t2 * t;
    if t < 1.0 {
        ((12.0 - 9.0 * b - 6.0 * c) * t3 + (-18.0 + 12.0 * b + 6.0 * c) * t2 + (6.0 - 2.0 * b))
            / 6.0
    } else if t < 2.0 {
        ((-b - 6.0 * c) * t3
            + (6.0 * b + 30.0 * c) * t2
            + (-12.0 * b - 48.0 * c) * t
            + (8.0 * b + 24.0 * c))
            / 6.0
    } else {
        0.0
    }
}

/// sin(πx)/(πx), with its Taylor series near 0 where the quotient loses precision.
fn sinc(x: f64) -> f64 {
    let px = PI * x;
    if px.abs() < 1e-4 {
        1.0 - px * px / 6.0
    } else {
        px.sin() / px
    }
}

/// The inverse cumulative distribution of the unit tent on [−1, 1]: its two halves are
/// (1 ± x)²/2, so x = √(2u) − 1 below the middle and 1 − √(2 − 2u) above.
fn tent_inverse(u: f64) -> f64 {
    if u < 0.5 {
        (2.0 * u).sqrt() - 1.0
    } else {
        1.0 - (2.0 - 2.0 * u).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::chi_square::PlanarBins;
    use crate::sampling::Rng;

    /// Seed for every random test in this module.
    const SEED: u64 = 0x5EED0005;

    fn filter(kind: FilterKind) -> Filter {
        Filter::new(kind, kind.default_radius()).unwrap()
    }

    /// ∫|f₁| over [−r, r] by Simpson's rule on 60 000 intervals (error far below 1e-9).
    fn profile_mass(f: &Filter) -> f64 {
        let n = 60_000;
        let r = f.radius();
        let h = 2.0 * r / n as f64;
        (0..=n)
            .map(|k| {
                let weight = match k {
                    0 => 1.0,
                    k if k == n => 1.0,
                    k if k % 2 == 1 => 4.0,
                    _ => 2.0,
                };
                weight * f.profile(-r + h * k as f64).abs()
            })
            .sum::<f64>()
            * h
            / 3.0
    }

    /// A jittered n × n pattern in [0, 1)², seeded.
    fn jittered(n: usize, seed: u64) -> Vec<[f64; 2]> {
        let mut rng = Rng::new(seed, 0);
        let mut points = Vec::with_capacity(n * n);
        for i in 0..n {
            for j in 0..n {
                points.push([
                    (i as f64 + rng.uniform()) / n as f64,
                    (j as f64 + rng.uniform()) / n as f64,
                ]);
            }
        }
        points
    }

    #[test]
    fn names_round_trip() {
        for kind in FilterKind::ALL {
            assert_eq!(kind.name().parse::<FilterKind>(), Ok(kind));
            assert_eq!(kind.to_string(), kind.name());
        }
        let radii: Vec<f64> = FilterKind::ALL.map(|k| k.default_radius()).to_vec();
        assert_eq!(radii, [0.5, 1.0, 1.5, 2.0, 3.0]);
    }

    #[test]
    fn unknown_name_lists_the_alternatives() {
        let error = "sinc".parse::<FilterKind>().unwrap_err();
        assert!(error.contains("sinc"), "{error}");
        for kind in FilterKind::ALL {
            assert!(error.contains(kind.name()), "{error}");
        }
    }

    #[test]
    fn new_rejects_bad_radii() {
        for radius in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let error = Filter::new(FilterKind::Tent, radius).unwrap_err();
            assert!(error.contains("radius"), "{error}");
        }
        // Tiny but usable radii still sample inside [−r, r].
        for kind in FilterKind::ALL {
            let f = Filter::new(kind, 1e-9).unwrap();
            let s = f.sample([0.1, 0.9]);
            assert!(
                s.dx < 0.0 && s.dx >= -1e-9 && s.dy > 0.0 && s.dy <= 1e-9,
                "{kind}: {s:?}"
            );
        }
    }

    #[test]
    fn profiles_at_known_points() {
        let [boxed, tent, gaussian, mitchell, lanczos] = FilterKind::ALL.map(filter);
        assert_eq!(boxed.evaluate(0.5, -0.5), 1.0);
        assert_eq!(tent.profile(0.25), 0.75);
        assert_eq!(tent.evaluate(0.5, -0.5), 0.25);
        assert!((gaussian.profile(0.0) - (1.0 - (-4.5f64).exp())).abs() < 1e-15);
        assert!((gaussian.profile(0.5) - ((-0.5f64).exp() - (-4.5f64).exp())).abs() < 1e-15);
        // Mitchell at 0 is (6 − 2B)/6 = 8/9; at |t| = 1 both cubics give 1/18; it dips
        // below zero between |t| = 1 and 2.
        assert!((mitchell.profile(0.0) - 8.0 / 9.0).abs() < 1e-15);
        assert!((mitchell.profile(1.0 - 1e-12) - 1.0 / 18.0).abs() < 1e-10);
        assert!((mitchell.profile(1.0 + 1e-12) - 1.0 / 18.0).abs() < 1e-10);
        assert!(mitchell.profile(1.5) < 0.0);
        assert!(lanczos.profile(0.0) == 1.0 && lanczos.profile(1.0).abs() < 1e-16);
        assert!(lanczos.profile(1.5) < 0.0 && lanczos.profile(2.5) > 0.0);
        for f in [boxed, tent, gaussian, mitchell, lanczos] {
            let r = f.radius();
            assert_eq!(f.evaluate(r * 1.001, 0.0), 0.0, "{:?}", f.kind());
            assert_eq!(f.evaluate(0.0, -r * 1.001), 0.0, "{:?}", f.kind());
            if f.kind() != FilterKind::Box {
                assert!(f.profile(r).abs() < 1e-12, "{:?} at r", f.kind());
            }
            assert_eq!(f.profile(0.3), f.profile(-0.3));
        }
    }

    #[test]
    fn box_and_tent_closed_forms() {
        for kind in FilterKind::ALL {
            let s = filter(kind).sample([0.5, 0.5]);
            assert!(s.dx.abs() < 1e-12 && s.dy.abs() < 1e-12, "{kind}: {s:?}");
            assert_eq!(s.weight, 1.0);
        }
        let boxed = Filter::new(FilterKind::Box, 0.5).unwrap();
        let s = boxed.sample([0.0, 0.75]);
        assert_eq!((s.dx, s.dy, s.weight), (-0.5, 0.25, 1.0));
        // The tent's quantiles: u = 1/8 → −r/2, 7/8 → r/2, 0 → −r.
        let tent = Filter::new(FilterKind::Tent, 2.0).unwrap();
        let s = tent.sample([0.125, 0.875]);
        assert!(
            (s.dx + 1.0).abs() < 1e-15 && (s.dy - 1.0).abs() < 1e-15,
            "{s:?}"
        );
        assert_eq!(tent.sample([0.0, 0.5]).dx, -2.0);
        assert_eq!(tent_inverse(0.5), 0.0);
    }

    #[test]
    fn tabulated_warps_are_monotone_and_continuous() {
        // Increasing u never moves the offset back, and at every segment boundary the two
        // neighbouring pieces meet, so strata map to strata without gaps or overlaps.
        for kind in [
            FilterKind::Gaussian,
            FilterKind::Mitchell,
            FilterKind::Lanczos,
        ] {
            let f = filter(kind);
            let r = f.radius();
            let mut previous = -r;
            for k in 0..=100_000 {
                let u = (k as f64 / 100_000.0).min(1.0 - f64::EPSILON / 2.0);
                let x = f.invert(u);
                assert!(
                    x >= previous && x <= r,
                    "{kind} at {u}: {x} after {previous}"
                );
                previous = x;
            }
            let width = 2.0 * r / SEGMENTS as f64;
            for i in 1..SEGMENTS {
                let (c, below) = (f.cdf[i], f.cdf[i - 1]);
                let boundary = -r + width * i as f64;
                assert!((f.invert(c) - boundary).abs() < 1e-12, "{kind} segment {i}");
                // Just below c the lower piece, of slope width / (c − below), ends there too.
                let step = 1e-6 * (c - below);
                let gap = boundary - f.invert(c - step);
                assert!(
                    gap >= 0.0 && gap < 2e-6 * width,
                    "{kind} segment {i}: {gap}"
                );
            }
        }
    }

    #[test]
    fn negative_weights_only_for_negative_lobes() {
        for kind in FilterKind::ALL {
            let f = filter(kind);
            let negative = jittered(100, SEED)
                .into_iter()
                .map(|u| f.sample(u))
                .inspect(|s| assert!(s.weight == 1.0 || s.weight == -1.0))
                .filter(|s| s.weight < 0.0)
                .count();
            let expects_negative = matches!(kind, FilterKind::Mitchell | FilterKind::Lanczos);
            assert_eq!(
                negative > 0,
                expects_negative,
                "{kind}: {negative} negative"
            );
        }
    }

    #[test]
    fn weights_match_the_sign_of_the_filter() {
        let f = filter(FilterKind::Lanczos);
        for u in jittered(50, SEED) {
            let s = f.sample(u);
            let value = f.evaluate(s.dx, s.dy);
            assert!(value == 0.0 || value.signum() == s.weight, "{s:?}: {value}");
        }
    }

    #[test]
    fn constant_image_is_reproduced_exactly() {
        // 0.75 and its multiples up to 2⁵⁰ are exact, so Σ w·L / Σ w is exactly 0.75.
        for kind in FilterKind::ALL {
            let f = filter(kind);
            let (mut sum, mut weights) = (0.0, 0.0);
            for u in jittered(64, SEED) {
                let s = f.sample(u);
                sum += s.weight * 0.75;
                weights += s.weight;
            }
            assert_eq!(sum / weights, 0.75, "{kind}");
        }
    }

    #[test]
    fn linear_ramp_gives_the_centre_value() {
        // L = 3 + dx − 2 dy: a symmetric filter averages it to L(centre) = 3. Seeded 256 × 256
        // jittered pattern; each tolerance is about five standard deviations of the error,
        // measured over 400 seeds. The sign changes of Mitchell and Lanczos cut across
        // strata, so their error falls only as 1/√N.
        for (kind, tolerance) in [
            (FilterKind::Box, 5e-5),
            (FilterKind::Tent, 1.5e-4),
            (FilterKind::Gaussian, 3e-4),
            (FilterKind::Mitchell, 5e-3),
            (FilterKind::Lanczos, 1e-2),
        ] {
            let f = filter(kind);
            let (mut sum, mut weights) = (0.0, 0.0);
            for u in jittered(256, SEED) {
                let s = f.sample(u);
                sum += s.weight * (3.0 + s.dx - 2.0 * s.dy);
                weights += s.weight;
            }
            let mean = sum / weights;
            assert!((mean - 3.0).abs() < tolerance, "{kind}: {mean}");
        }
        // On a symmetric grid of u (cell midpoints) the errors cancel exactly, up to rounding.
        let f = filter(FilterKind::Lanczos);
        let n = 512;
        let (mut sum, mut weights) = (0.0, 0.0);
        for i in 0..n {
            for j in 0..n {
                let s = f.sample([(i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64]);
                sum += s.weight * (3.0 + s.dx - 2.0 * s.dy);
                weights += s.weight;
            }
        }
        assert!((sum / weights - 3.0).abs() < 1e-10, "{}", sum / weights);
    }

    /// `f` sampled, tested against |g| / ∫∫|g| over [−r, r]² (r the larger radius):
    /// seed SEED, 1 000 000 samples, 24 × 24 cells.
    fn chi_square(f: &Filter, g: &Filter) -> crate::sampling::chi_square::Outcome {
        let mass = profile_mass(g).powi(2);
        let r = f.radius().max(g.radius());
        PlanarBins::square(-r, r, 24).test(
            1_000_000,
            SEED,
            |u| {
                let s = f.sample(u);
                (s.dx, s.dy)
            },
            |x, y| g.evaluate(x, y).abs() / mass,
        )
    }

    fn chi_square_test(kind: FilterKind) {
        let f = filter(kind);
        chi_square(&f, &f).assert_accepted(&format!("{kind} filter"));
    }

    #[test]
    fn chi_square_box() {
        chi_square_test(FilterKind::Box);
    }

    #[test]
    fn chi_square_tent() {
        chi_square_test(FilterKind::Tent);
    }

    #[test]
    fn chi_square_gaussian() {
        chi_square_test(FilterKind::Gaussian);
    }

    #[test]
    fn chi_square_mitchell() {
        chi_square_test(FilterKind::Mitchell);
    }

    #[test]
    fn chi_square_lanczos() {
        chi_square_test(FilterKind::Lanczos);
    }

    #[test]
    fn chi_square_rejects_the_wrong_filter() {
        // Tent samples against the Gaussian of the same radius must be rejected.
        let tent = Filter::new(FilterKind::Tent, 1.5).unwrap();
        let outcome = chi_square(&tent, &filter(FilterKind::Gaussian));
        assert!(!outcome.accepted(), "{outcome:?}");
    }
}
