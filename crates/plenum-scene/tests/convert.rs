//! `to_toml` writes a scene that renders exactly as the one it came from, whatever format
//! that was: the native format itself, NFF and `.ray` (with nested transforms and meshes).

mod common;
use common::shared_data_present;
use plenum_core::integrator::IntegratorKind;
use plenum_core::render::{render, RenderSettings};
use plenum_scene::{builtin_scene, load_scene, parse_scene, to_toml, LoadedScene};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

fn shared(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data")
        .join(rel)
}

fn pixels(l: &LoadedScene) -> Vec<[f32; 3]> {
    let settings = RenderSettings {
        width: 40,
        height: 30,
        integrator: plenum_core::integrator::IntegratorConfig {
            kind: l
                .defaults
                .integrator
                .unwrap_or_else(|| IntegratorKind::default_for(&l.scene)),
            max_depth: l.defaults.max_depth,
            min_weight: l.defaults.min_weight,
            rr_depth: l.defaults.rr_depth,
            color: l.defaults.color.unwrap_or_default(),
            strategies: false,
            photon: l.defaults.photon,
        },
        ..Default::default()
    };
    render(&l.scene, &settings, &AtomicBool::new(false), &|_, _| {})
        .film
        .pixels()
        .to_vec()
}

fn round_trip(original: LoadedScene, what: &str) {
    let text = to_toml(&original.scene, &original.defaults);
    let back = parse_scene(Path::new("converted.toml"), &text, Path::new("."))
        .unwrap_or_else(|e| panic!("{what}: the written scene does not parse: {e}"));
    // The NFF view angle serves only the corner-ray procedure; the camera itself is written.
    let expected = plenum_scene::RenderDefaults {
        nff_angle: None,
        ..original.defaults
    };
    assert_eq!(back.defaults, expected, "{what}");
    assert_eq!(
        back.scene.geometry.primitives.len(),
        original.scene.geometry.primitives.len(),
        "{what}"
    );
    let (a, b) = (pixels(&original), pixels(&back));
    let differences: Vec<f32> = a
        .iter()
        .zip(&b)
        .flat_map(|(p, q)| (0..3).map(move |i| (p[i] - q[i]).abs()))
        .collect();
    let worst = differences.iter().copied().fold(0.0f32, f32::max);
    if IntegratorKind::default_for(&original.scene) == IntegratorKind::Whitted {
        assert!(worst < 1e-4, "{what}: largest pixel difference {worst}");
    } else {
        // A placement written as a matrix has its inverse computed anew, a last-bit
        // difference that a path through glass can turn into another path altogether: a
        // few pixels of a path-traced image may differ, the rest must not.
        let off = differences.iter().filter(|&&d| d >= 1e-4).count();
        assert!(
            off * 100 <= differences.len(),
            "{what}: {off} of {} pixel channels differ (largest {worst})",
            differences.len()
        );
    }
    assert!(
        a.iter().flatten().any(|&v| v > 0.01),
        "{what}: the test image is black"
    );
}

#[test]
fn converted_scenes_render_the_same() {
    round_trip(builtin_scene(), "built-in");
    for rel in [
        "nff/jacks.nff",
        "nff/teapot.nff",
        "ray/uw-ut/simple/sphere_refract.ray",
        "ray/hkust/moreSamples/tentacles.ray",
        "ray/uw-ut/polymesh/sier.ray",
        "meshes/stanford-bunny.obj",
    ]
    .into_iter()
    .filter(|_| shared_data_present())
    {
        let loaded = load_scene(&shared(rel)).unwrap_or_else(|e| panic!("{e}"));
        round_trip(loaded, rel);
    }
    let examples = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    for name in [
        "polyhedra.toml",
        "instances.toml",
        "textures.toml",
        "shadows.toml",
        "soft-shadows.toml",
        "depth-of-field.toml",
        "motion-blur.toml",
        "glossy.toml",
        "cornell-box.toml",
        "metals.toml",
        "prism.toml",
        "glass.toml",
        "rough-metals.toml",
        "cut-outs.toml",
    ] {
        round_trip(load_scene(&examples.join(name)).unwrap(), name);
    }
}
