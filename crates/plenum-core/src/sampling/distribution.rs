//! Sampling tabulated functions: piecewise-constant densities in one and two dimensions by
//! inversion of their cumulative distribution, and discrete distributions by the alias method.
//!
//! The piecewise-constant distributions follow pbrt-v4, Appendix A (Pharr, Jakob & Humphreys
//! 2023): a 2-D density is a marginal over rows times a conditional within the chosen row,
//! each sampled by inverting its cumulative distribution. The alias table is Walker's method
//! (Walker 1977, "An efficient method for generating discrete random variables with general
//! distributions") built in O(n) by Vose's construction (Vose 1991, "A linear algorithm for
//! generating random numbers with a given distribution").
//!
//! Every table is built once; sampling and pdf queries only read it, so nothing allocates
//! per sample.

/// A piecewise-constant density over [min, max], proportional to n non-negative values, one
/// per equal-width cell.
///
/// A function that is zero everywhere (or has no values) is sampled uniformly instead, so that
/// sampling always succeeds; [`integral`](Self::integral) still reports 0 for it.
#[derive(Clone, Debug)]
pub struct PiecewiseConstant1D {
    /// The function's values, one per cell; negative and NaN inputs are stored as 0.
    function: Vec<f64>,
    /// n + 1 values from 0 to 1; cdf[i] is the probability of the cells before i.
    cdf: Vec<f64>,
    min: f64,
    max: f64,
    /// ∫ f over [min, max] as given.
    integral: f64,
    /// What the function is divided by for its density: the integral, or for a zero
    /// function (sampled uniformly) the domain's width, with every value taken as 1.
    normaliser: f64,
    uniform: bool,
}

impl PiecewiseConstant1D {
    /// The density over [`min`, `max`] (min < max) proportional to `values`. Negative or NaN
    /// values count as 0 (they are not densities); an empty slice is one zero cell.
    pub fn new(values: &[f64], min: f64, max: f64) -> PiecewiseConstant1D {
        debug_assert!(min < max, "empty domain [{min}, {max}]");
        let mut function: Vec<f64> = values
            .iter()
            .map(|&v| if v > 0.0 { v } else { 0.0 })
            .collect();
        if function.is_empty() {
            function.push(0.0);
        }
        let n = function.len();
        let width = (max - min) / n as f64;
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0);
        let mut sum = 0.0;
        for &f in &function {
            sum += f * width;
            cdf.push(sum);
        }
        let integral = sum;
        let uniform = !(integral > 0.0 && integral.is_finite());
        if uniform {
            for (i, c) in cdf.iter_mut().enumerate() {
                *c = i as f64 / n as f64;
            }
        } else {
            for c in &mut cdf {
                *c /= integral;
            }
        }
        // Exactly 1, so that no u < 1 lands past the last non-zero cell.
        cdf[n] = 1.0;
        PiecewiseConstant1D {
            function,
            cdf,
            min,
            max,
            integral: if uniform { 0.0 } else { integral },
            normaliser: if uniform { max - min } else { integral },
            uniform,
        }
    }

    /// The number of cells.
    pub fn len(&self) -> usize {
        self.function.len()
    }

    /// Always false: an empty input becomes one cell.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// ∫ f(x) dx over [min, max]; 0 for a function sampled uniformly because it is zero.
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// The domain [min, max].
    pub fn domain(&self) -> [f64; 2] {
        [self.min, self.max]
    }

    /// The value of the function in cell `i`.
    pub fn value(&self, i: usize) -> f64 {
        self.function[i]
    }

    /// The density of cell `i` with respect to x.
    fn cell_pdf(&self, i: usize) -> f64 {
        if self.uniform {
            1.0 / self.normaliser
        } else {
            self.function[i] / self.normaliser
        }
    }

    /// A point x in [min, max] for u in [0, 1), its density per unit x, and the index of its
    /// cell. Cells of value 0 are never returned.
    pub fn sample_continuous(&self, u: f64) -> (f64, f64, usize) {
        let n = self.len();
        // The last cell whose cdf starts at or below u; zero cells have cdf[i] = cdf[i + 1],
        // so the search passes over them.
        let offset = (self.cdf.partition_point(|&c| c <= u).max(1) - 1).min(n - 1);
        let start = self.cdf[offset];
        let step = self.cdf[offset + 1] - start;
        let within = if step > 0.0 {
            ((u - start) / step).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let t = (offset as f64 + within) / n as f64;
        let x = self.min + t * (self.max - self.min);
        (x, self.cell_pdf(offset), offset)
    }

    /// The cell holding x, or None outside [min, max].
    fn cell_of(&self, x: f64) -> Option<usize> {
        let t = (x - self.min) / (self.max - self.min);
        if (0.0..=1.0).contains(&t) {
            Some(((t * self.len() as f64) as usize).min(self.len() - 1))
        } else {
            None
        }
    }

    /// The density of [`sample_continuous`](Self::sample_continuous) at x per unit x; 0
    /// outside [min, max].
    pub fn pdf(&self, x: f64) -> f64 {
        self.cell_of(x).map_or(0.0, |i| self.cell_pdf(i))
    }

    /// The u that [`sample_continuous`](Self::sample_continuous) maps to x (the cumulative
    /// distribution at x), or None outside [min, max].
    pub fn invert(&self, x: f64) -> Option<f64> {
        let i = self.cell_of(x)?;
        let n = self.len() as f64;
        let within = ((x - self.min) / (self.max - self.min) * n - i as f64).clamp(0.0, 1.0);
        Some(self.cdf[i] + within * (self.cdf[i + 1] - self.cdf[i]))
    }
}

/// A piecewise-constant density over the unit square [0, 1]², proportional to a grid of
/// `nu` × `nv` non-negative values stored row by row (`values[v * nu + u]`): the first
/// coordinate runs along a row, the second across rows.
///
/// Sampling picks a row from the marginal density (the rows' integrals) with u[1], then a
/// point within the row from its conditional density with u[0]. A grid that is zero
/// everywhere is sampled uniformly.
#[derive(Clone, Debug)]
pub struct PiecewiseConstant2D {
    conditionals: Vec<PiecewiseConstant1D>,
    marginal: PiecewiseConstant1D,
}

impl PiecewiseConstant2D {
    /// The density proportional to `values` (length `nu * nv`, both at least 1; a shorter
    /// slice is padded with zeros, a longer one cut).
    pub fn new(values: &[f64], nu: usize, nv: usize) -> PiecewiseConstant2D {
        let (nu, nv) = (nu.max(1), nv.max(1));
        let conditionals: Vec<PiecewiseConstant1D> = (0..nv)
            .map(|v| {
                let row: Vec<f64> = (0..nu)
                    .map(|u| values.get(v * nu + u).copied().unwrap_or(0.0))
                    .collect();
                PiecewiseConstant1D::new(&row, 0.0, 1.0)
            })
            .collect();
        let row_integrals: Vec<f64> = conditionals.iter().map(|c| c.integral()).collect();
        let marginal = PiecewiseConstant1D::new(&row_integrals, 0.0, 1.0);
        PiecewiseConstant2D {
            conditionals,
            marginal,
        }
    }

    /// The grid size [nu, nv].
    pub fn resolution(&self) -> [usize; 2] {
        [self.conditionals[0].len(), self.marginal.len()]
    }

    /// ∫∫ f over the unit square; 0 for a zero grid.
    pub fn integral(&self) -> f64 {
        self.marginal.integral()
    }

    /// A point p in [0, 1]² for u in [0, 1)² and its density per unit area. Cells of value 0
    /// are never returned.
    pub fn sample(&self, u: [f64; 2]) -> ([f64; 2], f64) {
        let (y, pdf_row, row) = self.marginal.sample_continuous(u[1]);
        let (x, pdf_within, _) = self.conditionals[row].sample_continuous(u[0]);
        ([x, y], pdf_row * pdf_within)
    }

    /// The density of [`sample`](Self::sample) at p per unit area; 0 outside the square.
    pub fn pdf(&self, p: [f64; 2]) -> f64 {
        match self.marginal.cell_of(p[1]) {
            Some(row) => self.marginal.pdf(p[1]) * self.conditionals[row].pdf(p[0]),
            None => 0.0,
        }
    }

    /// The u that [`sample`](Self::sample) maps to p, or None outside the square.
    pub fn invert(&self, p: [f64; 2]) -> Option<[f64; 2]> {
        let row = self.marginal.cell_of(p[1])?;
        Some([
            self.conditionals[row].invert(p[0])?,
            self.marginal.invert(p[1])?,
        ])
    }
}

/// A discrete distribution over indices 0..n with probabilities proportional to non-negative
/// weights, sampled in constant time by Walker's alias method.
///
/// Each of n equal bins holds one index with probability `keep` and otherwise refers to its
/// alias; one uniform number picks the bin and decides between the two. Indices of weight 0
/// are never sampled. All-zero weights give the uniform distribution.
#[derive(Clone, Debug)]
pub struct AliasTable {
    bins: Vec<AliasBin>,
}

#[derive(Clone, Copy, Debug)]
struct AliasBin {
    /// The probability that the bin's own index is chosen once the bin is.
    keep: f64,
    /// The index chosen otherwise.
    alias: usize,
    /// The index's probability in the whole distribution.
    pmf: f64,
}

impl AliasTable {
    /// The table for `weights`; negative and NaN weights count as 0.
    ///
    /// Panics if `weights` is empty: there is nothing to sample.
    pub fn new(weights: &[f64]) -> AliasTable {
        assert!(
            !weights.is_empty(),
            "an alias table needs at least one weight"
        );
        let n = weights.len();
        let clean: Vec<f64> = weights
            .iter()
            .map(|&w| if w > 0.0 { w } else { 0.0 })
            .collect();
        let sum: f64 = clean.iter().sum();
        let pmf: Vec<f64> = if sum > 0.0 && sum.is_finite() {
            clean.iter().map(|w| w / sum).collect()
        } else {
            vec![1.0 / n as f64; n]
        };
        let mut bins: Vec<AliasBin> = pmf
            .iter()
            .enumerate()
            .map(|(i, &p)| AliasBin {
                keep: 1.0,
                alias: i,
                pmf: p,
            })
            .collect();
        // Vose: each bin's share of the mean, n·p; bins below 1 are topped up from one above.
        let mut share: Vec<f64> = pmf.iter().map(|p| p * n as f64).collect();
        let mut under: Vec<usize> = (0..n).filter(|&i| share[i] < 1.0).collect();
        let mut over: Vec<usize> = (0..n).filter(|&i| share[i] >= 1.0).collect();
        while let (Some(&small), Some(&large)) = (under.last(), over.last()) {
            under.pop();
            over.pop();
            bins[small].keep = share[small];
            bins[small].alias = large;
            share[large] -= 1.0 - share[small];
            if share[large] < 1.0 {
                under.push(large);
            } else {
                over.push(large);
            }
        }
        // What remains is off from a share of 1 by rounding alone: such bins keep themselves,
        // except that a weight of 0 must never be chosen, so it goes to the largest index.
        let largest = (0..n)
            .max_by(|&a, &b| pmf[a].total_cmp(&pmf[b]))
            .unwrap_or(0);
        for i in under.into_iter().chain(over) {
            if pmf[i] > 0.0 {
                bins[i].keep = 1.0;
                bins[i].alias = i;
            } else {
                bins[i].keep = 0.0;
                bins[i].alias = largest;
            }
        }
        AliasTable { bins }
    }

    /// The number of indices.
    pub fn len(&self) -> usize {
        self.bins.len()
    }

    /// Always false: a table has at least one index.
    pub fn is_empty(&self) -> bool {
        self.bins.is_empty()
    }

    /// The probability of index `i`.
    pub fn pmf(&self, i: usize) -> f64 {
        self.bins.get(i).map_or(0.0, |b| b.pmf)
    }

    /// An index for u in [0, 1), its probability, and u remapped to a fresh uniform number in
    /// [0, 1) (the part of u not spent on the choice), for reuse by the caller.
    pub fn sample(&self, u: f64) -> (usize, f64, f64) {
        let n = self.bins.len();
        let scaled = u * n as f64;
        let bin = (scaled as usize).min(n - 1);
        let within = (scaled - bin as f64).clamp(0.0, 1.0);
        let b = self.bins[bin];
        let below_one = 1.0 - f64::EPSILON / 2.0;
        if within < b.keep {
            (bin, b.pmf, (within / b.keep).min(below_one))
        } else {
            let rest = ((within - b.keep) / (1.0 - b.keep)).clamp(0.0, below_one);
            (b.alias, self.bins[b.alias].pmf, rest)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::chi_square::{chi_square_p_value, rejection_level, PlanarBins};
    use crate::sampling::Rng;

    const SEED: u64 = 0x5EED000D;
    const SAMPLES: usize = 1_000_000;

    /// Pearson's test of `observed` counts against `expected` probabilities over discrete
    /// cells (pooling cells expected below five samples); returns the p-value, or 0 when a
    /// cell of probability 0 was hit.
    fn discrete_p_value(observed: &[u64], expected: &[f64]) -> f64 {
        let n: u64 = observed.iter().sum();
        let (mut statistic, mut cells) = (0.0, 0u32);
        let (mut pooled_o, mut pooled_e) = (0.0, 0.0);
        for (&o, &p) in observed.iter().zip(expected) {
            let e = p * n as f64;
            if e == 0.0 {
                if o > 0 {
                    return 0.0;
                }
            } else if e < 5.0 {
                pooled_o += o as f64;
                pooled_e += e;
            } else {
                statistic += (o as f64 - e).powi(2) / e;
                cells += 1;
            }
        }
        if pooled_e > 0.0 {
            statistic += (pooled_o - pooled_e).powi(2) / pooled_e;
            cells += 1;
        }
        let p = chi_square_p_value(statistic, cells.saturating_sub(1).max(1));
        eprintln!("χ² = {statistic:.1}, {cells} cells, p = {p:.3e}");
        p
    }

    /// Values with zeros inside and at both ends, and a wide range of magnitudes.
    fn values() -> Vec<f64> {
        vec![0.0, 1.0, 3.0, 0.0, 0.0, 0.5, 8.0, 2.0, 0.0, 0.01, 4.0, 0.0]
    }

    #[test]
    fn one_dimensional_integral_pdf_and_zeros() {
        let f = PiecewiseConstant1D::new(&values(), -1.0, 2.0);
        let total: f64 = values().iter().sum();
        assert!((f.integral() - total * 3.0 / 12.0).abs() < 1e-12);
        // ∫ pdf = 1, by the midpoint rule on a fine grid (exact for a step function whose
        // steps lie on the grid).
        let steps = 12_000;
        let h = 3.0 / steps as f64;
        let mass: f64 = (0..steps)
            .map(|k| f.pdf(-1.0 + (k as f64 + 0.5) * h) * h)
            .sum();
        assert!((mass - 1.0).abs() < 1e-12, "{mass}");
        assert_eq!(f.pdf(-1.5), 0.0);
        assert_eq!(f.pdf(2.5), 0.0);
        let mut rng = Rng::new(SEED, 1);
        for _ in 0..100_000 {
            let u = rng.uniform();
            let (x, pdf, offset) = f.sample_continuous(u);
            assert!(
                values()[offset] > 0.0,
                "zero cell {offset} sampled at u = {u}"
            );
            assert!((-1.0..=2.0).contains(&x));
            assert_eq!(pdf, f.pdf(x), "at {x}");
            let back = f.invert(x).unwrap();
            assert!((back - u).abs() < 1e-12, "{u} → {x} → {back}");
        }
        // The ends of [0, 1) stay in non-zero cells.
        for u in [0.0, 1.0 - f64::EPSILON / 2.0] {
            let (_, _, offset) = f.sample_continuous(u);
            assert!(values()[offset] > 0.0, "u = {u}: cell {offset}");
        }
        assert_eq!(f.invert(3.0), None);
    }

    #[test]
    fn zero_functions_become_uniform() {
        for f in [
            PiecewiseConstant1D::new(&[0.0; 4], 0.0, 2.0),
            PiecewiseConstant1D::new(&[], 0.0, 2.0),
            PiecewiseConstant1D::new(&[-1.0, f64::NAN], 0.0, 2.0),
        ] {
            assert_eq!(f.integral(), 0.0);
            let (x, pdf, _) = f.sample_continuous(0.3);
            assert!((x - 0.6).abs() < 1e-12 && (pdf - 0.5).abs() < 1e-12);
            assert!((f.pdf(1.9) - 0.5).abs() < 1e-12);
        }
        let grid = PiecewiseConstant2D::new(&[0.0; 6], 3, 2);
        let (p, pdf) = grid.sample([0.25, 0.75]);
        assert!((p[0] - 0.25).abs() < 1e-12 && (p[1] - 0.75).abs() < 1e-12);
        assert!((pdf - 1.0).abs() < 1e-12 && (grid.pdf([0.9, 0.1]) - 1.0).abs() < 1e-12);
        let table = AliasTable::new(&[0.0, 0.0]);
        assert_eq!(table.pmf(0), 0.5);
        assert_eq!(table.sample(0.75).0, 1);
    }

    #[test]
    fn chi_square_piecewise_constant_1d() {
        // 60 bins over the domain, five per cell, so bin edges fall on cell edges and within.
        let f = PiecewiseConstant1D::new(&values(), -1.0, 2.0);
        let bins = 60;
        let mut observed = vec![0u64; bins];
        let mut rng = Rng::new(SEED, 2);
        for _ in 0..SAMPLES {
            let (x, _, _) = f.sample_continuous(rng.uniform());
            let t = (x + 1.0) / 3.0;
            observed[((t * bins as f64) as usize).min(bins - 1)] += 1;
        }
        let expected: Vec<f64> = (0..bins)
            .map(|b| f.pdf(-1.0 + 3.0 * (b as f64 + 0.5) / bins as f64) * 3.0 / bins as f64)
            .collect();
        assert!((expected.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let p = discrete_p_value(&observed, &expected);
        assert!(
            p >= rejection_level(),
            "1-D piecewise constant: p = {p:.3e}"
        );
    }

    /// A 7 × 5 grid with zero cells, zero rows and one bright cell.
    fn grid_values() -> Vec<f64> {
        let mut v = Vec::new();
        for row in 0..5 {
            for col in 0..7 {
                let value = match (row, col) {
                    (1, _) => 0.0,
                    (_, 2) => 0.0,
                    (3, 5) => 40.0,
                    _ => 1.0 + (row * 7 + col) as f64 % 3.0,
                };
                v.push(value);
            }
        }
        v
    }

    #[test]
    fn two_dimensional_integral_pdf_and_zeros() {
        let values = grid_values();
        let grid = PiecewiseConstant2D::new(&values, 7, 5);
        assert_eq!(grid.resolution(), [7, 5]);
        let total: f64 = values.iter().sum();
        assert!((grid.integral() - total / 35.0).abs() < 1e-12);
        let steps = 700;
        let h = 1.0 / steps as f64;
        let mut mass = 0.0;
        for i in 0..steps {
            for j in 0..steps {
                mass += grid.pdf([(i as f64 + 0.5) * h, (j as f64 + 0.5) * h]) * h * h;
            }
        }
        assert!((mass - 1.0).abs() < 1e-9, "{mass}");
        let mut rng = Rng::new(SEED, 3);
        for _ in 0..100_000 {
            let u = [rng.uniform(), rng.uniform()];
            let (p, pdf) = grid.sample(u);
            let cell = ((p[1] * 5.0) as usize).min(4) * 7 + ((p[0] * 7.0) as usize).min(6);
            assert!(values[cell] > 0.0, "zero cell {cell} sampled at {u:?}");
            assert!(
                (pdf - grid.pdf(p)).abs() <= 1e-12 * pdf,
                "{pdf} vs {}",
                grid.pdf(p)
            );
            assert!((pdf - values[cell] / grid.integral()).abs() <= 1e-12 * pdf);
            let back = grid.invert(p).unwrap();
            assert!((back[0] - u[0]).abs() < 1e-9 && (back[1] - u[1]).abs() < 1e-9);
        }
    }

    #[test]
    fn chi_square_piecewise_constant_2d() {
        let grid = PiecewiseConstant2D::new(&grid_values(), 7, 5);
        // 40 × 30 bins, whose edges miss the cells' edges: a bin edge on a jump of the pdf
        // puts Simpson's end nodes on the jump, which biases the expected counts.
        let bins = PlanarBins {
            x: [0.0, 1.0],
            y: [0.0, 1.0],
            bins: [40, 30],
        };
        bins.test(
            SAMPLES,
            SEED,
            |u| {
                let (p, _) = grid.sample(u);
                (p[0], p[1])
            },
            |x, y| grid.pdf([x, y]),
        )
        .assert_accepted("piecewise constant 2-D");
    }

    #[test]
    fn chi_square_rejects_a_wrong_2d_pdf() {
        // The same grid sampled, tested against a grid with the bright cell halved.
        let grid = PiecewiseConstant2D::new(&grid_values(), 7, 5);
        let mut wrong = grid_values();
        wrong[3 * 7 + 5] = 20.0;
        let wrong = PiecewiseConstant2D::new(&wrong, 7, 5);
        let outcome = PlanarBins::square(0.0, 1.0, 35).test(
            SAMPLES,
            SEED,
            |u| {
                let (p, _) = grid.sample(u);
                (p[0], p[1])
            },
            |x, y| wrong.pdf([x, y]),
        );
        assert!(!outcome.accepted(), "{outcome:?}");
    }

    fn weights() -> Vec<f64> {
        vec![
            0.0, 5.0, 1.0, 0.0, 0.25, 10.0, 3.0, 0.0, 1e-3, 7.0, 2.0, 0.0,
        ]
    }

    #[test]
    fn alias_table_pmf_and_zeros() {
        let table = AliasTable::new(&weights());
        let total: f64 = weights().iter().sum();
        let mass: f64 = (0..table.len()).map(|i| table.pmf(i)).sum();
        assert!((mass - 1.0).abs() < 1e-12);
        for (i, w) in weights().iter().enumerate() {
            assert!((table.pmf(i) - w / total).abs() < 1e-15);
        }
        // The probability each index gets from the bins equals its pmf exactly.
        let n = table.len() as f64;
        let mut from_bins = vec![0.0; table.len()];
        for (i, b) in table.bins.iter().enumerate() {
            from_bins[i] += b.keep / n;
            from_bins[b.alias] += (1.0 - b.keep) / n;
        }
        for (i, p) in from_bins.iter().enumerate() {
            assert!((p - table.pmf(i)).abs() < 1e-12, "index {i}");
        }
        let mut rng = Rng::new(SEED, 4);
        for _ in 0..100_000 {
            let (i, pmf, rest) = table.sample(rng.uniform());
            assert!(weights()[i] > 0.0, "zero weight {i} sampled");
            assert_eq!(pmf, table.pmf(i));
            assert!((0.0..1.0).contains(&rest));
        }
        for u in [0.0, 1.0 - f64::EPSILON / 2.0] {
            let (i, _, rest) = table.sample(u);
            assert!(weights()[i] > 0.0 && (0.0..1.0).contains(&rest), "u = {u}");
        }
        assert_eq!(AliasTable::new(&[3.0]).sample(0.7), (0, 1.0, 0.7));
    }

    #[test]
    fn chi_square_alias_table() {
        let table = AliasTable::new(&weights());
        let mut observed = vec![0u64; table.len()];
        let mut remapped = [0u64; 10];
        let mut rng = Rng::new(SEED, 5);
        for _ in 0..SAMPLES {
            let (i, _, rest) = table.sample(rng.uniform());
            observed[i] += 1;
            remapped[(rest * 10.0) as usize] += 1;
        }
        let expected: Vec<f64> = (0..table.len()).map(|i| table.pmf(i)).collect();
        let p = discrete_p_value(&observed, &expected);
        assert!(p >= rejection_level(), "alias table: p = {p:.3e}");
        // The remapped number is uniform: a loose check (not counted as a chi-square test),
        // each decile within 1.5e-3 of a tenth, five standard deviations.
        for count in remapped {
            assert!(
                (count as f64 / SAMPLES as f64 - 0.1).abs() < 1.5e-3,
                "{remapped:?}"
            );
        }
    }

    #[test]
    fn chi_square_rejects_a_wrong_pmf() {
        let table = AliasTable::new(&weights());
        let mut wrong_weights = weights();
        wrong_weights[5] = 9.5;
        let wrong = AliasTable::new(&wrong_weights);
        let mut observed = vec![0u64; table.len()];
        let mut rng = Rng::new(SEED, 6);
        for _ in 0..SAMPLES {
            observed[table.sample(rng.uniform()).0] += 1;
        }
        let expected: Vec<f64> = (0..wrong.len()).map(|i| wrong.pmf(i)).collect();
        assert!(discrete_p_value(&observed, &expected) < rejection_level());
    }
}
