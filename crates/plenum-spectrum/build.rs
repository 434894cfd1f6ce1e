//! Builds the sRGB-to-spectrum table (`RgbToSpectrumTable::srgb`) when the crate is built,
//! from the crate's own code and data, included here as they are, so that no render pays
//! for its 3·24³ solves at its start.

// The included modules hold more than the table needs.
#![allow(dead_code, unused_imports)]

#[path = "src/cie.rs"]
mod cie;
#[path = "src/color.rs"]
mod color;
#[path = "src/data/mod.rs"]
mod data;
#[path = "src/sampled.rs"]
mod sampled;
#[path = "src/uplift.rs"]
mod uplift;

/// What the crate's root holds in its place: the table itself, which this script makes.
static SRGB_TABLE: &[u8] = &[];

fn main() {
    for source in [
        "build.rs",
        "src/cie.rs",
        "src/color.rs",
        "src/data",
        "src/sampled.rs",
        "src/uplift.rs",
    ] {
        println!("cargo::rerun-if-changed={source}");
    }
    let table = uplift::RgbToSpectrumTable::build(uplift::SRGB_TABLE_RES);
    let out = std::path::PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    std::fs::write(out.join("srgb_table.bin"), table.to_bytes()).expect("OUT_DIR is writable");
}
