//! Measured and tabulated data, transcribed by scripts (the crate's `tools/gen_data.py` and
//! `tools/gen_glasses.py`) from the sources each file names. Nothing here is computed at run time.

// Measured numbers such as 3.14 are data, not approximations of π.
#![allow(clippy::approx_constant)]

pub mod cie;
pub mod glasses;
pub mod illuminants;
pub mod metals;
