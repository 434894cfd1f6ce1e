//! Lambertian reflection: radiance leaves equally in all directions, f = R/π (Lambert 1760;
//! pbrt-v4 §9.2), sampled by the cosine-weighted hemisphere.

use std::f64::consts::FRAC_1_PI;

use plenum_spectrum::SampledSpectrum;

use super::{same_hemisphere, BsdfSample, BxdfFlags, SampleFlags, TransportMode};
use crate::math::Vec3;
use crate::sampling::{cosine_hemisphere, cosine_hemisphere_pdf};

/// A Lambertian reflector of albedo `r` (each lane in [0, 1]); two-sided.
#[derive(Clone, Copy, Debug)]
pub struct DiffuseBxdf {
    pub r: SampledSpectrum,
}

impl DiffuseBxdf {
    pub fn new(r: SampledSpectrum) -> DiffuseBxdf {
        DiffuseBxdf { r }
    }

    pub fn flags(&self) -> BxdfFlags {
        if self.r.is_black() {
            BxdfFlags::UNSET
        } else {
            BxdfFlags::DIFFUSE_REFLECTION
        }
    }

    pub fn f(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> SampledSpectrum {
        if same_hemisphere(wo, wi) {
            self.r * FRAC_1_PI
        } else {
            SampledSpectrum::ZERO
        }
    }

    pub fn sample_f(
        &self,
        wo: Vec3,
        _uc: f64,
        u: [f64; 2],
        _mode: TransportMode,
        which: SampleFlags,
    ) -> Option<BsdfSample> {
        if !which.reflection() {
            return None;
        }
        let mut wi = cosine_hemisphere(u);
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        let pdf = cosine_hemisphere_pdf(wi.z.abs());
        Some(BsdfSample::new(
            self.r * FRAC_1_PI,
            wi,
            pdf,
            BxdfFlags::DIFFUSE_REFLECTION,
        ))
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3, _mode: TransportMode, which: SampleFlags) -> f64 {
        if !which.reflection() || !same_hemisphere(wo, wi) {
            return 0.0;
        }
        cosine_hemisphere_pdf(wi.z.abs())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bxdf::test_support::*;
    use crate::bxdf::Bxdf;

    fn white() -> Bxdf {
        Bxdf::Diffuse(DiffuseBxdf::new(SampledSpectrum::ONE))
    }

    #[test]
    fn pdf_is_cos_over_pi() {
        // cos θ/π to rounding (one ulp, 2.3e-16 relative), on both sides; 0 across.
        let b = white();
        for w in spread_directions(7) {
            for side in [1.0, -1.0] {
                let w = Vec3::new(w.x, w.y, w.z * side);
                let wo = Vec3::new(0.2, 0.1, side).normalized();
                let expected = w.z.abs() / std::f64::consts::PI;
                let pdf = b.pdf(wo, w, TransportMode::Radiance, SampleFlags::All);
                assert!(
                    (pdf - expected).abs() <= 2.3e-16 * expected,
                    "{pdf} vs {expected}"
                );
                assert_eq!(
                    b.pdf(-wo, w, TransportMode::Radiance, SampleFlags::All),
                    0.0
                );
            }
        }
    }

    #[test]
    fn chi_square_lambert() {
        chi_square_bxdf(
            "Lambert",
            &white(),
            Vec3::new(0.3, 0.2, 0.9).normalized(),
            1,
        );
    }

    #[test]
    fn white_furnace() {
        // ∫ f cos dω = 1 for a white Lambertian: the estimate is exact per sample here
        // (f cos/pdf = 1), and uniform sampling (seed SEED_FURNACE, 2·10⁵) agrees to 1 %.
        let b = white();
        for wo in spread_directions(5) {
            let by_sampling = albedo_by_sampling(&b, wo, TransportMode::Radiance, 100_000);
            let uniform = albedo_by_uniform(&b, wo, TransportMode::Radiance, 200_000);
            assert!(
                (by_sampling.average() - 1.0).abs() < 1e-12,
                "{by_sampling:?}"
            );
            let u = uniform.average();
            assert!((0.99..=1.01).contains(&u), "{wo:?}: {u}");
        }
    }

    #[test]
    fn reciprocal() {
        assert_reciprocal(&white(), 2);
    }
}
