//! Measured and tabulated data, transcribed by scripts (the crate's `tools/gen_data.py`, `tools/gen_glasses.py`) from the
//! sources each file names. Nothing here is computed at run time.

pub mod cie;
pub mod glasses;
pub mod illuminants;
pub mod metals;
