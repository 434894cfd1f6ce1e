//! A thin dielectric sheet (a window pane) of relative index η: light reflects off the
//! front, or crosses both interfaces, bouncing inside any number of times; since the two
//! interfaces are parallel, the transmitted light leaves along −wo undeviated. Summing the
//! geometric series of internal bounces (pbrt-v4 §9.5.3): with R the single-interface
//! reflectance and T = 1 − R, the sheet reflects R' = R + T²R/(1 − R²) and transmits
//! T' = 1 − R'. Absorption inside the sheet is ignored.

use plenum_spectrum::SampledSpectrum;

use super::fresnel::fr_dielectric;
use super::{BsdfSample, BxdfFlags, SampleFlags, TransportMode};
use crate::math::Vec3;

#[derive(Clone, Copy, Debug)]
pub struct ThinDielectricBxdf {
    pub eta: f64,
}

impl ThinDielectricBxdf {
    pub fn new(eta: f64) -> ThinDielectricBxdf {
        ThinDielectricBxdf { eta }
    }

    pub fn flags(&self) -> BxdfFlags {
        BxdfFlags::REFLECTION | BxdfFlags::TRANSMISSION | BxdfFlags::SPECULAR
    }

    /// The sheet's total reflectance and transmittance for light at cos θ = `cos`.
    pub fn reflectance_transmittance(&self, cos: f64) -> (f64, f64) {
        let mut r = fr_dielectric(cos.abs(), self.eta);
        let t = 1.0 - r;
        if r < 1.0 {
            r += t * t * r / (1.0 - r * r);
        }
        (r, 1.0 - r)
    }

    pub fn f(&self, _wo: Vec3, _wi: Vec3, _mode: TransportMode) -> SampledSpectrum {
        SampledSpectrum::ZERO
    }

    pub fn sample_f(
        &self,
        wo: Vec3,
        uc: f64,
        _u: [f64; 2],
        _mode: TransportMode,
        which: SampleFlags,
    ) -> Option<BsdfSample> {
        let (r, t) = self.reflectance_transmittance(wo.z);
        let pr = if which.reflection() { r } else { 0.0 };
        let pt = if which.transmission() { t } else { 0.0 };
        if pr == 0.0 && pt == 0.0 {
            return None;
        }
        let cos = wo.z.abs();
        if uc < pr / (pr + pt) {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            let f = SampledSpectrum::splat(r / cos);
            Some(BsdfSample::new(
                f,
                wi,
                pr / (pr + pt),
                BxdfFlags::SPECULAR_REFLECTION,
            ))
        } else {
            // Both interfaces are crossed, in and out: the radiance scalings cancel.
            let f = SampledSpectrum::splat(t / cos);
            Some(BsdfSample::new(
                f,
                -wo,
                pt / (pr + pt),
                BxdfFlags::SPECULAR_TRANSMISSION,
            ))
        }
    }

    pub fn pdf(&self, _wo: Vec3, _wi: Vec3, _mode: TransportMode, _which: SampleFlags) -> f64 {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bxdf::test_support::*;
    use crate::bxdf::Bxdf;

    #[test]
    fn reflection_plus_transmission_is_one() {
        // R' + T' = 1 to 1e-12 at every angle both sides; the sampled weights f·cos/pdf are
        // 1 (to 1e-12) and the albedo by sampling is 1.
        let b = Bxdf::ThinDielectric(ThinDielectricBxdf::new(1.5));
        for k in 0..90 {
            for side in [1.0, -1.0] {
                let mut wo = direction_at(k as f64, 0.2);
                wo.z *= side;
                let mode = TransportMode::Radiance;
                let r = b
                    .sample_f(wo, 0.0, [0.0; 2], mode, SampleFlags::Reflection)
                    .unwrap();
                let t = b
                    .sample_f(wo, 0.0, [0.0; 2], mode, SampleFlags::Transmission)
                    .unwrap();
                let sum = r.f[0] * r.wi.z.abs() + t.f[0] * t.wi.z.abs();
                assert!((sum - 1.0).abs() < 1e-12, "{k}° {side}: {sum}");
                assert!((t.wi + wo).length() < 1e-15 && t.eta == 1.0);
                let a = albedo_by_sampling(&b, wo, mode, 200).average();
                assert!((a - 1.0).abs() < 1e-12, "{a}");
            }
        }
    }

    #[test]
    fn sheet_reflects_more_than_one_interface() {
        // At normal incidence, η = 1.5: R = 0.04, R' = 2R/(1 + R) = 0.0769..., to 1e-14.
        let (r, _) = ThinDielectricBxdf::new(1.5).reflectance_transmittance(1.0);
        assert!((r - 0.08 / 1.04).abs() < 1e-14, "{r}");
    }
}
