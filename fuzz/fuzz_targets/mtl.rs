//! The MTL reader on any bytes: materials or an error, never a crash (docs/robustness.md).
#![no_main]

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    let path = std::path::Path::new("/nonexistent-plenum-fuzz/input.mtl");
    if let Err(e) = plenum_scene::read_material_library(path, bytes.to_vec()) {
        let _ = e.to_string();
    }
});
