//! The pbrt-v4 reader on any bytes: a scene or an error, never a crash (docs/robustness.md).
#![no_main]

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    // A folder that does not exist: a mutated file name inside reads nothing.
    let path = std::path::Path::new("/nonexistent-plenum-fuzz/input.pbrt");
    if let Err(e) = plenum_scene::read_scene(path, "pbrt", bytes.to_vec()) {
        let _ = e.to_string();
    }
});
