//! The integrator ladder on one scene description: local illumination and Appel's method
//! against Whitted's, and light tracing and bidirectional path tracing against closed forms
//! (pbrt-v4's furnace scenes), against Mitsuba 3's Cornell box, against the path tracer on
//! smooth-shaded geometry, and against themselves for any thread count.

use plenum_core::integrator::{ColorMode, IntegratorKind};
use plenum_core::raw_film::RawFilm;
use plenum_core::render::{new_film, render, render_film, Adaptive, RenderControl, RenderSettings};
use plenum_core::sampling::{Filter, FilterKind};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

mod common;
use common::integrators::*;

/// The furnace (a sphere of reflectance 0.5 around the camera) converges to radiance 1
/// under light tracing and BDPT as under the path tracer: 1024 spp on 12×12 pixels, image
/// mean within ±0.01 (seed 3; light tracing's standard error is about 0.003 there, BDPT's
/// less).
#[test]
#[ignore = "full suite (cargo test -- --include-ignored): over 10 s"]
fn light_tracing_and_bdpt_converge_in_the_furnace() {
    let cases = furnace_cases();
    for kind in [IntegratorKind::Light, IntegratorKind::Bdpt] {
        for (what, light, emission) in &cases {
            let l = scene(&furnace(light, emission));
            for color in [ColorMode::Rgb, ColorMode::Spectral] {
                let m = mean(&draw(&l, &settings_for(&l, kind, 1024, color, 3)));
                for (c, v) in m.iter().enumerate() {
                    assert!(
                        (v - 1.0).abs() <= 0.01,
                        "{}, {what}, {color:?}: channel {c} has mean {v}, expected 1 ± 0.01",
                        kind.name()
                    );
                }
            }
        }
    }
}

/// The methods that converge to the physically based image.
const PHYSICAL: [IntegratorKind; 5] = [
    IntegratorKind::Path,
    IntegratorKind::Light,
    IntegratorKind::Bdpt,
    IntegratorKind::Photon,
    IntegratorKind::Sppm,
];

/// Every method counts bounces alike: in the furnaces cut at `max_depth` D, light that
/// bounced at most D + 1 times from the emitter to the eye arrives, 1 − 0.5^(D+1) under the
/// point lights and 1 − 0.5^(D+2) from the emitting sphere (its emission seen directly
/// counts). The last vertex's direct light is where a method that weighs light sampling
/// against a bounce it does not take would lose light (the path tracer did: 0.625 for 0.75).
/// 256 spp (light tracing 1024, photon mapping 64), RGB, seed 7; each image mean within
/// ±0.01 (photon mapping, biased, ±0.02).
#[test]
fn every_method_cuts_paths_at_the_same_depth() {
    let cases = furnace_cases();
    for depth in [0u32, 1] {
        for (what, light, emission) in &cases {
            let text = furnace(light, emission)
                .replace("max_depth = 100", &format!("max_depth = {depth}"));
            let l = scene(&text);
            let expected = match emission.is_empty() {
                true => 1.0 - 0.5f64.powi(depth as i32 + 1),
                false => 1.0 - 0.5f64.powi(depth as i32 + 2),
            };
            for kind in PHYSICAL {
                let (spp, tolerance) = match kind {
                    IntegratorKind::Photon => (64, 0.02),
                    IntegratorKind::Light => (1024, 0.01),
                    _ => (256, 0.01),
                };
                let m = mean(&draw(&l, &settings_for(&l, kind, spp, ColorMode::Rgb, 7)));
                for (c, v) in m.iter().enumerate() {
                    assert!(
                        (v - expected).abs() <= tolerance,
                        "{} at max_depth {depth}, {what}: channel {c} has mean {v}, expected {expected}",
                        kind.name()
                    );
                }
            }
        }
    }
}

/// Every physically based method converges in a furnace with every sampler (their random
/// numbers feed the light paths too): the sphere lit by its own emission 0.5, radiance 1
/// everywhere; 256 samples (SPPM: iterations) per pixel, light tracing 1024, RGB, seed 11;
/// each image mean within ±0.01 of 1 (photon mapping, biased, ±0.02). `cook16` once paired
/// its regions by one table for every pixel, which tied light tracing's choices together
/// across the image (0.87 for 1); its tables are now drawn per pixel and pass.
#[test]
#[ignore = "full suite (cargo test -- --include-ignored): over 10 s"]
fn every_method_converges_with_every_sampler() {
    use plenum_core::sampling::{PixelSampler, SamplerKind};
    let (_, _, emission) = &furnace_cases()[2];
    let l = scene(&furnace("", emission));
    let mut failures = Vec::new();
    for sampler in [
        SamplerKind::Grid,
        SamplerKind::Random,
        SamplerKind::Jittered,
        SamplerKind::Cook16,
        SamplerKind::Sobol,
    ] {
        for kind in PHYSICAL {
            let (spp, tolerance) = match kind {
                IntegratorKind::Light => (1024, 0.01),
                IntegratorKind::Photon => (256, 0.02),
                _ => (256, 0.01),
            };
            let mut s = settings_for(&l, kind, spp, ColorMode::Rgb, 11);
            s.sampler = PixelSampler::new(sampler, spp);
            let m = mean(&draw(&l, &s));
            if m.iter().any(|v| (v - 1.0).abs() > tolerance) {
                failures.push(format!(
                    "{} with the {} sampler: mean {m:?}, expected 1 ± {tolerance}",
                    kind.name(),
                    sampler.name()
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
#[ignore = "full suite (cargo test -- --include-ignored): over 10 s"]
fn light_tracing_matches_mitsuba_on_the_cornell_box() {
    cbox_z_test(
        IntegratorKind::Light,
        ColorMode::Spectral,
        "reference-spectral.exr",
        "reference-spectral-variance.exr",
    );
}

#[test]
#[ignore = "full suite (cargo test -- --include-ignored): over 10 s"]
fn bdpt_matches_mitsuba_on_the_cornell_box() {
    cbox_z_test(
        IntegratorKind::Bdpt,
        ColorMode::Rgb,
        "reference.exr",
        "reference-variance.exr",
    );
}

/// A floor whose shading normals lean 35° away from its true normal, lit by a small area
/// light: light carried from the light (light tracing, BDPT's light subpaths) scatters by
/// the adjoint BSDF with Veach's correction, so all three methods see the same floor. Means
/// over 20×16 pixels at 256 spp agree within 1.5 % (seed 5).
#[test]
fn light_from_the_lights_and_from_the_camera_agree_on_shading_normals() {
    let l = scene(
        r#"
[render]
max_depth = 3
[camera]
position = [0, 2, 3]
look_at = [0, 0, 0]
fov = 40
resolution = [20, 16]
[materials.white]
type = "diffuse"
reflectance = 0.7
[meshes.floor]
positions = [[-3, 0, -3], [3, 0, -3], [3, 0, 3], [-3, 0, 3]]
indices = [[0, 2, 1], [0, 3, 2]]
normals = [[0.7, 1, 0], [0.7, 1, 0], [0.7, 1, 0], [0.7, 1, 0]]
[[objects]]
type = "mesh"
mesh = "floor"
material = "white"
[[objects]]
type = "mesh"
name = "lamp"
positions = [[-0.3, 1.5, -0.3], [-0.3, 1.5, 0.3], [0.3, 1.5, 0.3], [0.3, 1.5, -0.3]]
indices = [[0, 1, 2], [0, 2, 3]]
emission = [5, 5, 5]
"#,
    );
    let means: Vec<(IntegratorKind, f64)> = [
        IntegratorKind::Path,
        IntegratorKind::Light,
        IntegratorKind::Bdpt,
    ]
    .into_iter()
    .map(|kind| {
        let m = mean(&draw(&l, &settings_for(&l, kind, 256, ColorMode::Rgb, 5)));
        (kind, m.iter().sum::<f64>() / 3.0)
    })
    .collect();
    let path = means[0].1;
    for &(kind, m) in &means[1..] {
        assert!(
            (m / path - 1.0).abs() < 0.015,
            "{} gives mean {m}, the path tracer {path}",
            kind.name()
        );
    }
}

/// Splats from light paths are summed in fixed point, so light tracing and BDPT give the
/// same bytes for 1 and 3 threads, in both colour modes.
#[test]
fn splatting_integrators_do_not_depend_on_thread_count() {
    let l = load_cornell_box();
    for kind in [IntegratorKind::Light, IntegratorKind::Bdpt] {
        for color in [ColorMode::Rgb, ColorMode::Spectral] {
            let mut settings = settings_for(&l, kind, 2, color, 9);
            settings.width = 40;
            settings.height = 40;
            let films: Vec<Vec<[f32; 3]>> = [1, 3]
                .iter()
                .map(|&n| {
                    rayon::ThreadPoolBuilder::new()
                        .num_threads(n)
                        .build()
                        .unwrap()
                        .install(|| draw(&l, &settings))
                })
                .collect();
            assert_eq!(films[0], films[1], "{} {color:?}", kind.name());
        }
    }
}

/// BDPT's strategy images, weighted by MIS, add up to its image (to the fixed point's and
/// f32's rounding); each unweighted image is a whole estimate of the paths of its length
/// that its strategy can make, so lengths that every strategy sees (two-bounce light on
/// the diffuse box) have equal means for every (s, t) of that length, within noise.
#[test]
fn bdpt_strategies_sum_to_the_image() {
    let l = load_cornell_box();
    let mut settings: RenderSettings =
        settings_for(&l, IntegratorKind::Bdpt, 128, ColorMode::Rgb, 4);
    settings.width = 32;
    settings.height = 32;
    settings.integrator.max_depth = 2;
    settings.integrator.strategies = true;
    let out = render(&l.scene, &settings, &AtomicBool::new(false), &|_, _| {});
    let image = out.film.pixels();
    let mut sum = vec![[0.0f64; 3]; image.len()];
    for (_, _, weighted, _) in &out.strategies {
        for (s, p) in sum.iter_mut().zip(weighted.pixels()) {
            for c in 0..3 {
                s[c] += p[c] as f64;
            }
        }
    }
    // (s, t) with t ≥ 1 and s + t vertices, 2 to 5 at max_depth 2, but (1, 1).
    assert_eq!(out.strategies.len(), 1 + 3 + 4 + 5);
    for (a, b) in image.iter().zip(&sum) {
        for c in 0..3 {
            assert!(
                (a[c] as f64 - b[c]).abs() <= 1e-4 * (1.0 + b[c]),
                "pixel {a:?} vs strategies' sum {b:?}"
            );
        }
    }
    // Paths of 4 vertices (one bounce) come from (0,4), (1,3), (2,2) and (3,1); each
    // unweighted image estimates them all (the box has no specular surface). Those that
    // sample the light by its area agree within 6 % at this sample count; (0,4), which
    // must hit the small lamp by chance, is far noisier: within 30 % (seed 4).
    let means: Vec<(usize, f64)> = out
        .strategies
        .iter()
        .filter(|(s, t, _, _)| s + t == 4)
        .map(|(s, _, _, plain)| (*s, mean(plain.pixels()).iter().sum::<f64>()))
        .collect();
    assert_eq!(means.len(), 4);
    let by_light = means[1].1;
    for &(s, m) in &means {
        let tolerance = if s == 0 { 0.3 } else { 0.06 };
        assert!(
            (m / by_light - 1.0).abs() < tolerance,
            "{means:?}: (s, mean) for s + t = 4"
        );
    }
}

/// Appel's method is Whitted's without recursion, and local illumination Appel's without
/// shadow rays: on the built-in scene, Appel's image equals Whitted's at depth 0, local
/// illumination traces no shadow ray, and no pixel of it is darker than Appel's.
#[test]
fn local_and_appel_are_the_first_rungs() {
    let l = plenum_scene::builtin_scene();
    let base = |kind, depth| {
        let mut s = settings_for(&l, kind, 1, ColorMode::Rgb, 0);
        s.width = 64;
        s.height = 48;
        s.integrator.max_depth = depth;
        s
    };
    let run = |s: &RenderSettings| render(&l.scene, s, &AtomicBool::new(false), &|_, _| {});
    let whitted = run(&base(IntegratorKind::Whitted, 0));
    let appel = run(&base(IntegratorKind::Appel, 5));
    let local = run(&base(IntegratorKind::Local, 5));
    assert_eq!(appel.film.pixels(), whitted.film.pixels());
    assert!(appel.counts.shadow > 0);
    assert_eq!(appel.counts.reflection + appel.counts.refraction, 0);
    assert_eq!(local.counts.shadow, 0);
    let mut brighter = 0;
    for (a, b) in local.film.pixels().iter().zip(appel.film.pixels()) {
        for c in 0..3 {
            assert!(a[c] >= b[c] - 1e-6, "local {a:?} darker than Appel {b:?}");
        }
        brighter += usize::from(a != b);
    }
    assert!(brighter > 0, "shadows must darken some pixel");
}

/// Light paths reach the film through a thin lens (a hexagonal aperture) on a moving
/// camera: light tracing and BDPT agree with the path tracer on the Cornell box seen so,
/// image means over 32×32 pixels at 128 spp within 2 % (seed 6).
#[test]
fn light_paths_find_the_lens_of_a_moving_thin_lens_camera() {
    use plenum_core::camera::Lens;
    use plenum_core::Vec3;
    let mut l = load_cornell_box();
    l.scene.camera.lens = Lens {
        radius: 0.15,
        focus_distance: 3.0,
        blades: 6,
        rotation_degrees: 15.0,
    };
    let (p, at) = (l.scene.camera.position, l.scene.camera.look_at);
    l.scene.camera.motion = Some((p + Vec3::new(0.3, 0.0, 0.0), at));
    let means: Vec<(IntegratorKind, f64)> = [
        IntegratorKind::Path,
        IntegratorKind::Light,
        IntegratorKind::Bdpt,
    ]
    .into_iter()
    .map(|kind| {
        let mut s = settings_for(&l, kind, 128, ColorMode::Rgb, 6);
        s.width = 32;
        s.height = 32;
        let m = mean(&draw(&l, &s));
        (kind, m.iter().sum::<f64>() / 3.0)
    })
    .collect();
    let path = means[0].1;
    for &(kind, m) in &means[1..] {
        assert!(
            (m / path - 1.0).abs() < 0.02,
            "{} gives mean {m}, the path tracer {path}",
            kind.name()
        );
    }
}

/// Light tracing and BDPT spread each splat over the pixels within the filter's radius
/// (weights f / ∫∫f), so with a wide filter they estimate the same filtered pixels as the
/// path tracer's filter-sampled camera rays. The Cornell box at 48×48, RGB: 8 renders each
/// (path 32 spp, light 128, bdpt 32; seeds of each method's own), per-pixel z-test between the methods,
/// at least 99.5 % of pixel channels pass and the squared difference within 0.75–1.33 of
/// what the two variances predict, over the pixels that do not see the lamp (nor lie within
/// 2 of it): on the lamp itself light tracing comes out 0.45 % darker than the path tracer
/// at this size with the box filter too (1 % with the Gaussian), a discrepancy of its own,
/// open in docs/integrators.md. Against the path tracer's box-filtered image the
/// Mitchell-filtered light-traced one fails (the test can tell the filters apart).
#[test]
#[ignore = "full suite (cargo test -- --include-ignored): over 10 s"]
fn splatting_integrators_honour_the_pixel_filter() {
    use plenum_core::sampling::{Filter, FilterKind};
    let l = load_cornell_box();
    // Seeds of their own per method: BDPT's camera subpaths would repeat the path tracer's.
    let images = |kind: IntegratorKind, spp: u32, filter: &Filter| {
        let first = 100 * kind as u64;
        let renders: Vec<Vec<[f32; 3]>> = (first..first + 8)
            .map(|seed| {
                let mut s = settings_for(&l, kind, spp, ColorMode::Rgb, seed);
                (s.width, s.height) = (48, 48);
                s.filter = filter.clone();
                draw(&l, &s)
            })
            .collect();
        mean_and_variance(&renders)
    };
    let box_path = images(IntegratorKind::Path, 32, &Filter::box_pixel());
    // The lamp seen directly and the pixels within 2 of it are left out (see above).
    let w = 48i64;
    let lamp = |i: i64| box_path.0[i as usize].iter().sum::<f64>() > 3.0;
    let kept: Vec<usize> = (0..w * w)
        .filter(|&i| {
            let (x, y) = (i % w, i / w);
            !(-2..=2).any(|dy| {
                (-2..=2).any(|dx| {
                    let (u, v) = (x + dx, y + dy);
                    (0..w).contains(&u) && (0..w).contains(&v) && lamp(v * w + u)
                })
            })
        })
        .map(|i| i as usize)
        .collect();
    let compare = |a: &(Vec<[f64; 3]>, Vec<[f64; 3]>), b: &(Vec<[f64; 3]>, Vec<[f64; 3]>)| {
        let pick = |v: &[[f64; 3]]| kept.iter().map(|&i| v[i]).collect::<Vec<_>>();
        let (rate, ratio, _) = z_test(&pick(&a.0), &pick(&a.1), &pick(&b.0), &pick(&b.1));
        (rate, ratio)
    };
    for kind in [FilterKind::Mitchell, FilterKind::Gaussian] {
        let filter = Filter::new(kind, kind.default_radius()).unwrap();
        let path = images(IntegratorKind::Path, 32, &filter);
        for (method, spp) in [(IntegratorKind::Light, 128), (IntegratorKind::Bdpt, 32)] {
            let (rate, ratio) = compare(&images(method, spp, &filter), &path);
            eprintln!(
                "{} against path, {} filter: {:.3} % pass, squared difference {ratio:.3} × predicted",
                method.name(),
                kind.name(),
                100.0 * rate
            );
            assert!(rate >= 0.995, "{}, {}: {rate}", method.name(), kind.name());
            assert!(
                (0.75..=1.33).contains(&ratio),
                "{}, {}: {ratio}",
                method.name(),
                kind.name()
            );
            if kind == FilterKind::Mitchell && method == IntegratorKind::Light {
                let (rate, ratio) = compare(&images(method, spp, &filter), &box_path);
                eprintln!("light with Mitchell against path with box: {:.3} % pass, {ratio:.3} × predicted", 100.0 * rate);
                assert!(
                    rate < 0.995 || ratio > 1.33,
                    "the filters cannot be told apart"
                );
            }
        }
    }
}

/// Renders into `film`, handing a copy of it to `saved` at every checkpoint (after each
/// round of tiles, the interval being zero) and cancelling once `stop_after` tiles are done.
fn render_stopping(
    l: &plenum_scene::LoadedScene,
    settings: &RenderSettings,
    film: &mut RawFilm,
    saved: Option<&mut Vec<RawFilm>>,
    stop_after: Option<usize>,
) -> Vec<[f32; 3]> {
    let cancel = AtomicBool::new(false);
    let progress = |done: usize, _: usize| {
        if stop_after.is_some_and(|n| done >= n) {
            cancel.store(true, Ordering::SeqCst);
        }
    };
    let checkpointing = saved.is_some();
    let mut saved = saved;
    let mut keep = |f: &RawFilm| {
        if let Some(s) = saved.as_deref_mut() {
            s.push(f.clone());
        }
    };
    let checkpoint: Option<(Duration, &mut dyn FnMut(&RawFilm))> = if checkpointing {
        Some((Duration::ZERO, &mut keep))
    } else {
        None
    };
    let control = RenderControl {
        cancel: &cancel,
        progress: &progress,
        checkpoint,
    };
    render_film(&l.scene, settings, film, control)
        .film
        .pixels()
        .to_vec()
}

/// Every method but SPPM sums its pixels in fixed point: a render stopped at any checkpoint
/// or cancelled mid-way and continued from its film, or split into sample ranges rendered
/// apart and merged, gives the same bytes as one render. SPPM continues from its
/// statistics after whole iterations, to the same bytes. With the box filter and with
/// Mitchell's (negative lobes, splats spread over several pixels), in both colour modes;
/// adaptive sampling (Whitted's subdivision, and by variance over its two passes) resumes
/// to the same bytes too.
#[test]
fn every_method_resumes_and_merges_to_the_same_bytes() {
    let l = plenum_scene::load_scene(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/ladder.toml"),
    )
    .unwrap();
    let mut cases = Vec::new();
    for (i, kind) in IntegratorKind::ALL.into_iter().enumerate() {
        if kind == IntegratorKind::Sppm {
            continue;
        }
        let color = if i % 2 == 0 {
            ColorMode::Rgb
        } else {
            ColorMode::Spectral
        };
        let mut s = settings_for(&l, kind, 4, color, 5);
        (s.width, s.height) = (40, 34);
        s.integrator.photon.photons = 3000;
        s.integrator.photon.caustic_photons = 3000;
        cases.push(s.clone());
        if kind.splats() || kind == IntegratorKind::Path {
            s.filter = Filter::new(FilterKind::Mitchell, 2.0).unwrap();
            cases.push(s);
        }
    }
    for s in &cases {
        let name = format!(
            "{} {:?} {:?}",
            s.integrator.kind.name(),
            s.integrator.color,
            s.filter
        );
        let whole = draw(&l, s);
        let spp = s.sampler.samples_per_pixel();
        // Every checkpoint, continued.
        let mut saved = Vec::new();
        let mut film = new_film(s, 0..spp);
        let image = render_stopping(&l, s, &mut film, Some(&mut saved), None);
        assert!(image == whole, "{name}: a render that checkpoints");
        assert!(saved.len() >= 3, "{name}: {} checkpoints", saved.len());
        for (i, f) in saved.iter().enumerate().step_by(2) {
            let mut f = f.clone();
            let image = render_stopping(&l, s, &mut f, None, None);
            assert!(image == whole, "{name}: continued from checkpoint {i}");
        }
        // Cancelled after three tiles, then continued.
        let mut film = new_film(s, 0..spp);
        render_stopping(&l, s, &mut film, None, Some(3));
        assert!(!film.is_complete(1), "{name}: the cancel stopped it");
        let image = render_stopping(&l, s, &mut film, None, None);
        assert!(image == whole, "{name}: continued after a cancel");
        // Sample ranges, merged in any order.
        let parts: Vec<RawFilm> = [2..4, 0..1, 1..2]
            .into_iter()
            .map(|r| {
                let mut f = new_film(s, r);
                render_stopping(&l, s, &mut f, None, None);
                f
            })
            .collect();
        let merged = RawFilm::merge(parts).unwrap();
        assert!(
            merged.image().pixels() == &whole[..],
            "{name}: merged ranges"
        );
    }
    // Adaptive sampling resumes (it cannot be split into sample ranges).
    for adaptive in [
        Adaptive::Subdivide {
            contrast: 0.05,
            depth: 2,
        },
        Adaptive::Variance {
            threshold: 0.05,
            min_spp: 4,
            max_spp: 16,
        },
    ] {
        for kind in [IntegratorKind::Whitted, IntegratorKind::Path] {
            let mut s = settings_for(&l, kind, 4, ColorMode::Rgb, 5);
            (s.width, s.height) = (40, 34);
            s.adaptive = Some(adaptive);
            let whole = draw(&l, &s);
            let mut saved = Vec::new();
            let mut film = new_film(&s, 0..4);
            render_stopping(&l, &s, &mut film, Some(&mut saved), None);
            for (i, f) in saved.iter().enumerate() {
                let mut f = f.clone();
                let image = render_stopping(&l, &s, &mut f, None, None);
                assert!(
                    image == whole,
                    "{adaptive:?} {}: checkpoint {i}",
                    kind.name()
                );
            }
        }
    }
    // SPPM continues from its statistics after any iteration, in both colour modes; its
    // films are refused by merge (each iteration gathers within the radii the last left).
    for color in [ColorMode::Rgb, ColorMode::Spectral] {
        let mut s = settings_for(&l, IntegratorKind::Sppm, 4, color, 5);
        (s.width, s.height) = (40, 34);
        s.integrator.photon.sppm_photons = 2000;
        let whole = draw(&l, &s);
        let mut saved = Vec::new();
        let mut film = new_film(&s, 0..4);
        let image = render_stopping(&l, &s, &mut film, Some(&mut saved), None);
        assert!(image == whole, "sppm {color:?}: a render that checkpoints");
        assert_eq!(
            saved.len(),
            3,
            "sppm {color:?}: a checkpoint after each iteration but the last"
        );
        for (i, f) in saved.iter().enumerate() {
            let mut f = f.clone();
            let image = render_stopping(&l, &s, &mut f, None, None);
            assert!(
                image == whole,
                "sppm {color:?}: continued from checkpoint {i}"
            );
        }
        let mut film = new_film(&s, 0..4);
        render_stopping(&l, &s, &mut film, None, Some(2));
        assert!(
            !film.is_complete(1),
            "sppm {color:?}: the cancel stopped it"
        );
        let image = render_stopping(&l, &s, &mut film, None, None);
        assert!(image == whole, "sppm {color:?}: continued after a cancel");
        let e = RawFilm::merge(vec![film.clone(), film]).unwrap_err();
        assert!(e.contains("SPPM renders cannot be merged"), "{e}");
    }
}

/// At `max_depth` 0 (direct light only) light that only a BSDF-sampled ray finds still
/// counts at the path's last vertex, as in pbrt-v4 and Mitsuba: the sky over a white plane
/// (radiance ρ = 0.8 everywhere, in closed form), and a lamp seen in a mirror. The path
/// tracer took neither (black, where BDPT gave the sky's 0.8 and the lamp). 64 spp, RGB,
/// seed 4; the plane within ±0.01 of 0.8 under both, the mirror's lamp within 1 % between
/// them.
#[test]
fn the_last_vertex_takes_the_light_its_bsdf_ray_meets() {
    let sky = scene(
        r#"
background = [1, 1, 1]
[render]
max_depth = 0
[camera]
position = [0, 1, 0]
look_at = [0, 0, 0]
up = [0, 0, -1]
fov = 60
resolution = [12, 12]
[materials.white]
type = "diffuse"
reflectance = 0.8
[[objects]]
type = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "white"
"#,
    );
    for kind in [IntegratorKind::Path, IntegratorKind::Bdpt] {
        let m = mean(&draw(
            &sky,
            &settings_for(&sky, kind, 64, ColorMode::Rgb, 4),
        ));
        for v in m {
            assert!(
                (v - 0.8).abs() < 0.01,
                "{}: the sky over a white plane gives {v}, not 0.8",
                kind.name()
            );
        }
    }
    let mirror = scene(
        r#"
[render]
max_depth = 0
[camera]
position = [0, 0, 0]
look_at = [0, 0, -1]
fov = 40
resolution = [12, 12]
[materials.mirror]
type = "conductor"
metal = "Ag"
[[objects]]
type = "polygon"
vertices = [[-5, -5, -1], [5, -5, -1], [5, 5, -1], [-5, 5, -1]]
material = "mirror"
[[objects]]
type = "polygon"
vertices = [[-5, -5, 2], [-5, 5, 2], [5, 5, 2], [5, -5, 2]]
emission = [2, 2, 2]
two_sided = false
"#,
    );
    let path = mean(&draw(
        &mirror,
        &settings_for(&mirror, IntegratorKind::Path, 64, ColorMode::Rgb, 4),
    ));
    let bdpt = mean(&draw(
        &mirror,
        &settings_for(&mirror, IntegratorKind::Bdpt, 64, ColorMode::Rgb, 4),
    ));
    for c in 0..3 {
        assert!(path[c] > 1.5, "the lamp in the mirror: {path:?}");
        assert!(
            (path[c] / bdpt[c] - 1.0).abs() < 0.01,
            "path {path:?}, bdpt {bdpt:?}"
        );
    }
}

/// Two equal lights over a floor, the left half of one hidden just beneath it: the path
/// tracer picks a light in one dimension and a point on it in the next. `cook16` once paired
/// those by one table for every pixel, so the samples that picked the half-hidden light
/// always landed in the same regions of it, however many there were. Its image mean must
/// match `random`'s and `jittered`'s within 5σ, σ from the spread of the means of 8
/// independent renders of each (32×32 pixels, 256 spp, direct light only, RGB, seeds
/// 20–27). Measured: 1.0σ and 1.6σ; with Cook's one table 0.76 % bright, 7.0σ from random.
#[test]
fn cook16_sees_a_half_hidden_light_as_the_other_samplers_do() {
    use plenum_core::sampling::{PixelSampler, SamplerKind};
    let l = scene(
        r#"
[render]
max_depth = 0
[camera]
position = [0, 3, 0]
look_at = [0, 0, 0]
up = [0, 0, -1]
fov = 70
resolution = [32, 32]
[materials.floor]
type = "diffuse"
reflectance = 0.5
[materials.black]
type = "diffuse"
reflectance = 0
[[lights]]
type = "rectangle"
corner = [-1.25, 1, -0.25]
edge_u = [0.5, 0, 0]
edge_v = [0, 0, 0.5]
intensity = 4
[[lights]]
type = "rectangle"
corner = [0.75, 1, -0.25]
edge_u = [0.5, 0, 0]
edge_v = [0, 0, 0.5]
intensity = 4
[[objects]]
type = "polygon"
material = "floor"
vertices = [[-3, 0, -3], [-3, 0, 3], [3, 0, 3], [3, 0, -3]]
[[objects]]
type = "polygon"
material = "black"
vertices = [[0.7, 0.999, -0.3], [0.7, 0.999, 0.3], [1.0, 0.999, 0.3], [1.0, 0.999, -0.3]]
"#,
    );
    let stats = |sampler: SamplerKind| -> (f64, f64) {
        let means: Vec<f64> = (20..28)
            .map(|seed| {
                let mut s = settings_for(&l, IntegratorKind::Path, 256, ColorMode::Rgb, seed);
                s.sampler = PixelSampler::new(sampler, 256);
                mean(&draw(&l, &s))[1]
            })
            .collect();
        let k = means.len() as f64;
        let m = means.iter().sum::<f64>() / k;
        let var = means.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (k - 1.0) / k;
        (m, var)
    };
    let (cook, vc) = stats(SamplerKind::Cook16);
    for other in [SamplerKind::Random, SamplerKind::Jittered] {
        let (m, v) = stats(other);
        let z = (cook - m) / (vc + v).sqrt();
        assert!(
            z.abs() < 5.0,
            "cook16's mean {cook:.5} against {}'s {m:.5}: {z:.1}σ",
            other.name()
        );
    }
}

/// The variance image (`--aov variance`: each pixel's variance of its value, from its own
/// samples) predicts how the pixel's value spreads between independent renders. On the
/// Cornell box at 32×32, 16 spp, path tracing, RGB, with the box and the Gaussian filter:
/// the mean over the image of the variance images of 24 renders (seeds 40–63) matches the
/// mean of the variances of their pixel values to within 12 % (each side's own noise is a
/// few per cent). Splatting methods and SPPM give no variance image.
#[test]
fn the_variance_image_predicts_the_spread_between_renders() {
    let l = load_cornell_box();
    for filter in [
        Filter::default(),
        Filter::new(FilterKind::Gaussian, 2.0).unwrap(),
    ] {
        let (mut predicted, mut images) = (0.0, Vec::new());
        for seed in 40..64 {
            let mut s = path_settings(&l, 16, ColorMode::Rgb, seed);
            (s.width, s.height) = (32, 32);
            s.filter = filter.clone();
            let mut film = new_film(&s, 0..16);
            images.push(render_stopping(&l, &s, &mut film, None, None));
            let v = film
                .variance_image()
                .expect("the path tracer's pixels are its samples");
            predicted += v.pixels().iter().map(|p| p[1] as f64).sum::<f64>();
        }
        let k = images.len() as f64;
        predicted /= k * 1024.0;
        let (_, var_of_mean) = mean_and_variance(&images);
        // The variance of one render's value: that of the mean of k renders, times k.
        let observed = var_of_mean.iter().map(|v| v[1] * k).sum::<f64>() / 1024.0;
        let ratio = predicted / observed;
        assert!(
            (0.88..=1.12).contains(&ratio),
            "{filter:?}: predicted / observed = {ratio}"
        );
    }
    let mut s = settings_for(&l, IntegratorKind::Bdpt, 4, ColorMode::Rgb, 1);
    (s.width, s.height) = (8, 8);
    let mut film = new_film(&s, 0..4);
    render_stopping(&l, &s, &mut film, None, None);
    assert!(
        film.variance_image().is_none(),
        "BDPT splats: no variance image"
    );
}

/// The background is a light to every physically based method: a uniform infinite light,
/// sampled for direct light, emitting light paths and photons, hit by rays that leave. A
/// diffuse sphere resting on a diffuse floor under a sky of radiance (0.6, 0.7, 0.9), the
/// sky not in view (light tracing cannot see it directly): every method's image mean within
/// 2 % of a 4096-spp BDPT render's, per channel (photon mapping 3 %, its documented bias;
/// RGB, seed 7; 24×24 pixels; path and light tracing 1024 spp, SPPM 256 iterations, photon
/// mapping 64 spp). Before, light paths and photons never started from the sky: light
/// tracing rendered black, photon mapping and SPPM lost the sky's light after a bounce.
#[test]
fn the_background_lights_every_method_alike() {
    let l = scene(
        r#"
background = [0.6, 0.7, 0.9]
[render]
max_depth = 5
[camera]
position = [0, 2.5, 2.5]
look_at = [0, 0.3, 0]
fov = 30
resolution = [24, 24]
[materials.floor]
type = "diffuse"
reflectance = [0.7, 0.6, 0.5]
[materials.ball]
type = "diffuse"
reflectance = [0.5, 0.7, 0.6]
[[objects]]
type = "polygon"
material = "floor"
vertices = [[-6, 0, -6], [-6, 0, 6], [6, 0, 6], [6, 0, -6]]
[[objects]]
type = "sphere"
center = [0, 0.5, 0]
radius = 0.5
material = "ball"
"#,
    );
    let reference = mean(&draw(
        &l,
        &settings_for(&l, IntegratorKind::Bdpt, 4096, ColorMode::Rgb, 7),
    ));
    // Photon mapping within its documented bias (light blurred into the contact shadow).
    for (kind, spp, tolerance) in [
        (IntegratorKind::Path, 1024, 0.02),
        (IntegratorKind::Light, 1024, 0.02),
        (IntegratorKind::Photon, 64, 0.03),
        (IntegratorKind::Sppm, 256, 0.02),
    ] {
        let m = mean(&draw(&l, &settings_for(&l, kind, spp, ColorMode::Rgb, 7)));
        assert_mean_within(kind.name(), m, "BDPT's", reference, tolerance);
    }
}

/// Phong glass (glossy and refracting) and a Phong mirror with a highlight, over a floor
/// under a sky: photon mapping (64 spp, its default maps) within 4 % of a 2048-spp path
/// trace, per channel, and SPPM (4096 iterations of 4000 photons) within 2 % (RGB, seed 7;
/// 24×24 pixels; measured +0.1 % and +0.5 % at worst). Before, both methods stopped the
/// eye path at the first surface with a diffuse or glossy lobe and lost the specular lobes
/// there: −22 % and −27 %.
#[test]
fn phong_glass_and_mirrors_are_read_alike_by_every_method() {
    let l = scene(
        r#"
background = [0.6, 0.7, 0.9]
[render]
max_depth = 5
[camera]
position = [0, 1.2, 4]
look_at = [0, 0.7, 0]
fov = 35
resolution = [24, 24]
[materials.floor]
type = "diffuse"
reflectance = [0.7, 0.6, 0.5]
[materials.glass]
diffuse = 0.0
specular = 0.6
shininess = 200
transmissive = 0.95
ior = 1.5
fresnel = true
[materials.mirror]
diffuse = [0.05, 0.05, 0.06]
specular = 0.5
shininess = 120
reflective = 0.85
[[objects]]
type = "polygon"
material = "floor"
vertices = [[-6, 0, -6], [-6, 0, 6], [6, 0, 6], [6, 0, -6]]
[[objects]]
type = "sphere"
center = [0.55, 0.6, 0]
radius = 0.6
material = "glass"
[[objects]]
type = "sphere"
center = [-0.6, 0.6, -0.6]
radius = 0.6
material = "mirror"
"#,
    );
    let reference = mean(&draw(
        &l,
        &settings_for(&l, IntegratorKind::Path, 2048, ColorMode::Rgb, 7),
    ));
    let photon = settings_for(&l, IntegratorKind::Photon, 64, ColorMode::Rgb, 7);
    let mut sppm = settings_for(&l, IntegratorKind::Sppm, 4096, ColorMode::Rgb, 7);
    sppm.integrator.photon.sppm_photons = 4000;
    for (settings, tolerance) in [(photon, 0.04), (sppm, 0.02)] {
        let m = mean(&draw(&l, &settings));
        let what = settings.integrator.kind.name();
        assert_mean_within(what, m, "the path tracer's", reference, tolerance);
    }
}
