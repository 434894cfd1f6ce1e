//! What the integrators' tests share: scenes, settings, pbrt-v4's analytic furnace, and
//! Mitsuba 3's per-pixel image test against the Cornell box reference.
#![allow(dead_code)]

use plenum_core::integrator::{ColorMode, IntegratorConfig, IntegratorKind};
use plenum_core::render::{render, RenderOutput, RenderSettings};
use plenum_core::sampling::{PixelSampler, SamplerKind};
use plenum_scene::{load_scene, parse_scene, LoadedScene};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

pub fn scene(text: &str) -> LoadedScene {
    parse_scene(Path::new("test.toml"), text, Path::new(".")).unwrap_or_else(|e| panic!("{e}"))
}

/// Settings for rendering `l` with `kind` at `spp` random samples per pixel.
pub fn settings_for(
    l: &LoadedScene,
    kind: IntegratorKind,
    spp: u32,
    color: ColorMode,
    seed: u64,
) -> RenderSettings {
    RenderSettings {
        width: l.defaults.width,
        height: l.defaults.height,
        sampler: PixelSampler::new(SamplerKind::Random, spp),
        integrator: IntegratorConfig {
            kind,
            max_depth: l.defaults.max_depth,
            rr_depth: l.defaults.rr_depth,
            color,
            ..Default::default()
        },
        seed,
        ..Default::default()
    }
}

pub fn path_settings(l: &LoadedScene, spp: u32, color: ColorMode, seed: u64) -> RenderSettings {
    settings_for(l, IntegratorKind::Path, spp, color, seed)
}

/// Renders `l`; no sample may come out NaN or infinite.
pub fn render_checked(l: &LoadedScene, settings: &RenderSettings) -> RenderOutput {
    let out = render(&l.scene, settings, &AtomicBool::new(false), &|_, _| {});
    assert_eq!(
        out.counts.invalid, 0,
        "no sample may come out NaN or infinite"
    );
    out
}

pub fn draw(l: &LoadedScene, settings: &RenderSettings) -> Vec<[f32; 3]> {
    render_checked(l, settings).film.pixels().to_vec()
}

/// Asserts that each channel of the image mean `m` is within `tolerance` (relative) of
/// `reference`'s, naming `what` and the reference's name `against` where it is not.
pub fn assert_mean_within(
    what: &str,
    m: [f64; 3],
    against: &str,
    reference: [f64; 3],
    tolerance: f64,
) {
    for c in 0..3 {
        let rel = m[c] / reference[c] - 1.0;
        assert!(
            rel.abs() < tolerance,
            "{what}: channel {c} {:.4} against {against} {:.4} ({:+.2} %)",
            m[c],
            reference[c],
            100.0 * rel
        );
    }
}

pub fn mean(pixels: &[[f32; 3]]) -> [f64; 3] {
    let mut m = [0.0; 3];
    for p in pixels {
        for c in 0..3 {
            m[c] += p[c] as f64;
        }
    }
    m.map(|v| v / pixels.len() as f64)
}

/// pbrt-v4's three furnaces, as (what, light, sphere emission) for [`furnace`]: a central
/// point light of intensity π, four of π/4 close by, or the sphere's own emission 0.5. In each
/// the radiance everywhere is 1: L = ρ/π·E + ρ·L with E = I/r² = π, or L = L_e + ρ·L.
pub fn furnace_cases() -> Vec<(&'static str, String, String)> {
    let pi = std::f64::consts::PI;
    let point = |p: [f64; 3], i: f64| {
        format!("[[lights]]\ntype = \"point\"\nposition = {p:?}\nintensity = {i}\n")
    };
    let four: String = [
        [0.1, 0.0, 0.0],
        [-0.1, 0.0, 0.0],
        [0.0, 0.1, 0.0],
        [0.0, -0.1, 0.0],
    ]
    .into_iter()
    .map(|p| point(p, pi / 4.0))
    .collect();
    vec![
        (
            "a central point light of intensity π",
            point([0.0; 3], pi),
            String::new(),
        ),
        ("four point lights of intensity π/4", four, String::new()),
        (
            "the sphere's own emission 0.5",
            String::new(),
            "emission = [0.5, 0.5, 0.5]".into(),
        ),
    ]
}

/// The camera inside a sphere of radius 1 and reflectance 0.5: pbrt-v4's analytic scenes.
pub fn furnace(light: &str, sphere_emission: &str) -> String {
    format!(
        r#"
[render]
max_depth = 100
rr_depth = 5

[camera]
position = [0, 0, 0]
look_at = [0, 0, -1]
fov = 90
resolution = [12, 12]

[materials.half]
type = "diffuse"
reflectance = 0.5

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 1
material = "half"
{sphere_emission}

{light}
"#
    )
}

pub fn cbox_reference(file: &str) -> Option<PathBuf> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/references/cbox")
        .join(file);
    if !p.exists() {
        super::missing(&format!("../shared/data/references/cbox/{file}"));
        return None;
    }
    Some(p)
}

pub fn read_exr(p: &Path) -> Vec<[f32; 3]> {
    plenum_image::read_float_image(p)
        .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
        .pixels
}

/// Mitsuba 3's image test on the Cornell box, rendered by `kind`: `renders` independent renders of `spp` samples
/// give each pixel channel a mean and the variance of that mean; z = |mean − ref| /
/// √(var + var_ref); a channel passes when 2(1 − Φ(z)) > α = 1 − 0.99^(1/N). At least 99.75 %
/// must pass, and the squared error must be what the two variances predict (its ratio to
/// them within 0.8–1.25).
pub fn cbox_z_test(kind: IntegratorKind, color: ColorMode, reference: &str, variance: &str) {
    cbox_z_test_with(kind, color, reference, variance, 16, |_| {});
}

/// [`cbox_z_test`] of renders at `spp` samples (iterations) per pixel, their settings
/// changed by `tweak`.
pub fn cbox_z_test_with(
    kind: IntegratorKind,
    color: ColorMode,
    reference: &str,
    variance: &str,
    spp: u32,
    tweak: impl Fn(&mut RenderSettings),
) {
    cbox_z_test_of(
        &load_cornell_box(),
        kind,
        color,
        reference,
        variance,
        spp,
        tweak,
    );
}

/// [`cbox_z_test_with`] of the Cornell box as another file describes it (another format).
pub fn cbox_z_test_of(
    l: &LoadedScene,
    kind: IntegratorKind,
    color: ColorMode,
    reference: &str,
    variance: &str,
    spp: u32,
    tweak: impl Fn(&mut RenderSettings),
) {
    let (Some(r), Some(v)) = (cbox_reference(reference), cbox_reference(variance)) else {
        return;
    };
    let (reference, ref_var) = (read_exr(&r), read_exr(&v));
    let renders = 16u64;
    let images: Vec<Vec<[f32; 3]>> = (0..renders)
        .map(|seed| {
            let mut s = settings_for(l, kind, spp, color, 1000 + seed);
            tweak(&mut s);
            draw(l, &s)
        })
        .collect();
    assert_eq!(images[0].len(), reference.len());
    let (mean, var) = mean_and_variance(&images);
    let (rate, ratio, z_max) = z_test(&mean, &var, &reference, &ref_var);
    eprintln!(
        "Cornell box, {}, {color:?}, {} spp: {:.4} % of pixel channels pass (z ≤ {z_max:.2}); squared error / predicted = {ratio:.3}",
        kind.name(),
        renders * spp as u64,
        100.0 * rate
    );
    assert!(rate >= 0.9975, "only {:.3} % passed", 100.0 * rate);
    assert!(
        (0.8..=1.25).contains(&ratio),
        "squared error is {ratio} × what noise predicts"
    );
    // The image mean within 4σ of the reference's, per channel, σ from both images'
    // per-pixel variances (pixels independent): a pass rate cannot see a small bias spread
    // over the whole image.
    let n = mean.len() as f64;
    for c in 0..3 {
        let ours = mean.iter().map(|p| p[c]).sum::<f64>() / n;
        let theirs = reference.iter().map(|p| p[c] as f64).sum::<f64>() / n;
        let variance = (var.iter().map(|p| p[c]).sum::<f64>()
            + ref_var.iter().map(|p| p[c] as f64).sum::<f64>())
            / (n * n);
        let z = (ours - theirs) / variance.sqrt();
        eprintln!(
            "  channel {c}: mean {ours:.5} against {theirs:.5} ({:+.3} %, z = {z:+.2})",
            100.0 * (ours / theirs - 1.0)
        );
        assert!(
            z.abs() <= 4.0,
            "channel {c}: the image mean is {z:.2} σ off"
        );
    }
}

/// Each pixel channel's mean over independent `images` and the variance of that mean.
pub fn mean_and_variance(images: &[Vec<[f32; 3]>]) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let k = images.len() as f64;
    let n = images[0].len();
    let mut mean = vec![[0.0; 3]; n];
    let mut var = vec![[0.0; 3]; n];
    for i in 0..n {
        for c in 0..3 {
            let m = images.iter().map(|im| im[i][c] as f64).sum::<f64>() / k;
            let v = images
                .iter()
                .map(|im| (im[i][c] as f64 - m).powi(2))
                .sum::<f64>();
            mean[i][c] = m;
            var[i][c] = v / ((k - 1.0) * k);
        }
    }
    (mean, var)
}

/// Mitsuba 3's per-pixel z-test of estimate `a` (variance `va`) against `b` (variance `vb`):
/// z = |a − b| / √(va + vb), a channel passing when 2(1 − Φ(z)) > α = 1 − 0.99^(1/N). Gives
/// the fraction that pass, the squared error over what the variances predict, and z's bound.
pub fn z_test<A: Copy + Into<f64>, B: Copy + Into<f64>>(
    a: &[[f64; 3]],
    va: &[[f64; 3]],
    b: &[[A; 3]],
    vb: &[[B; 3]],
) -> (f64, f64, f64) {
    let n = (a.len() * 3) as f64;
    let alpha = 1.0 - 0.99f64.powf(1.0 / n);
    let z_max = normal_quantile(1.0 - alpha / 2.0);
    let (mut pass, mut squared, mut predicted) = (0usize, 0.0, 0.0);
    for i in 0..a.len() {
        for c in 0..3 {
            let d = a[i][c] - b[i][c].into();
            let total = va[i][c] + vb[i][c].into();
            if total == 0.0 && d == 0.0 || d.abs() <= z_max * total.sqrt() {
                pass += 1;
            }
            squared += d * d;
            predicted += total;
        }
    }
    (pass as f64 / n, squared / predicted, z_max)
}

/// Φ⁻¹(p) by bisection on the complementary error function's series (erfc from
/// Numerical Recipes' Chebyshev fit, relative error < 1.2e-7).
pub fn normal_quantile(p: f64) -> f64 {
    let erfc = |x: f64| {
        let z = x.abs();
        let t = 1.0 / (1.0 + 0.5 * z);
        let r = t
            * (-z * z - 1.26551223
                + t * (1.00002368
                    + t * (0.37409196
                        + t * (0.09678418
                            + t * (-0.18628806
                                + t * (0.27886807
                                    + t * (-1.13520398
                                        + t * (1.48851587
                                            + t * (-0.82215223 + t * 0.17087277)))))))))
                .exp();
        if x >= 0.0 {
            r
        } else {
            2.0 - r
        }
    };
    let cdf = |x: f64| 1.0 - 0.5 * erfc(x / std::f64::consts::SQRT_2);
    let (mut lo, mut hi) = (-40.0, 40.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if cdf(mid) < p {
            lo = mid
        } else {
            hi = mid
        }
    }
    0.5 * (lo + hi)
}

/// scenes/cornell-box.toml, the box of the Mitsuba reference in the native format.
pub fn load_cornell_box() -> LoadedScene {
    let file = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.toml");
    load_scene(&file).unwrap_or_else(|e| panic!("{e}"))
}

/// A mesh of scenes/cornell-box.toml: its corners, triangles, reflectance and emission.
pub struct CornellMesh {
    pub name: String,
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
    pub reflectance: [f64; 3],
    pub emission: Option<[f64; 3]>,
}

/// The meshes of scenes/cornell-box.toml, read from the file as written: what the tests
/// write the box in other formats from.
pub fn cornell_meshes() -> Vec<CornellMesh> {
    let file = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.toml");
    let t: toml::Table = std::fs::read_to_string(file).unwrap().parse().unwrap();
    let num = |v: &toml::Value| {
        v.as_float()
            .unwrap_or_else(|| v.as_integer().unwrap() as f64)
    };
    let three = |v: &toml::Value| {
        let a = v.as_array().unwrap();
        [num(&a[0]), num(&a[1]), num(&a[2])]
    };
    t["objects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| CornellMesh {
            name: o["name"].as_str().unwrap().to_string(),
            positions: o["positions"]
                .as_array()
                .unwrap()
                .iter()
                .map(three)
                .collect(),
            triangles: o["indices"]
                .as_array()
                .unwrap()
                .iter()
                .map(|i| three(i).map(|x| x as u32))
                .collect(),
            reflectance: three(&t["materials"][o["material"].as_str().unwrap()]["reflectance"]),
            emission: o.get("emission").map(three),
        })
        .collect()
}
