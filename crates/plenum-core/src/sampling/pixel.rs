//! Where in a pixel each sample goes. Jittered, adaptive and low-discrepancy patterns are
//! further variants of this enum: the renderer asks only for the count and the positions.

use super::Rng;

/// The most samples per pixel a render may ask for (a 256 × 256 grid).
pub const MAX_SPP: u32 = 1 << 16;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PixelSampler {
    /// Regular supersampling on an n × n grid of sub-pixel centres, averaged (a box filter).
    Grid { n: u32 },
}

impl PixelSampler {
    /// The regular grid closest to `spp` samples: n = round(√spp), from 1 to 256.
    pub fn grid_for(spp: u32) -> PixelSampler {
        PixelSampler::Grid {
            n: ((spp as f64).sqrt().round() as u32).clamp(1, 256),
        }
    }

    pub fn samples_per_pixel(&self) -> u32 {
        match *self {
            PixelSampler::Grid { n } => n * n,
        }
    }

    /// Offset of sample `index` inside the pixel, in [0, 1)².
    pub fn offset(&self, index: u32, _rng: &mut Rng) -> (f64, f64) {
        match *self {
            PixelSampler::Grid { n } => {
                let (i, j) = (index % n, index / n);
                ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64)
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
}
