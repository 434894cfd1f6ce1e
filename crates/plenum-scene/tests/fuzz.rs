//! Fuzz targets, one per reader: any bytes give a scene or an error, never a panic, an
//! abort, a hang or a huge allocation. Under `cargo test` bolero runs each on random inputs
//! for a short while; the same bodies run for longer under cargo-fuzz (`fuzz/`, see
//! docs/robustness.md).

use std::path::Path;

/// The reader for `extension` on arbitrary bytes. Relative paths inside resolve against a
/// folder that does not exist, so a mutated file name reads nothing.
fn read(extension: &str, bytes: &[u8]) {
    let path = Path::new("/nonexistent-plenum-fuzz").join(format!("input.{extension}"));
    if let Err(e) = plenum_scene::read_scene(&path, extension, bytes.to_vec()) {
        // Every error shows: its display must not panic either.
        let _ = e.to_string();
    }
}

#[test]
fn toml() {
    bolero::check!().for_each(|bytes: &[u8]| read("toml", bytes));
}

#[test]
fn nff() {
    bolero::check!().for_each(|bytes: &[u8]| read("nff", bytes));
}

#[test]
fn ray() {
    bolero::check!().for_each(|bytes: &[u8]| read("ray", bytes));
}

#[test]
fn obj() {
    bolero::check!().for_each(|bytes: &[u8]| read("obj", bytes));
}

#[test]
fn mtl() {
    bolero::check!().for_each(|bytes: &[u8]| {
        let path = Path::new("/nonexistent-plenum-fuzz/input.mtl");
        let _ = plenum_scene::read_material_library(path, bytes.to_vec());
    });
}

#[test]
fn ply() {
    bolero::check!().for_each(|bytes: &[u8]| read("ply", bytes));
}

/// Structured inputs reach deeper than random bytes: a valid header and records of random
/// numbers, counts and keywords.
#[test]
fn ply_records() {
    bolero::check!()
        .with_type::<(u8, Vec<(u8, i32)>)>()
        .for_each(|(format, values)| {
            let format = ["ascii", "binary_little_endian", "binary_big_endian"][*format as usize % 3];
            let mut bytes = format!("ply\nformat {format} 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n").into_bytes();
            for (kind, v) in values {
                match (format, kind % 2) {
                    ("ascii", _) => bytes.extend(format!("{v} ").bytes()),
                    (_, 0) => bytes.push(*v as u8),
                    _ => bytes.extend(v.to_le_bytes()),
                }
            }
            read("ply", &bytes);
        });
}
