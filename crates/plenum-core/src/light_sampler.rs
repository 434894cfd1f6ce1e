//! Choosing a light for next-event estimation: in proportion to the lights' power (pbrt-v4's
//! `PowerLightSampler`), or uniformly. The choice's probability is part of the light
//! sample's pdf, so MIS weighs a light found by a BSDF ray by it too.

/// How lights are chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightSamplerKind {
    /// In proportion to each light's power (its RGB luminance times its extent).
    #[default]
    Power,
    Uniform,
}

/// A discrete distribution over the scene's lights.
#[derive(Clone, Debug, Default)]
pub struct LightSampler {
    pmf: Vec<f64>,
    /// Running sums of `pmf`, the last one 1.
    cdf: Vec<f64>,
}

impl LightSampler {
    /// From the lights' weights (powers; non-negative, non-finite counted as 0). Lights of
    /// weight 0 are never chosen; when all are 0 the choice is uniform.
    pub fn new(weights: &[f64]) -> LightSampler {
        let clean: Vec<f64> = weights
            .iter()
            .map(|&w| if w.is_finite() && w > 0.0 { w } else { 0.0 })
            .collect();
        let total: f64 = clean.iter().sum();
        let pmf: Vec<f64> = if total > 0.0 {
            clean.iter().map(|w| w / total).collect()
        } else {
            vec![1.0 / weights.len().max(1) as f64; weights.len()]
        };
        let mut sum = 0.0;
        let mut cdf: Vec<f64> = pmf
            .iter()
            .map(|p| {
                sum += p;
                sum
            })
            .collect();
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        LightSampler { pmf, cdf }
    }

    pub fn uniform(count: usize) -> LightSampler {
        LightSampler::new(&vec![1.0; count])
    }

    /// A light index and its probability, for u ∈ [0, 1); `None` without lights.
    #[inline]
    pub fn sample(&self, u: f64) -> Option<(u32, f64)> {
        if self.cdf.is_empty() {
            return None;
        }
        let i = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.cdf.len() - 1);
        // Skip lights of probability 0 that the search can land on at a boundary.
        let i = (i..self.pmf.len())
            .find(|&j| self.pmf[j] > 0.0)
            .unwrap_or(i);
        Some((i as u32, self.pmf[i]))
    }

    /// The probability of choosing light `i`.
    #[inline]
    pub fn pmf(&self, i: u32) -> f64 {
        self.pmf.get(i as usize).copied().unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    #[test]
    fn lights_are_chosen_in_proportion_to_power() {
        let s = LightSampler::new(&[1.0, 0.0, 3.0, f64::NAN]);
        assert_eq!(s.pmf(0), 0.25);
        assert_eq!(s.pmf(1), 0.0);
        assert_eq!(s.pmf(2), 0.75);
        assert_eq!(s.pmf(3), 0.0);
        let mut rng = Rng::new(7, 0);
        let mut counts = [0u32; 4];
        let n = 100_000;
        for _ in 0..n {
            let (i, p) = s.sample(rng.uniform()).unwrap();
            assert_eq!(p, s.pmf(i));
            counts[i as usize] += 1;
        }
        // Binomial standard deviation at p = 0.25 is 137 of 100 000; allow 5σ.
        assert!(
            (counts[0] as f64 - 0.25 * n as f64).abs() < 700.0,
            "{counts:?}"
        );
        assert_eq!(counts[1] + counts[3], 0);
    }

    #[test]
    fn no_power_means_uniform_and_no_lights_none() {
        let s = LightSampler::new(&[0.0, 0.0]);
        assert_eq!(s.pmf(1), 0.5);
        assert!(LightSampler::new(&[]).sample(0.5).is_none());
    }
}
