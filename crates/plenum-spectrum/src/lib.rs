//! Spectra and colour: a leaf crate with no dependencies, so the renderer's physics of light
//! can be built and tested on its own (Psychopath's layout).
//!
//! - [`sampled`]: [`SampledSpectrum`], values at [`N_SAMPLES`] wavelengths, and
//!   [`SampledWavelengths`], those wavelengths with their pdfs (hero wavelength sampling,
//!   Wilkie et al. 2014), or the three channels of RGB rendering.

pub mod sampled;

pub use sampled::{ColorMode, SampledSpectrum, SampledWavelengths, N_SAMPLES};
