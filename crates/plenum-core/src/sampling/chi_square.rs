//! Pearson's chi-square goodness-of-fit test for sampling routines, as Mitsuba and pbrt run
//! them: draw many samples, count them in the cells of a 2-D parameterisation of the domain,
//! integrate the claimed pdf over each cell for the expected counts, pool cells expected to
//! hold fewer than five samples, and turn the statistic into a p-value.
//!
//! The p-value comes from the regularised upper incomplete gamma function, Q(k/2, χ²/2) for
//! k degrees of freedom, by its series or its continued fraction (Numerical Recipes §6.2),
//! with ln Γ from Lanczos's approximation (g = 7, nine terms, Godfrey's coefficients).
//!
//! Every test in the crate uses a fixed seed, so a result never changes from run to run; the
//! level each p-value is held to is [`SIGNIFICANCE`] corrected for [`TEST_COUNT`] tests
//! (Šidák), so that a correct sampler passes them all with probability 0.99.

use std::f64::consts::TAU;

use crate::math::Vec3;
use crate::sampling::{Frame, Rng};

/// The chance that a correct sampler fails at least one chi-square test of the crate.
pub(crate) const SIGNIFICANCE: f64 = 0.01;

/// The number of chi-square tests expected to pass in the crate (warp.rs: 12 + 2 equal-area,
/// filter.rs: 5, light.rs: 4, distribution.rs: 3, environment.rs: 2, bxdf/: 24 — diffuse 1,
/// conductor 6, dielectric 12, diffuse transmission 2, Phong 3); update it when adding one.
pub(crate) const TEST_COUNT: u32 = 52;

/// Cells expected to hold fewer samples than this are pooled into one, where Pearson's
/// statistic stops following the chi-square distribution.
const MIN_EXPECTED: f64 = 5.0;

/// Intervals of the composite Simpson rule along each axis of a cell (17 × 17 points).
const QUADRATURE_INTERVALS: usize = 16;

/// The level a single test's p-value is held to: 1 − (1 − α)^(1/m), about α/m.
pub(crate) fn rejection_level() -> f64 {
    1.0 - (1.0 - SIGNIFICANCE).powf(1.0 / TEST_COUNT as f64)
}

/// What one test found.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Outcome {
    pub statistic: f64,
    pub degrees_of_freedom: u32,
    pub p_value: f64,
    /// The integral of the pdf over the binned region, which should be at most 1.
    pub mass_in_bins: f64,
    /// How many cells went into the pooled cell.
    pub pooled_cells: usize,
}

impl Outcome {
    pub fn accepted(&self) -> bool {
        self.p_value >= rejection_level()
    }

    /// Panics unless accepted; prints the outcome either way (seen with --nocapture).
    pub fn assert_accepted(&self, what: &str) {
        let report = format!(
            "{what}: χ² = {:.1} with {} degrees of freedom, p = {:.3e} (level {:.2e}); \
             the pdf holds {:.7} of its mass in the bins; {} cells pooled",
            self.statistic,
            self.degrees_of_freedom,
            self.p_value,
            rejection_level(),
            self.mass_in_bins,
            self.pooled_cells
        );
        eprintln!("{report}");
        assert!(
            self.accepted(),
            "the samples do not follow the pdf: {report}"
        );
    }
}

/// A grid of `bins[0]` × `bins[1]` cells over the rectangle x × y, for samplers of planar
/// domains; samples outside it (or NaN) count in one more cell.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PlanarBins {
    pub x: [f64; 2],
    pub y: [f64; 2],
    pub bins: [usize; 2],
}

impl PlanarBins {
    /// n × n cells over the square [low, high]².
    pub fn square(low: f64, high: f64, n: usize) -> PlanarBins {
        PlanarBins {
            x: [low, high],
            y: [low, high],
            bins: [n, n],
        }
    }

    /// `samples` points from `sample` fed independent uniform pairs (seeded by `seed`),
    /// tested against `pdf`, a density per unit area.
    pub fn test(
        &self,
        samples: usize,
        seed: u64,
        mut sample: impl FnMut([f64; 2]) -> (f64, f64),
        pdf: impl Fn(f64, f64) -> f64,
    ) -> Outcome {
        let [nx, ny] = self.bins;
        let mut observed = vec![0u64; nx * ny + 1];
        let mut rng = Rng::new(seed, 0);
        for _ in 0..samples {
            let (x, y) = sample([rng.uniform(), rng.uniform()]);
            let cell = match (bin(x, self.x, nx), bin(y, self.y, ny)) {
                (Some(i), Some(j)) => j * nx + i,
                _ => nx * ny,
            };
            observed[cell] += 1;
        }
        let mut mass = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                mass.push(integrate(edges(self.x, nx, i), edges(self.y, ny, j), &pdf));
            }
        }
        compare(&observed, &mass, samples)
    }
}

/// Cells of equal solid angle over directions: `bins[0]` bands of cos θ over `cos_theta`
/// times `bins[1]` sectors of φ, both measured in `frame`. Directions outside the bands (or
/// not of unit length) count in one more cell.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SphericalBins {
    pub frame: Frame,
    pub cos_theta: [f64; 2],
    pub bins: [usize; 2],
}

impl SphericalBins {
    /// Bands of cos θ from `cos_low` to 1 about world +z.
    pub fn about_z(cos_low: f64, bins: [usize; 2]) -> SphericalBins {
        SphericalBins {
            frame: Frame::from_z(Vec3::Z),
            cos_theta: [cos_low, 1.0],
            bins,
        }
    }

    /// `samples` directions from `sample` fed independent uniform pairs (seeded by `seed`),
    /// tested against `pdf`, a density per steradian.
    pub fn test(
        &self,
        samples: usize,
        seed: u64,
        mut sample: impl FnMut([f64; 2]) -> Vec3,
        pdf: impl Fn(Vec3) -> f64,
    ) -> Outcome {
        let [nc, np] = self.bins;
        let mut observed = vec![0u64; nc * np + 1];
        let mut rng = Rng::new(seed, 0);
        for _ in 0..samples {
            let w = sample([rng.uniform(), rng.uniform()]);
            let local = self.frame.to_local(w);
            let phi = local.y.atan2(local.x).rem_euclid(TAU);
            let unit = (w.length() - 1.0).abs() < 1e-9;
            let cell = match (bin(local.z, self.cos_theta, nc), bin(phi, [0.0, TAU], np)) {
                (Some(i), Some(j)) if unit => i * np + j,
                _ => nc * np,
            };
            observed[cell] += 1;
        }
        // dω = d(cos θ) dφ, so the integral over a cell is a plain one over (cos θ, φ).
        let pdf_at = |cos: f64, phi: f64| {
            let sin = (1.0 - cos * cos).max(0.0).sqrt();
            let (sin_phi, cos_phi) = phi.sin_cos();
            let local = Vec3::new(sin * cos_phi, sin * sin_phi, cos);
            pdf(self.frame.to_world(local))
        };
        let mut mass = Vec::with_capacity(nc * np);
        for i in 0..nc {
            for j in 0..np {
                mass.push(integrate(
                    edges(self.cos_theta, nc, i),
                    edges([0.0, TAU], np, j),
                    &pdf_at,
                ));
            }
        }
        compare(&observed, &mass, samples)
    }
}

/// Cells over the whole sphere: `bins[0]` equal bands of θ ∈ [0, π] times `bins[1]` sectors
/// of φ, measured in `frame`, as pbrt-v4 bins its BSDF tests (80 × 160). Directions not of
/// unit length (a failed sample passes NaN) count in one more cell.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PolarBins {
    pub frame: Frame,
    pub bins: [usize; 2],
}

impl PolarBins {
    /// Bands of θ about world +z.
    pub fn about_z(bins: [usize; 2]) -> PolarBins {
        PolarBins {
            frame: Frame::from_z(Vec3::Z),
            bins,
        }
    }

    /// `samples` directions from `sample` fed independent uniform pairs (seeded by `seed`),
    /// tested against `pdf`, a density per steradian.
    pub fn test(
        &self,
        samples: usize,
        seed: u64,
        mut sample: impl FnMut([f64; 2]) -> Vec3,
        pdf: impl Fn(Vec3) -> f64,
    ) -> Outcome {
        let [nt, np] = self.bins;
        let theta_range = [0.0, std::f64::consts::PI];
        let mut observed = vec![0u64; nt * np + 1];
        let mut rng = Rng::new(seed, 0);
        for _ in 0..samples {
            let w = sample([rng.uniform(), rng.uniform()]);
            let local = self.frame.to_local(w);
            let theta = local.z.clamp(-1.0, 1.0).acos();
            let phi = local.y.atan2(local.x).rem_euclid(TAU);
            let unit = (w.length() - 1.0).abs() < 1e-9;
            let cell = match (bin(theta, theta_range, nt), bin(phi, [0.0, TAU], np)) {
                (Some(i), Some(j)) if unit => i * np + j,
                _ => nt * np,
            };
            observed[cell] += 1;
        }
        // dω = sin θ dθ dφ.
        let pdf_at = |theta: f64, phi: f64| {
            let (sin, cos) = theta.sin_cos();
            let (sin_phi, cos_phi) = phi.sin_cos();
            let local = Vec3::new(sin * cos_phi, sin * sin_phi, cos);
            pdf(self.frame.to_world(local)) * sin
        };
        let mut mass = Vec::with_capacity(nt * np);
        for i in 0..nt {
            for j in 0..np {
                mass.push(integrate(
                    edges(theta_range, nt, i),
                    edges([0.0, TAU], np, j),
                    &pdf_at,
                ));
            }
        }
        compare(&observed, &mass, samples)
    }
}

/// The bin of `value` among `n` equal bins over `range`, or None outside it (or for NaN).
fn bin(value: f64, range: [f64; 2], n: usize) -> Option<usize> {
    let t = (value - range[0]) / (range[1] - range[0]);
    // Written so that NaN fails the test.
    if (0.0..=1.0).contains(&t) {
        Some(((t * n as f64) as usize).min(n - 1))
    } else {
        None
    }
}

/// The edges of bin `i` of `n` over `range`.
fn edges(range: [f64; 2], n: usize, i: usize) -> [f64; 2] {
    let width = (range[1] - range[0]) / n as f64;
    [
        range[0] + width * i as f64,
        range[0] + width * (i + 1) as f64,
    ]
}

/// ∫∫ f over the rectangle x × y by the composite Simpson rule, refined adaptively.
///
/// Most pdfs tested here jump to zero at the domain's edge. Simpson's rule errs by up to
/// a node spacing times the jump along such an edge, and when the edge runs parallel to the
/// grid (a polygon's side) the errors add up instead of cancelling; so a cell whose
/// quadrants disagree with it is split, down to [`REFINEMENTS`] levels.
fn integrate(x: [f64; 2], y: [f64; 2], f: &impl Fn(f64, f64) -> f64) -> f64 {
    refine(x, y, simpson(x, y, f), REFINEMENTS, f)
}

/// Levels of quadrant splitting at most: each halves the error along an edge.
const REFINEMENTS: u32 = 6;

/// Absolute tolerance on a cell's probability: a tenth of a sample in a million.
const TOLERANCE: f64 = 1e-7;

fn refine(x: [f64; 2], y: [f64; 2], whole: f64, depth: u32, f: &impl Fn(f64, f64) -> f64) -> f64 {
    let xm = 0.5 * (x[0] + x[1]);
    let ym = 0.5 * (y[0] + y[1]);
    let quadrants = [
        ([x[0], xm], [y[0], ym]),
        ([xm, x[1]], [y[0], ym]),
        ([x[0], xm], [ym, y[1]]),
        ([xm, x[1]], [ym, y[1]]),
    ];
    let parts = quadrants.map(|(qx, qy)| simpson(qx, qy, f));
    let sum: f64 = parts.iter().sum();
    if depth == 0 || (sum - whole).abs() <= TOLERANCE {
        return sum;
    }
    quadrants
        .iter()
        .zip(parts)
        .map(|(&(qx, qy), part)| refine(qx, qy, part, depth - 1, f))
        .sum()
}

/// ∫∫ f over the rectangle x × y by the composite Simpson rule.
fn simpson(x: [f64; 2], y: [f64; 2], f: &impl Fn(f64, f64) -> f64) -> f64 {
    let n = QUADRATURE_INTERVALS;
    let weight = |k: usize| match k {
        0 => 1.0,
        k if k == n => 1.0,
        k if k % 2 == 1 => 4.0,
        _ => 2.0,
    };
    let hx = (x[1] - x[0]) / n as f64;
    let hy = (y[1] - y[0]) / n as f64;
    let mut sum = 0.0;
    for i in 0..=n {
        for j in 0..=n {
            sum += weight(i) * weight(j) * f(x[0] + hx * i as f64, y[0] + hy * j as f64);
        }
    }
    sum * hx * hy / 9.0
}

/// Pearson's test of the counts `observed` (the binned cells, then the cell outside them)
/// against `samples` times the probability `mass` of each binned cell.
fn compare(observed: &[u64], mass: &[f64], samples: usize) -> Outcome {
    let n = samples as f64;
    let mass_in_bins: f64 = mass.iter().sum();
    assert!(
        mass_in_bins <= 1.0 + 1e-3,
        "the pdf integrates to {mass_in_bins} over the bins: it is not normalised"
    );
    let mut expected: Vec<f64> = mass.iter().map(|m| m * n).collect();
    // The outside cell expects the rest; rounding in the quadrature can leave a sliver.
    let rest = (1.0 - mass_in_bins) * n;
    expected.push(if rest < 1e-3 * MIN_EXPECTED {
        0.0
    } else {
        rest
    });
    pearson(observed, &expected, mass_in_bins)
}

fn pearson(observed: &[u64], expected: &[f64], mass_in_bins: f64) -> Outcome {
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let mut statistic = 0.0;
    let mut cells = 0u32;
    let (mut pooled_observed, mut pooled_expected, mut pooled_cells) = (0.0, 0.0, 0);
    for k in order {
        let (o, e) = (observed[k] as f64, expected[k]);
        if e == 0.0 {
            if o > 0.0 {
                // A sample where the pdf says none can be: no statistic can excuse it.
                return Outcome {
                    statistic: f64::INFINITY,
                    degrees_of_freedom: cells,
                    p_value: 0.0,
                    mass_in_bins,
                    pooled_cells,
                };
            }
        } else if e < MIN_EXPECTED || (pooled_cells > 0 && pooled_expected < MIN_EXPECTED) {
            // Sorted ascending, so this gathers the small cells first and then only as many
            // larger ones as the pool needs to reach MIN_EXPECTED.
            pooled_observed += o;
            pooled_expected += e;
            pooled_cells += 1;
        } else {
            statistic += (o - e) * (o - e) / e;
            cells += 1;
        }
    }
    if pooled_cells > 0 {
        statistic += (pooled_observed - pooled_expected).powi(2) / pooled_expected;
        cells += 1;
    }
    // The counts add up to the sample count, which removes one degree of freedom.
    let degrees_of_freedom = cells.saturating_sub(1).max(1);
    Outcome {
        statistic,
        degrees_of_freedom,
        p_value: chi_square_p_value(statistic, degrees_of_freedom),
        mass_in_bins,
        pooled_cells,
    }
}

/// P(X ≥ `statistic`) for X chi-square distributed with `degrees_of_freedom`.
pub(crate) fn chi_square_p_value(statistic: f64, degrees_of_freedom: u32) -> f64 {
    gamma_q(0.5 * degrees_of_freedom as f64, 0.5 * statistic)
}

/// The regularised upper incomplete gamma function Q(a, x) = Γ(a, x)/Γ(a), a > 0.
pub(crate) fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        1.0
    } else if x.is_infinite() {
        0.0
    } else if x < a + 1.0 {
        // The series converges fast here; the fraction converges fast in the other region.
        1.0 - gamma_p_series(a, x)
    } else {
        gamma_q_fraction(a, x)
    }
}

/// The common factor xᵃ e⁻ˣ / Γ(a), formed in logarithms so that it neither over- nor
/// underflows for large a.
fn gamma_prefactor(a: f64, x: f64) -> f64 {
    (a * x.ln() - x - ln_gamma(a)).exp()
}

/// P(a, x) = γ(a, x)/Γ(a) = xᵃ e⁻ˣ/Γ(a) · Σₙ xⁿ / (a (a+1) ⋯ (a+n)).
fn gamma_p_series(a: f64, x: f64) -> f64 {
    let mut denominator = a;
    let mut term = 1.0 / a;
    let mut sum = term;
    for _ in 0..100_000 {
        denominator += 1.0;
        term *= x / denominator;
        sum += term;
        if term.abs() < sum.abs() * 1e-16 {
            break;
        }
    }
    sum * gamma_prefactor(a, x)
}

/// Q(a, x) from its continued fraction 1/(x + 1 − a − 1·(1 − a)/(x + 3 − a − 2·(2 − a)/…)),
/// evaluated by the modified Lentz method.
fn gamma_q_fraction(a: f64, x: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let mut b = x + 1.0 - a;
    let mut c = 1.0 / TINY;
    let mut d = 1.0 / b;
    let mut fraction = d;
    for i in 1..100_000 {
        let an = -(i as f64) * (i as f64 - a);
        b += 2.0;
        d = an * d + b;
        if d.abs() < TINY {
            d = TINY;
        }
        c = b + an / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        let step = d * c;
        fraction *= step;
        if (step - 1.0).abs() < 1e-16 {
            break;
        }
    }
    fraction * gamma_prefactor(a, x)
}

/// ln Γ(x) for x > 0, by Lanczos's approximation with g = 7 and nine coefficients (Godfrey),
/// good to about 1e-15 relative.
pub(crate) fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const COEFFICIENTS: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection, Γ(x) Γ(1 − x) = π / sin(πx): the series is accurate for x ≥ 1/2.
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let z = x - 1.0;
    let mut series = COEFFICIENTS[0];
    for (k, c) in COEFFICIENTS.iter().enumerate().skip(1) {
        series += c / (z + k as f64);
    }
    let t = z + G + 0.5;
    0.5 * TAU.ln() + (z + 0.5) * t.ln() - t + series.ln()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Q(n, x) for whole n in closed form: e⁻ˣ Σ_{k<n} xᵏ/k!, the Poisson tail.
    fn gamma_q_whole(n: u32, x: f64) -> f64 {
        let mut term = (-x).exp();
        let mut sum = 0.0;
        for k in 0..n {
            if k > 0 {
                term *= x / k as f64;
            }
            sum += term;
        }
        sum
    }

    #[test]
    fn ln_gamma_matches_factorials() {
        let mut factorial = 1.0f64;
        for n in 1..=100u32 {
            if n > 1 {
                factorial *= (n - 1) as f64;
            }
            let exact = factorial.ln();
            assert!(
                (ln_gamma(n as f64) - exact).abs() <= 1e-13 * exact.abs().max(1.0),
                "Γ({n})"
            );
        }
        let root_pi = std::f64::consts::PI.sqrt();
        assert!((ln_gamma(0.5) - root_pi.ln()).abs() < 1e-14);
        assert!((ln_gamma(1.5) - (0.5 * root_pi).ln()).abs() < 1e-14);
        assert!((ln_gamma(0.25) - 3.625_609_908_221_908_f64.ln()).abs() < 1e-13);
    }

    #[test]
    fn gamma_q_matches_the_poisson_tail() {
        // Both branches (series below a + 1, fraction above), small and large a, to 1e-12.
        for (n, x) in [
            (1, 0.3),
            (1, 7.0),
            (5, 2.0),
            (5, 9.0),
            (30, 20.0),
            (30, 45.0),
            (300, 280.0),
            (300, 320.0),
        ] {
            let exact = gamma_q_whole(n, x);
            let q = gamma_q(n as f64, x);
            assert!(
                (q - exact).abs() < 1e-12,
                "Q({n}, {x}) = {q}, expected {exact}"
            );
        }
    }

    #[test]
    fn p_values_at_known_quantiles() {
        // The 95 % point of one degree of freedom, 3.841458820694124, from erfc.
        let p = chi_square_p_value(3.841_458_820_694_124, 1);
        assert!((p - 0.05).abs() < 1e-12, "{p}");
        // Two degrees of freedom: P(X ≥ x) = e^(−x/2).
        for x in [0.1, 1.0, 10.0, 40.0] {
            let p = chi_square_p_value(x, 2);
            assert!((p / (-0.5 * x).exp() - 1.0).abs() < 1e-12, "{x}: {p}");
        }
        assert_eq!(chi_square_p_value(0.0, 7), 1.0);
        assert_eq!(chi_square_p_value(f64::INFINITY, 7), 0.0);
    }

    #[test]
    fn pooling_and_impossible_samples() {
        // Cells expected 0.5, 1, 2 and 3 pool into one of 6.5; with 1000 and 1000 left that
        // makes three cells, two degrees of freedom.
        let observed = [1, 1, 2, 3, 1000, 1000];
        let expected = [0.5, 1.0, 2.0, 3.0, 1000.0, 1000.0];
        let outcome = pearson(&observed, &expected, 1.0);
        assert_eq!(outcome.pooled_cells, 4);
        assert_eq!(outcome.degrees_of_freedom, 2);
        assert!((outcome.statistic - 0.25 / 6.5).abs() < 1e-12);
        // One sample where the pdf is zero rejects outright.
        let outcome = pearson(&[1, 500, 500], &[0.0, 500.0, 500.0], 1.0);
        assert!(!outcome.accepted() && outcome.p_value == 0.0);
    }

    #[test]
    fn simpson_integrates_cubics_exactly() {
        let f = |x: f64, y: f64| x * x * x - 2.0 * x * y * y + 1.0;
        // ∫₀¹∫₀² (x³ − 2xy² + 1) dy dx = ∫₀¹ (2x³ − 16x/3 + 2) dx.
        let exact = 0.5 - 8.0 / 3.0 + 2.0;
        assert!((simpson([0.0, 1.0], [0.0, 2.0], &f) - exact).abs() < 1e-13);
    }

    #[test]
    fn bins_reject_nan_and_outside() {
        assert_eq!(bin(f64::NAN, [0.0, 1.0], 4), None);
        assert_eq!(bin(-1e-9, [0.0, 1.0], 4), None);
        assert_eq!(bin(1.0, [0.0, 1.0], 4), Some(3));
        assert_eq!(bin(0.25, [0.0, 1.0], 4), Some(1));
    }
}
