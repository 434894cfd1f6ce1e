//! Placeholder, replaced below.
use plenum_spectrum::SampledSpectrum;

use super::{BsdfSample, BxdfFlags, SampleFlags, TransportMode};
use crate::math::Vec3;

#[derive(Clone, Copy, Debug)]
pub struct CoatedDiffuseBxdf {}

impl CoatedDiffuseBxdf {
    pub fn flags(&self) -> BxdfFlags { BxdfFlags::UNSET }
    pub fn f(&self, _wo: Vec3, _wi: Vec3, _mode: TransportMode) -> SampledSpectrum { SampledSpectrum::ZERO }
    pub fn sample_f(&self, _wo: Vec3, _uc: f64, _u: [f64; 2], _mode: TransportMode, _which: SampleFlags) -> Option<BsdfSample> { None }
    pub fn pdf(&self, _wo: Vec3, _wi: Vec3, _mode: TransportMode, _which: SampleFlags) -> f64 { 0.0 }
}
