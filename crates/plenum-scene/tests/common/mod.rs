//! What the integration tests share.

pub mod integrators;

use std::path::PathBuf;

/// Whether ../shared/data is beside the repository: its tests have nothing to read without
/// it, and say so.
#[allow(dead_code)]
pub fn shared_data_present() -> bool {
    let present = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data")
        .is_dir();
    if !present {
        eprintln!("../shared/data is not here: this test has no files to read");
    }
    present
}
