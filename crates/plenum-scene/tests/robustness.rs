//! Readers on hostile input: text that is not UTF-8, and nesting deeper than any scene needs.

use plenum_scene::load_scene;
use std::path::Path;

fn write(dir: &Path, name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn a_latin1_comment_is_read_with_a_located_warning_in_every_text_format() {
    // A Latin-1 `é` rejected the whole file, with no location.
    let dir = tempfile::tempdir().unwrap();
    let nff = b"# caf\xe9\nv\nfrom 0 0 -5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 1\nresolution 4 4\nf 1 1 1 1 0 0 0 1\ns 0 0 0 1\n".to_vec();
    let ray = b"SBT-raytracer 1.0\n// caf\xe9\nsphere { }\n".to_vec();
    let obj = b"# caf\xe9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_vec();
    let toml = b"# caf\xe9\n[[objects]]\ntype = \"sphere\"\nradius = 1\n".to_vec();
    for (name, bytes, at) in [
        ("a.nff", nff, "1:6"),
        ("a.ray", ray, "2:7"),
        ("a.obj", obj, "1:6"),
        ("a.toml", toml, "1:6"),
    ] {
        let path = write(dir.path(), name, &bytes);
        let loaded = load_scene(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        let place = format!("{name}:{at}");
        assert!(
            loaded.warnings.iter().any(|w| w.contains(&place)),
            "{name}: {:?}",
            loaded.warnings
        );
    }
    // Where the byte matters, the error is located.
    let path = write(dir.path(), "b.nff", b"v\nfrom 0 0 -5\xe9\n");
    let e = load_scene(&path).err().unwrap();
    assert_eq!((e.line, e.column), (2, 10), "{e}");
}

#[test]
fn toml_nesting_beyond_the_parser_s_bound_is_a_located_error() {
    let dir = tempfile::tempdir().unwrap();
    let deep = format!("a = {}{}\n", "[".repeat(100_000), "]".repeat(100_000));
    let path = write(dir.path(), "deep.toml", deep.as_bytes());
    let e = load_scene(&path).err().unwrap();
    assert_eq!(e.line, 1, "{e}");
    assert!(e.column > 1 && e.column < 1000, "{e}");
}
