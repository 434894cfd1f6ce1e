//! Spectra and colour: a leaf crate with no dependencies, so the renderer's physics of light
//! can be built and tested on its own (Psychopath's layout).
//!
//! - [`sampled`]: [`SampledSpectrum`], values at [`N_SAMPLES`] wavelengths, and
//!   [`SampledWavelengths`], those wavelengths with their pdfs (hero wavelength sampling,
//!   Wilkie et al. 2014, over the visible-importance density), or the three channels of RGB
//!   rendering.
//! - [`cie`]: the CIE 1931 2° observer.
//! - [`color`]: XYZ, linear sRGB, CIELAB; sampled spectra to colour.
//! - [`blackbody`]: Planck's law.
//! - [`uplift`]: RGB to spectrum (Jakob and Hanika 2019).
//! - [`spectrum`]: [`Spectrum`], the spectra a scene gives.
//! - [`named`]: measured metals, glasses, media and CIE illuminants by name.

pub mod blackbody;
pub mod cie;
pub mod color;
mod data;
pub mod named;
pub mod sampled;
pub mod spectrum;
pub mod uplift;

pub use cie::{cie_xyz, CIE_Y_INTEGRAL};
pub use named::{named, names};
pub use sampled::{
    sample_visible_wavelength, visible_pdf, ColorMode, SampledSpectrum, SampledWavelengths,
    N_SAMPLES,
};
pub use spectrum::Spectrum;
pub use uplift::{RgbSigmoid, RgbToSpectrumTable};

/// [`RgbToSpectrumTable::srgb`]'s table, which build.rs builds.
static SRGB_TABLE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/srgb_table.bin"));
