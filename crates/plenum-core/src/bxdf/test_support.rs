//! Shared helpers for the BSDF tests: directions, the chi-square test of `sample_f`
//! against `pdf` in pbrt-v4's layout, Monte Carlo albedo estimates, reciprocity.

use std::f64::consts::PI;

use plenum_spectrum::SampledSpectrum;

use super::{Bxdf, SampleFlags, TransportMode};
use crate::math::Vec3;
use crate::sampling::chi_square::{Outcome, PolarBins};
use crate::sampling::{uniform_sphere, Rng};

/// Seed of every albedo estimate.
pub const SEED_FURNACE: u64 = 0x0F04_1ACE;

/// Samples per chi-square test (pbrt-v4's count).
pub const CHI_SQUARE_SAMPLES: usize = 1_000_000;

/// pbrt-v4's cells: 80 bands of θ over [0, π] times 160 sectors of φ.
pub const CHI_SQUARE_BINS: [usize; 2] = [80, 160];

/// The unit direction at polar angle `theta_deg` degrees and azimuth `phi` radians.
pub fn direction_at(theta_deg: f64, phi: f64) -> Vec3 {
    let (sin, cos) = theta_deg.to_radians().sin_cos();
    Vec3::new(sin * phi.cos(), sin * phi.sin(), cos)
}

/// Outgoing directions the tests run at: near normal, oblique, and grazing (86°).
pub fn incidences() -> [Vec3; 3] {
    [
        direction_at(10.0, 0.3),
        direction_at(55.0, 1.9),
        direction_at(86.0, 4.0),
    ]
}

/// About n² directions spread over the upper hemisphere, off the pole and the horizon.
pub fn spread_directions(n: usize) -> Vec<Vec3> {
    let mut out = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let theta = 88.0 * (i as f64 + 0.5) / n as f64;
            let phi = 2.0 * PI * (j as f64 + 0.3) / n as f64;
            out.push(direction_at(theta, phi));
        }
    }
    out
}

/// Samples `bxdf.sample_f` at `wo` 10⁶ times (uniform pairs from `seed`, the lobe choice
/// from a second stream) and tests the directions against `bxdf.pdf` over 80 × 160 cells,
/// at the crate's Šidák-corrected 1 % level. Failed samples count in the cell outside the
/// sphere, which expects 1 − ∫ pdf.
pub fn chi_square_bxdf(what: &str, bxdf: &Bxdf, wo: Vec3, seed: u64) {
    chi_square_outcome(bxdf, bxdf, wo, seed).assert_accepted(&format!(
        "{what}, θo = {:.1}°",
        wo.z.clamp(-1.0, 1.0).acos().to_degrees()
    ));
}

/// The chi-square test of `sampled`'s samples against `tested`'s pdf.
pub fn chi_square_outcome(sampled: &Bxdf, tested: &Bxdf, wo: Vec3, seed: u64) -> Outcome {
    let mode = TransportMode::Radiance;
    let mut choice = Rng::new(seed, 7);
    let nan = Vec3::splat(f64::NAN);
    PolarBins::about_z(CHI_SQUARE_BINS).test(
        CHI_SQUARE_SAMPLES,
        seed,
        |u| match sampled.sample_f(wo, choice.uniform(), u, mode, SampleFlags::All) {
            Some(s) if !s.is_specular() && s.pdf > 0.0 => s.wi,
            _ => nan,
        },
        |wi| tested.pdf(wo, wi, mode, SampleFlags::All),
    )
}

/// ∫ f(wo, wi) |cos θi| dωi over the sphere by importance sampling: the mean of
/// f·|cos θi|/pdf over `n` samples from `sample_f` (seed SEED_FURNACE), delta lobes included.
pub fn albedo_by_sampling(bxdf: &Bxdf, wo: Vec3, mode: TransportMode, n: usize) -> SampledSpectrum {
    let mut rng = Rng::new(SEED_FURNACE, 1);
    let mut sum = SampledSpectrum::ZERO;
    for _ in 0..n {
        let (uc, u) = (rng.uniform(), [rng.uniform(), rng.uniform()]);
        if let Some(s) = bxdf.sample_f(wo, uc, u, mode, SampleFlags::All) {
            if s.pdf > 0.0 {
                sum += s.f * (s.wi.z.abs() / s.pdf);
            }
        }
    }
    sum / n as f64
}

/// The same integral over uniform directions on the sphere (continuous lobes only).
pub fn albedo_by_uniform(bxdf: &Bxdf, wo: Vec3, mode: TransportMode, n: usize) -> SampledSpectrum {
    let mut rng = Rng::new(SEED_FURNACE, 2);
    let mut sum = SampledSpectrum::ZERO;
    for _ in 0..n {
        let wi = uniform_sphere([rng.uniform(), rng.uniform()]);
        sum += bxdf.f(wo, wi, mode) * (wi.z.abs() * 4.0 * PI);
    }
    sum / n as f64
}

/// f(wo, wi) = f(wi, wo) to 1e-12 relative over 2000 random pairs in one hemisphere (and
/// its mirror), seed `seed`.
pub fn assert_reciprocal(bxdf: &Bxdf, seed: u64) {
    let mut rng = Rng::new(seed, 3);
    let mode = TransportMode::Radiance;
    for _ in 0..2000 {
        let mut wo = uniform_sphere([rng.uniform(), rng.uniform()]);
        let mut wi = uniform_sphere([rng.uniform(), rng.uniform()]);
        wi.z = wi.z.abs().copysign(wo.z);
        if wo.z == 0.0 {
            wo.z = 1e-3;
        }
        let a = bxdf.f(wo, wi, mode);
        let b = bxdf.f(wi, wo, mode);
        for k in 0..plenum_spectrum::N_SAMPLES {
            let scale = a[k].abs().max(b[k].abs());
            assert!(
                (a[k] - b[k]).abs() <= 1e-12 * scale,
                "{wo:?} {wi:?}: {a:?} vs {b:?}"
            );
        }
    }
}
