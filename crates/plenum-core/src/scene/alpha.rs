//! Cut-outs: a surface that is there only where an alpha texture says so (leaves cut from a
//! quad, a fence from a plane). Rays pass a cut-away part as if nothing were there: camera
//! rays, shadow rays, photons, every method alike.

use crate::material::FloatTexture;
use crate::texture::TextureCoords;

/// Where a surface is present, by a value a in [0, 1] looked up like any texture.
#[derive(Clone, Debug)]
pub struct Alpha {
    pub texture: FloatTexture,
    /// `Some(c)`: present exactly where a ≥ c (glTF's `MASK` mode). `None`: present with
    /// probability a (pbrt-v4's stochastic test, glTF's `BLEND`), which averages over the
    /// pixel's samples to a surface of coverage a.
    pub cutoff: Option<f64>,
}

impl Alpha {
    /// A stochastic cut-out of coverage `texture`.
    pub fn stochastic(texture: FloatTexture) -> Alpha {
        Alpha {
            texture,
            cutoff: None,
        }
    }

    /// Whether the surface is present at `at`. `seed` (a hash of the ray and hit, so the
    /// choice is the same for any thread) is asked for only where a lies strictly between
    /// 0 and 1 and no cutoff decides.
    #[inline]
    pub fn keeps(&self, at: &TextureCoords, seed: impl FnOnce() -> u64) -> bool {
        let a = self.texture.evaluate(at);
        match self.cutoff {
            Some(c) => a >= c,
            None if a >= 1.0 => true,
            None if a <= 0.0 => false,
            // The top 53 bits as a number in [0, 1).
            None => ((seed() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)) < a,
        }
    }

    /// Whether the test looks anything up by texture coordinates.
    pub fn needs_uv(&self) -> bool {
        self.texture.needs_uv()
    }

    /// Whether the surface is present nowhere (a constant a of 0, or below the cutoff).
    pub fn is_absent(&self) -> bool {
        match (&self.texture, self.cutoff) {
            (FloatTexture::Constant(a), None) => *a <= 0.0,
            (FloatTexture::Constant(a), Some(c)) => *a < c,
            _ => false,
        }
    }

    /// Whether the surface is present everywhere (a constant a of 1 without a higher cutoff):
    /// then no test is needed.
    pub fn is_opaque(&self) -> bool {
        match (&self.texture, self.cutoff) {
            (FloatTexture::Constant(a), None) => *a >= 1.0,
            (FloatTexture::Constant(a), Some(c)) => *a >= c,
            _ => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;
    use crate::texture::Texture;

    fn at(u: f64) -> TextureCoords {
        TextureCoords::new([u, 0.25], Vec3::ZERO)
    }

    #[test]
    fn a_cutoff_decides_by_threshold_and_never_asks_for_a_seed() {
        let checker = Texture::Checker2d {
            even: crate::color::Color::gray(0.2),
            odd: crate::color::Color::gray(0.7),
            scale: 2.0,
        };
        let alpha = Alpha {
            texture: FloatTexture::Texture(checker),
            cutoff: Some(0.5),
        };
        // u in [0, 0.5): even squares (0.2), cut; [0.5, 1): odd (0.7), kept.
        assert!(!alpha.keeps(&at(0.25), || panic!("no seed needed")));
        assert!(alpha.keeps(&at(0.75), || panic!("no seed needed")));
        assert!(!alpha.is_opaque());
    }

    #[test]
    fn stochastic_coverage_matches_alpha() {
        // Seed 1234567 for a SplitMix64 stream; 100,000 trials: the kept fraction's standard
        // deviation is √(0.3·0.7/1e5) = 0.00145; tolerance 5σ.
        let alpha = Alpha::stochastic(FloatTexture::Constant(0.3));
        let mut state: u64 = 1234567;
        let mut next = || {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        };
        let n = 100_000;
        let kept = (0..n).filter(|_| alpha.keeps(&at(0.0), &mut next)).count();
        let fraction = kept as f64 / n as f64;
        assert!((fraction - 0.3).abs() < 5.0 * 0.00145, "kept {fraction}");
        // The ends never ask.
        let none = Alpha::stochastic(FloatTexture::Constant(0.0));
        assert!(!none.keeps(&at(0.0), || panic!("no seed needed")));
        let all = Alpha::stochastic(FloatTexture::Constant(1.0));
        assert!(all.keeps(&at(0.0), || panic!("no seed needed")));
        assert!(all.is_opaque());
    }
}
