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

/// Writes `files` (name, bytes) into a fresh folder and loads the first as a scene.
#[allow(dead_code)]
pub fn load_files(
    files: &[(&str, &[u8])],
) -> Result<plenum_scene::LoadedScene, plenum_scene::SceneError> {
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in files {
        std::fs::write(dir.path().join(name), bytes).unwrap();
    }
    plenum_scene::load_scene(&dir.path().join(files[0].0))
}

/// The scene as `plenum convert` writes it, parsed back.
#[allow(dead_code)]
pub fn native(l: &plenum_scene::LoadedScene) -> toml::Table {
    plenum_scene::to_toml(&l.scene, &l.defaults)
        .parse()
        .unwrap()
}

/// A written number, integer or float.
#[allow(dead_code)]
pub fn number(v: &toml::Value) -> f64 {
    v.as_float()
        .or_else(|| v.as_integer().map(|i| i as f64))
        .unwrap()
}

/// Where a lamp lands: the mean position of the pixels of `image` (`width` wide) whose red
/// exceeds 0.5. Panics if there are none.
#[allow(dead_code)]
pub fn bright_centre(image: &[[f32; 3]], width: usize) -> (f64, f64) {
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
    for (i, p) in image.iter().enumerate() {
        if p[0] > 0.5 {
            sx += (i % width) as f64;
            sy += (i / width) as f64;
            n += 1.0;
        }
    }
    assert!(n > 0.0, "the lamp is seen");
    (sx / n, sy / n)
}

/// An 8-bit PNG of `samples` (rows from the top), RGB if `channels` is 3, RGBA if 4, stored
/// as PNG's format says: the signature, IHDR, one zlib IDAT of filter-0 rows, IEND, each
/// chunk with its CRC-32.
#[allow(dead_code)]
pub fn png(width: u32, height: u32, channels: u8, samples: &[u8]) -> Vec<u8> {
    use std::io::Write;
    fn crc32(bytes: &[u8]) -> u32 {
        let mut c = !0u32;
        for &b in bytes {
            c ^= b as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }
    let chunk = |out: &mut Vec<u8>, kind: &[u8], data: &[u8]| {
        out.extend((data.len() as u32).to_be_bytes());
        let body = [kind, data].concat();
        out.extend(&body);
        out.extend(crc32(&body).to_be_bytes());
    };
    let mut raw = Vec::new();
    for row in samples.chunks(width as usize * channels as usize) {
        raw.push(0);
        raw.extend(row);
    }
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    z.write_all(&raw).unwrap();
    let idat = z.finish().unwrap();
    let mut ihdr = Vec::new();
    ihdr.extend(width.to_be_bytes());
    ihdr.extend(height.to_be_bytes());
    let colour_type = if channels == 4 { 6 } else { 2 };
    ihdr.extend([8, colour_type, 0, 0, 0]);
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    chunk(&mut out, b"IHDR", &ihdr);
    chunk(&mut out, b"IDAT", &idat);
    chunk(&mut out, b"IEND", &[]);
    out
}
