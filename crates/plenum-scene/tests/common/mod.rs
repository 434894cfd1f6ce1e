//! What the integration tests share.

pub mod integrators;

use std::path::PathBuf;

/// Whether ../shared/data is beside the repository: its tests have nothing to read without
/// it, and say so. With `PLENUM_REQUIRE_SHARED_DATA` set (as `.ci/run` sets it) its absence
/// fails the test instead.
#[allow(dead_code)]
pub fn shared_data_present() -> bool {
    let present = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data")
        .is_dir();
    if !present {
        missing("../shared/data");
    }
    present
}

/// Says that `what` is not here, or fails where it is required.
pub fn missing(what: &str) {
    if std::env::var_os("PLENUM_REQUIRE_SHARED_DATA").is_some() {
        panic!("{what} is not here, and PLENUM_REQUIRE_SHARED_DATA asks for it");
    }
    eprintln!("{what} is not here: this test has nothing to compare with");
}
