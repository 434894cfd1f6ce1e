//! A diffuse reflector and transmitter (paper, leaves, thin cloth): f = R/π towards wo's
//! side and T/π through to the other (pbrt-v4's `DiffuseTransmissionBxDF`), each sampled by
//! a cosine-weighted hemisphere, the side chosen with probability proportional to the
//! lanes' average of R and of T.

use std::f64::consts::FRAC_1_PI;

use plenum_spectrum::SampledSpectrum;

use super::{same_hemisphere, BsdfSample, BxdfFlags, SampleFlags, TransportMode};
use crate::math::Vec3;
use crate::sampling::{cosine_hemisphere, cosine_hemisphere_pdf};

#[derive(Clone, Copy, Debug)]
pub struct DiffuseTransmissionBxdf {
    pub r: SampledSpectrum,
    pub t: SampledSpectrum,
}

impl DiffuseTransmissionBxdf {
    pub fn new(r: SampledSpectrum, t: SampledSpectrum) -> DiffuseTransmissionBxdf {
        DiffuseTransmissionBxdf { r, t }
    }

    pub fn flags(&self) -> BxdfFlags {
        let mut flags = BxdfFlags::UNSET;
        if !self.r.is_black() {
            flags = flags | BxdfFlags::DIFFUSE_REFLECTION;
        }
        if !self.t.is_black() {
            flags = flags | BxdfFlags::DIFFUSE_TRANSMISSION;
        }
        flags
    }

    fn weights(&self, which: SampleFlags) -> (f64, f64) {
        let pr = if which.reflection() {
            self.r.average()
        } else {
            0.0
        };
        let pt = if which.transmission() {
            self.t.average()
        } else {
            0.0
        };
        (pr, pt)
    }

    pub fn f(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> SampledSpectrum {
        if same_hemisphere(wo, wi) {
            self.r * FRAC_1_PI
        } else {
            self.t * FRAC_1_PI
        }
    }

    pub fn sample_f(
        &self,
        wo: Vec3,
        uc: f64,
        u: [f64; 2],
        _mode: TransportMode,
        which: SampleFlags,
    ) -> Option<BsdfSample> {
        let (pr, pt) = self.weights(which);
        if pr <= 0.0 && pt <= 0.0 {
            return None;
        }
        let mut wi = cosine_hemisphere(u);
        let reflect = uc < pr / (pr + pt);
        // Reflection keeps wi on wo's side, transmission puts it on the other.
        if (wo.z < 0.0) == reflect {
            wi.z = -wi.z;
        }
        let (f, p, flags) = if reflect {
            (self.r, pr, BxdfFlags::DIFFUSE_REFLECTION)
        } else {
            (self.t, pt, BxdfFlags::DIFFUSE_TRANSMISSION)
        };
        let pdf = cosine_hemisphere_pdf(wi.z.abs()) * p / (pr + pt);
        Some(BsdfSample::new(f * FRAC_1_PI, wi, pdf, flags))
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3, _mode: TransportMode, which: SampleFlags) -> f64 {
        let (pr, pt) = self.weights(which);
        if pr <= 0.0 && pt <= 0.0 {
            return 0.0;
        }
        let p = if same_hemisphere(wo, wi) { pr } else { pt };
        cosine_hemisphere_pdf(wi.z.abs()) * p / (pr + pt)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bxdf::test_support::*;
    use crate::bxdf::Bxdf;

    fn leaf() -> Bxdf {
        Bxdf::DiffuseTransmission(DiffuseTransmissionBxdf::new(
            SampledSpectrum([0.3, 0.5, 0.2, 0.4]),
            SampledSpectrum([0.6, 0.2, 0.5, 0.3]),
        ))
    }

    #[test]
    fn chi_square_both_sides() {
        chi_square_bxdf("diffuse transmission", &leaf(), direction_at(40.0, 0.5), 60);
        chi_square_bxdf(
            "diffuse transmission from below",
            &leaf(),
            -direction_at(70.0, 2.0),
            61,
        );
    }

    #[test]
    fn furnace_is_r_plus_t() {
        // The albedo per lane is R + T: by sampling (2·10⁵, seed SEED_FURNACE) to 1 %.
        let b = leaf();
        let expected = [0.9, 0.7, 0.7, 0.7];
        for wo in [direction_at(30.0, 0.0), -direction_at(75.0, 1.0)] {
            let a = albedo_by_sampling(&b, wo, TransportMode::Radiance, 200_000);
            for k in 0..4 {
                assert!((a[k] / expected[k] - 1.0).abs() < 0.01, "{wo:?}: {a:?}");
            }
        }
    }

    #[test]
    fn reciprocal() {
        assert_reciprocal(&leaf(), 5);
    }
}
