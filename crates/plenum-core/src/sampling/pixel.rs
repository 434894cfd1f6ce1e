//! Where in a pixel each sample goes: a regular grid, independent uniform points, or one
//! uniform point in each cell of a grid (jittered, or stratified, sampling). The renderer
//! asks only for the count and the positions; every random number comes from the sample's
//! own generator (seed, pixel, sample index).

use super::Rng;

/// The most samples per pixel a render may ask for (a 256 × 256 grid).
pub const MAX_SPP: u32 = 1 << 16;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PixelSampler {
    /// Regular supersampling on an n × n grid of sub-pixel centres, averaged (a box filter).
    Grid { n: u32 },
    /// `spp` independent uniform points.
    Random { spp: u32 },
    /// One uniform point in each cell of an n × n grid.
    Jittered { n: u32 },
}

/// The sampler kinds `--sampler` names.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SamplerKind {
    #[default]
    Grid,
    Random,
    Jittered,
}

impl std::str::FromStr for SamplerKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "grid" => Ok(SamplerKind::Grid),
            "random" => Ok(SamplerKind::Random),
            "jittered" => Ok(SamplerKind::Jittered),
            _ => Err(format!(
                "unknown sampler `{s}`: expected grid, random or jittered"
            )),
        }
    }
}

impl PixelSampler {
    /// The regular grid closest to `spp` samples: n = round(√spp), from 1 to 256.
    pub fn grid_for(spp: u32) -> PixelSampler {
        PixelSampler::Grid {
            n: ((spp as f64).sqrt().round() as u32).clamp(1, 256),
        }
    }

    /// A `kind` sampler of about `spp` samples: exactly `spp` for random, the nearest
    /// square for the grid patterns.
    pub fn new(kind: SamplerKind, spp: u32) -> PixelSampler {
        let n = match PixelSampler::grid_for(spp) {
            PixelSampler::Grid { n } => n,
            _ => unreachable!("grid_for makes a grid"),
        };
        match kind {
            SamplerKind::Grid => PixelSampler::Grid { n },
            SamplerKind::Random => PixelSampler::Random {
                spp: spp.clamp(1, MAX_SPP),
            },
            SamplerKind::Jittered => PixelSampler::Jittered { n },
        }
    }

    pub fn samples_per_pixel(&self) -> u32 {
        match *self {
            PixelSampler::Grid { n } | PixelSampler::Jittered { n } => n * n,
            PixelSampler::Random { spp } => spp,
        }
    }

    /// Offset of sample `index` inside the pixel, in [0, 1)²; `rng` is the sample's own.
    pub fn offset(&self, index: u32, rng: &mut Rng) -> (f64, f64) {
        match *self {
            PixelSampler::Grid { n } => {
                let (i, j) = (index % n, index / n);
                ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64)
            }
            PixelSampler::Random { .. } => (rng.uniform(), rng.uniform()),
            PixelSampler::Jittered { n } => {
                let (i, j) = (index % n, index / n);
                let (u, v) = (rng.uniform(), rng.uniform());
                ((i as f64 + u) / n as f64, (j as f64 + v) / n as f64)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_covers_the_pixel_evenly() {
        let s = PixelSampler::grid_for(16);
        assert_eq!(s.samples_per_pixel(), 16);
        let mut rng = Rng::new(0, 0);
        let offsets: Vec<_> = (0..16).map(|i| s.offset(i, &mut rng)).collect();
        assert_eq!(offsets[0], (0.125, 0.125));
        assert_eq!(offsets[15], (0.875, 0.875));
        let mean_x = offsets.iter().map(|o| o.0).sum::<f64>() / 16.0;
        assert!((mean_x - 0.5).abs() < 1e-15);
        assert_eq!(PixelSampler::grid_for(1).offset(0, &mut rng), (0.5, 0.5));
    }

    #[test]
    fn jittered_puts_one_sample_in_each_cell() {
        let s = PixelSampler::new(SamplerKind::Jittered, 16);
        assert_eq!(s, PixelSampler::Jittered { n: 4 });
        for index in 0..16 {
            let mut rng = Rng::for_sample(7, 3, 5, index);
            let (x, y) = s.offset(index, &mut rng);
            assert_eq!(((x * 4.0) as u32, (y * 4.0) as u32), (index % 4, index / 4));
        }
        assert_eq!(
            PixelSampler::new(SamplerKind::Random, 10).samples_per_pixel(),
            10
        );
        assert!("sobol"
            .parse::<SamplerKind>()
            .unwrap_err()
            .contains("jittered"));
    }

    /// Estimating the area of a pixel below a random edge: random sampling's RMS error
    /// falls as 1/√N; jittered sampling's faster (as N^-3/4 for edges), so it is smaller at
    /// equal N. 4000 random edges, seeds fixed; tolerances are factors of two around the
    /// expected ratios, many standard errors wide.
    #[test]
    fn jittered_beats_random_on_edges() {
        let rmse = |kind: SamplerKind, spp: u32| {
            let sampler = PixelSampler::new(kind, spp);
            let mut edges = Rng::new(99, 1);
            let mut sum = 0.0;
            let trials = 4000;
            for t in 0..trials {
                // The edge y = a + b·(x − ½) through the pixel; exact area below it (clamped
                // by integrating over 1000 columns, which is exact enough here).
                let a = edges.uniform();
                let b = (edges.uniform() - 0.5) * 4.0;
                let inside = |x: f64, y: f64| y < a + b * (x - 0.5);
                let exact = (0..1000)
                    .map(|k| {
                        let x = (k as f64 + 0.5) / 1000.0;
                        (a + b * (x - 0.5)).clamp(0.0, 1.0)
                    })
                    .sum::<f64>()
                    / 1000.0;
                let n = sampler.samples_per_pixel();
                let hits = (0..n)
                    .filter(|&i| {
                        let mut rng = Rng::for_sample(5, t, 0, i);
                        let (x, y) = sampler.offset(i, &mut rng);
                        inside(x, y)
                    })
                    .count();
                let err = hits as f64 / n as f64 - exact;
                sum += err * err;
            }
            (sum / trials as f64).sqrt()
        };
        let (r16, r64) = (rmse(SamplerKind::Random, 16), rmse(SamplerKind::Random, 64));
        let (j16, j64) = (
            rmse(SamplerKind::Jittered, 16),
            rmse(SamplerKind::Jittered, 64),
        );
        // Random: 4× the samples, half the error.
        assert!((r16 / r64 - 2.0).abs() < 0.4, "random {r16} -> {r64}");
        // Jittered: smaller than random at equal N, and falling faster.
        assert!(j16 < 0.7 * r16 && j64 < 0.6 * r64, "jittered {j16}, {j64}");
        assert!(j16 / j64 > 2.2, "jittered {j16} -> {j64}");
    }
}
