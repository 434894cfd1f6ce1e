//! Photon mapping and stochastic progressive photon mapping against closed forms and an
//! independent renderer: pbrt-v4's analytic furnace scenes (every pixel's radiance is 1),
//! Mitsuba 3's converged Cornell box, the same image for any thread count, and clear errors
//! for bad settings.

mod common;
use common::integrators::{
    assert_mean_within, cbox_z_test_with, furnace, furnace_cases, load_cornell_box, mean,
    render_checked, scene, settings_for,
};

use plenum_core::integrator::{ColorMode, IntegratorKind, PhotonConfig};
use plenum_core::render::{trace_pixel, RenderSettings};
use plenum_scene::{parse_scene, LoadedScene};
use std::path::Path;

/// pbrt-v4's furnace (see common::integrators) on 16×16 pixels.
fn furnace16(light: &str, sphere_emission: &str) -> String {
    furnace(light, sphere_emission).replace("resolution = [12, 12]", "resolution = [16, 16]")
}

fn settings(
    l: &LoadedScene,
    kind: IntegratorKind,
    spp: u32,
    color: ColorMode,
    photon: PhotonConfig,
    seed: u64,
) -> RenderSettings {
    let mut s = settings_for(l, kind, spp, color, seed);
    s.integrator.photon = photon;
    s
}

fn draw(l: &LoadedScene, settings: &RenderSettings) -> Vec<[f32; 3]> {
    let out = render_checked(l, settings);
    assert!(out.counts.photon > 0, "photons were traced");
    out.film.pixels().to_vec()
}

/// The three furnaces on 16×16 pixels.
fn furnaces() -> Vec<(&'static str, String)> {
    furnace_cases()
        .into_iter()
        .map(|(what, light, emission)| (what, furnace16(&light, &emission)))
        .collect()
}

/// Photon mapping in the furnaces: L = 1 everywhere. With 50,000 global photon paths, k = 64
/// and 16 spp (seed 3) the image means came out within 0.009 of 1 (the density estimate is
/// unbiased for light spread evenly over a sphere, as here, so what is left is noise and the
/// spectral read-back of RGB photon flux); the test allows ±0.02.
#[test]
fn photon_mapping_furnaces_converge_to_radiance_one() {
    for (what, text) in furnaces() {
        let l = scene(&text);
        for color in [ColorMode::Rgb, ColorMode::Spectral] {
            let p = PhotonConfig {
                photons: 50_000,
                caustic_photons: 0,
                ..Default::default()
            };
            let s = settings(&l, IntegratorKind::Photon, 16, color, p, 3);
            let m = mean(&draw(&l, &s));
            for (c, v) in m.iter().enumerate() {
                assert!(
                    (v - 1.0).abs() <= 0.02,
                    "{what}, {color:?}: channel {c} has mean {v}, expected 1 ± 0.02"
                );
            }
        }
    }
}

/// The same photon-mapped image, bit for bit, on 1 and 3 threads (the photon pass's chunks,
/// the kd-tree's parallel build and the tiles all run differently), in both colour modes.
#[test]
fn photon_mapped_image_does_not_depend_on_thread_count() {
    let l = scene(&furnace16(
        "[[lights]]\ntype = \"point\"\nposition = [0.2, 0.1, 0]\nintensity = 3",
        "",
    ));
    for color in [ColorMode::Rgb, ColorMode::Spectral] {
        let p = PhotonConfig {
            photons: 40_000,
            caustic_photons: 5_000,
            ..Default::default()
        };
        let s = settings(&l, IntegratorKind::Photon, 2, color, p, 9);
        let films: Vec<Vec<[f32; 3]>> = [1, 3]
            .iter()
            .map(|&n| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build()
                    .unwrap()
                    .install(|| draw(&l, &s))
            })
            .collect();
        assert_eq!(films[0], films[1], "{color:?}");
    }
}

/// SPPM in the furnaces: L = 1 everywhere. 64 iterations of 20,000 photon paths, seed 3:
/// the image means came out within 0.009 of 1 (RGB within 0.004); the test asks ±0.01.
fn sppm_furnaces(color: ColorMode) {
    for (what, text) in furnaces() {
        let l = scene(&text);
        let p = PhotonConfig {
            sppm_photons: 20_000,
            ..Default::default()
        };
        let m = mean(&draw(
            &l,
            &settings(&l, IntegratorKind::Sppm, 64, color, p, 3),
        ));
        for (c, v) in m.iter().enumerate() {
            assert!(
                (v - 1.0).abs() <= 0.01,
                "{what}, {color:?}: channel {c} has mean {v}, expected 1 ± 0.01"
            );
        }
    }
}

#[test]
#[ignore = "full suite (cargo test -- --include-ignored): over 10 s"]
fn sppm_furnaces_converge_to_radiance_one_in_rgb() {
    sppm_furnaces(ColorMode::Rgb);
}

#[test]
#[ignore = "full suite (cargo test -- --include-ignored): over 10 s"]
fn sppm_furnaces_converge_to_radiance_one_spectrally() {
    sppm_furnaces(ColorMode::Spectral);
}

/// The same SPPM image, bit for bit, on 1 and 3 threads, in both colour modes.
#[test]
fn sppm_image_does_not_depend_on_thread_count() {
    let l = scene(&furnace16(
        "[[lights]]\ntype = \"point\"\nposition = [0.2, 0.1, 0]\nintensity = 3",
        "",
    ));
    for color in [ColorMode::Rgb, ColorMode::Spectral] {
        let p = PhotonConfig {
            sppm_photons: 10_000,
            ..Default::default()
        };
        let s = settings(&l, IntegratorKind::Sppm, 4, color, p, 9);
        let films: Vec<Vec<[f32; 3]>> = [1, 3]
            .iter()
            .map(|&n| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build()
                    .unwrap()
                    .install(|| draw(&l, &s))
            })
            .collect();
        assert_eq!(films[0], films[1], "{color:?}");
    }
}

/// SPPM passes the path tracer's per-pixel z-test against Mitsuba 3's Cornell box
/// (common::integrators::cbox_z_test): 16 independent renders of 32 iterations, each of
/// 16,384 photon paths, the radius chosen automatically (one pixel's footprint at first).
/// SPPM is biased at any finite iteration count (light blurred over the radius), and its
/// bias falls as fast as its noise (both as N^(-1/3) with α = 2/3), so the test asks that
/// the bias stay below the noise of these renders; a fixed radius of 0.004 fails it (97 %
/// pass). Measured: 99.93 % pass in RGB (squared error 1.16 × predicted), 99.88 %
/// spectrally (1.16 ×); at 16 iterations, spectrally, 99.70 %.
fn sppm_z_test(color: ColorMode, reference: &str, variance: &str) {
    cbox_z_test_with(IntegratorKind::Sppm, color, reference, variance, 32, |s| {
        s.integrator.photon.sppm_photons = 16_384;
    });
}

#[test]
#[ignore = "full suite (cargo test -- --include-ignored): over 10 s"]
fn sppm_matches_mitsuba_on_the_cornell_box_in_rgb() {
    sppm_z_test(ColorMode::Rgb, "reference.exr", "reference-variance.exr");
}

#[test]
#[ignore = "full suite (cargo test -- --include-ignored): over 10 s"]
fn sppm_matches_mitsuba_on_the_cornell_box_spectrally() {
    sppm_z_test(
        ColorMode::Spectral,
        "reference-spectral.exr",
        "reference-spectral-variance.exr",
    );
}

/// Bad photon settings are refused with a reason, by the render settings' check and by the
/// scene format (at the key).
#[test]
fn bad_photon_settings_give_clear_errors() {
    let l = scene(&furnace16("", "emission = [0.5, 0.5, 0.5]"));
    let base = PhotonConfig::default();
    for (bad, says) in [
        (PhotonConfig { photons: 0, ..base }, "photons"),
        (PhotonConfig { nearest: 0, ..base }, "density estimate"),
        (
            PhotonConfig {
                nearest: 100_000,
                ..base
            },
            "density estimate",
        ),
        (
            PhotonConfig {
                radius: -1.0,
                ..base
            },
            "radius",
        ),
        (
            PhotonConfig {
                radius: f64::NAN,
                ..base
            },
            "radius",
        ),
        (
            PhotonConfig {
                gather_rays: 0,
                ..base
            },
            "final-gather",
        ),
        (PhotonConfig { alpha: 1.0, ..base }, "alpha"),
        (PhotonConfig { alpha: 0.0, ..base }, "alpha"),
    ] {
        for kind in [IntegratorKind::Photon, IntegratorKind::Sppm] {
            let s = settings(&l, kind, 1, ColorMode::Rgb, bad, 0);
            let e = s.check().expect_err("bad settings are refused");
            assert!(e.contains(says), "{bad:?}: {e}");
        }
        // The path tracer does not read them.
        assert!(
            settings(&l, IntegratorKind::Path, 1, ColorMode::Rgb, bad, 0)
                .check()
                .is_ok()
        );
    }
    let mut s = settings(&l, IntegratorKind::Sppm, 4, ColorMode::Rgb, base, 0);
    s.filter = plenum_core::sampling::Filter::new(plenum_core::sampling::FilterKind::Gaussian, 1.5)
        .unwrap();
    assert!(s.check().unwrap_err().contains("box filter"));

    for (key, value) in [
        ("photons", "0"),
        ("photon_nearest", "0"),
        ("photon_radius", "-2"),
        ("gather_rays", "0"),
        ("sppm_alpha", "1.5"),
        ("caustic_photons", "-1"),
    ] {
        let text =
            furnace16("", "").replace("rr_depth = 5", &format!("rr_depth = 5\n{key} = {value}"));
        let e = parse_scene(Path::new("bad.toml"), &text, Path::new("."))
            .err()
            .unwrap_or_else(|| panic!("{key} = {value} is refused"))
            .to_string();
        assert!(
            e.contains("bad.toml:5:"),
            "{key} = {value}: the error points at it: {e}"
        );
    }
    let good = furnace16("", "").replace(
        "rr_depth = 5",
        "rr_depth = 5\nphotons = 1000\ncaustic_photons = 0\nphoton_nearest = 10\nphoton_radius = 0.5\ngather_rays = 4\nsppm_photons = 77\nsppm_alpha = 0.5",
    );
    let d = scene(&good).defaults.photon;
    assert_eq!(
        d,
        PhotonConfig {
            photons: 1000,
            caustic_photons: 0,
            nearest: 10,
            radius: 0.5,
            gather_rays: 4,
            sppm_photons: 77,
            alpha: 0.5,
        }
    );
    // The writer keeps them.
    let l = scene(&good);
    let back = scene(&plenum_scene::to_toml(&l.scene, &l.defaults));
    assert_eq!(back.defaults.photon, d);
}

/// `trace-pixel` for the photon methods lists the photons each density estimate used: all
/// within its radius, nearest first, at most k per estimate for photon mapping; for SPPM the
/// pixel's colour is what one iteration renders there (to 10⁻⁴: the render sums photons in
/// fixed point).
#[test]
fn trace_pixel_lists_the_photons_found() {
    let l = load_cornell_box();
    let (x, y) = (100, 230);
    for kind in [IntegratorKind::Photon, IntegratorKind::Sppm] {
        let p = PhotonConfig {
            photons: 20_000,
            caustic_photons: 0,
            nearest: 32,
            ..Default::default()
        };
        // Photon mapping: every ray of 8 samples; SPPM: its first iteration.
        let s = settings(&l, kind, 8, ColorMode::Rgb, p, 4);
        let (tree, color) = trace_pixel(&l.scene, &s, x, y);
        let gathers: Vec<_> = tree
            .nodes
            .iter()
            .filter_map(|n| n.photons.as_ref())
            .collect();
        assert!(
            !gathers.is_empty(),
            "{}: no density estimate recorded",
            kind.name()
        );
        let mut total = 0;
        for g in &gathers {
            total += g.photons.len();
            if kind == IntegratorKind::Photon {
                assert!(
                    g.photons.len() <= 32,
                    "{} photons for k = 32",
                    g.photons.len()
                );
            }
            for pair in g.photons.windows(2) {
                assert!(pair[0].distance <= pair[1].distance, "nearest first");
            }
            for ph in &g.photons {
                assert!(
                    ph.distance <= g.radius * (1.0 + 1e-5),
                    "{}: a photon outside the radius",
                    kind.name()
                );
            }
        }
        assert!(total > 0, "{}: no photon found at the floor", kind.name());
        if kind == IntegratorKind::Sppm {
            let image = draw(&l, &settings(&l, kind, 1, ColorMode::Rgb, p, 4));
            let rendered = image[(y * s.width + x) as usize];
            for (c, v) in [color.r, color.g, color.b].into_iter().enumerate() {
                assert!(
                    (v - rendered[c] as f64).abs() <= 1e-4 * (1.0 + v.abs()),
                    "channel {c}: trace-pixel gives {v}, the render {}",
                    rendered[c]
                );
            }
        }
    }
}

/// A lamp (a rectangle light, whose surface also carries a Phong k_e for Whitted) over a
/// floor: photon mapping's image mean within 1 % of the path tracer's per channel (RGB, seed
/// 5; 32×24 pixels, 64 spp each; measured 0.0 %). A final-gather ray that met the lamp
/// counted it as k_e, in full, on top of the light sample: twice the floor's light (+100 %).
#[test]
fn a_lamp_a_gather_ray_meets_counts_once() {
    let l = scene(
        r#"
[render]
max_depth = 3
[camera]
position = [0.0, 2.4, 8.5]
look_at = [0.0, 0.7, 0.0]
fov = 34
resolution = [32, 24]
[materials.floor]
type = "diffuse"
reflectance = 0.5
[[lights]]
type = "rectangle"
corner = [-3.0, 6.0, 2.0]
edge_u = [2.0, 0.0, 0.0]
edge_v = [0.0, 0.0, 2.0]
color = [1.0, 0.9, 0.75]
intensity = 12
[[objects]]
type = "plane"
material = "floor"
normal = [0, 1, 0]
"#,
    );
    let reference = mean(
        &render_checked(
            &l,
            &settings_for(&l, IntegratorKind::Path, 64, ColorMode::Rgb, 5),
        )
        .film
        .pixels()
        .to_vec(),
    );
    let photon = PhotonConfig {
        photons: 20_000,
        caustic_photons: 20_000,
        ..PhotonConfig::default()
    };
    let m = mean(&draw(
        &l,
        &settings(&l, IntegratorKind::Photon, 64, ColorMode::Rgb, photon, 5),
    ));
    assert_mean_within("photon", m, "the path tracer's", reference, 0.01);
}

/// Spectral photons keep the sign of their colours. A green lamp's caustic through a glass
/// ball on a grey floor: every surface is grey, so the image has the lamp's colour, whose
/// red is about −0.001 of its green (−0.0004 by BDPT at 256 spp, −0.0017 by integrating
/// the uplifted (0, 1, 0) at 1 nm). A photon's flux seen at four wavelengths is a colour far
/// outside the gamut (at 500 nm red is strongly negative); read back as the spectrum fitted
/// to its clamped colour, each photon lost its negative red, and red/green came out
/// +0.0051 to +0.0067 (seeds 1–5). Positive part minus negative part: −0.0009 to +0.0009
/// (seeds 1–6). Tolerance 0.0025 about 0.
#[test]
fn spectral_photons_keep_negative_channels() {
    let l = scene(
        r#"
[render]
max_depth = 5
[camera]
position = [0.0, 2.4, 6.5]
look_at = [0.0, 0.5, 0.0]
fov = 34
resolution = [48, 36]
[materials.floor]
type = "diffuse"
reflectance = 0.8
[materials.glass]
type = "dielectric"
eta = 1.5
[[lights]]
type = "rectangle"
corner = [-0.5, 5.0, -0.5]
edge_u = [1.0, 0.0, 0.0]
edge_v = [0.0, 0.0, 1.0]
color = [0.0, 1.0, 0.0]
intensity = 30
[[objects]]
type = "plane"
material = "floor"
normal = [0, 1, 0]
[[objects]]
type = "sphere"
material = "glass"
center = [0.0, 1.0, 0.0]
radius = 1.0
"#,
    );
    let photon = PhotonConfig {
        photons: 20_000,
        caustic_photons: 500_000,
        ..PhotonConfig::default()
    };
    let m = mean(&draw(
        &l,
        &settings(
            &l,
            IntegratorKind::Photon,
            128,
            ColorMode::Spectral,
            photon,
            1,
        ),
    ));
    let ratio = m[0] / m[1];
    assert!(
        ratio.abs() < 0.0025,
        "red/green {ratio:.5}, the lamp's about −0.001: spectral photons lose the sign of their colour"
    );
}
