//! The path tracer against closed forms and an independent renderer: pbrt-v4's analytic
//! furnace scenes (every pixel's radiance is 1), dispersion through a prism against Snell's
//! law, Mitsuba 3's converged Cornell box by a per-pixel z-test, and the same image for any
//! thread count.

use plenum_core::bxdf::TransportMode;
use plenum_core::integrator::{ColorMode, IntegratorKind};
use plenum_core::math::Ray;
use plenum_core::render::{render, RenderSettings};
use plenum_core::Vec3;
use plenum_scene::LoadedScene;
use plenum_spectrum::SampledWavelengths;
use std::sync::atomic::AtomicBool;

mod common;
use common::integrators::*;

/// L = ρ/π·E + ρ·L with E = I/r² = π from the point light(s), or L = L_e + ρ·L for an
/// emitting sphere: both give L = 1. At 256 spp the image mean must be within ±0.01
/// (Russian roulette, unbiased; the standard error of the mean here is below 0.003).
#[test]
fn furnace_scenes_converge_to_radiance_one() {
    for (what, light, emission) in furnace_cases() {
        let l = scene(&furnace(&light, &emission));
        for color in [ColorMode::Rgb, ColorMode::Spectral] {
            let m = mean(&draw(&l, &path_settings(&l, 256, color, 3)));
            for (c, v) in m.iter().enumerate() {
                assert!(
                    (v - 1.0).abs() <= 0.01,
                    "{what}, {color:?}: channel {c} has mean {v}, expected 1 ± 0.01"
                );
            }
        }
    }
}

/// Dense flint glass (N-SF5-class, Sellmeier) as a 60° prism: a ray of each wavelength
/// refracted in and out through the material's BSDF leaves at the angle that Snell's law and
/// the glass's dispersion formula give (to 10⁻⁷ rad: the faces' normals are rounded), and
/// only the hero wavelength goes on.
#[test]
fn a_prism_disperses_by_snells_law() {
    let l = scene(
        r#"
[camera]
position = [0, 0, 10]
look_at = [0, 0, 0]

[materials.flint]
type = "dielectric"
eta = "dense-flint"

[[objects]]
type = "polyhedron"
material = "flint"
vertices = [[-1, -0.57735027, -1], [1, -0.57735027, -1], [0, 1.15470054, -1],
            [-1, -0.57735027, 1], [1, -0.57735027, 1], [0, 1.15470054, 1]]
faces = [[0, 2, 1], [3, 4, 5], [0, 1, 4, 3], [1, 2, 5, 4], [2, 0, 3, 5]]
"#,
    );
    let s = &l.scene;
    let eta = plenum_spectrum::named("dense-flint").expect("dense flint is named");
    // The beam meets the left face at 50° from its normal, in the plane z = 0.
    let left_normal = Vec3::new(-0.8660254037844386, 0.5, 0.0);
    let incidence = 50f64.to_radians();
    let into = -left_normal;
    let tangent = Vec3::new(0.5, 0.8660254037844386, 0.0);
    let d0 = (into * incidence.cos() + tangent * incidence.sin()).normalized();
    let mut exits = Vec::new();
    for lambda in [450.0, 550.0, 650.0] {
        let mut wl = SampledWavelengths::from_parts(
            [lambda, lambda + 100.0, lambda + 200.0, lambda + 300.0],
            [1.0; 4],
        );
        let mut ray = Ray::new(Vec3::new(-0.5, 0.2886751345948129, 0.0) - d0 * 2.0, d0);
        for interface in 0..2 {
            let (prim, hit) = s
                .geometry
                .intersect(&ray, f64::INFINITY)
                .expect("the beam meets the prism");
            let it = s.geometry.interaction(&ray, prim, &hit);
            let wo = -ray.direction.normalized();
            let bsdf = s.bsdf(&it, wo, &mut wl).expect("glass scatters");
            // u close to 1 chooses transmission (reflection takes u < R/(R+T)).
            let bs = bsdf
                .sample_f(wo, 0.999_999, [0.5, 0.5], TransportMode::Radiance)
                .expect("the beam is transmitted");
            assert!(bs.is_transmission(), "interface {interface} at {lambda} nm");
            let origin = plenum_core::math::offset_ray_origin(it.p, it.p_error, it.n, bs.wi);
            ray = Ray::new(origin, bs.wi);
        }
        assert!(
            wl.secondary_terminated(),
            "dispersion keeps only the hero wavelength"
        );
        // Snell twice: in at 50° on the left face, out through the right face (apex 60°).
        let n = eta.eval(lambda);
        let inside = (incidence.sin() / n).asin();
        let at_exit = 60f64.to_radians() - inside;
        let out = (n * at_exit.sin()).asin();
        let right_normal = Vec3::new(0.8660254037844386, 0.5, 0.0);
        let got = ray.direction.normalized().dot(right_normal).acos();
        assert!(
            (got - out).abs() < 1e-7,
            "{lambda} nm: left the prism at {:.9}°, Snell's law gives {:.9}°",
            got.to_degrees(),
            out.to_degrees()
        );
        exits.push(got);
    }
    // Blue bends most.
    assert!(exits[0] > exits[1] && exits[1] > exits[2], "{exits:?}");
}

#[test]
#[ignore = "full suite (cargo test -- --include-ignored): over 10 s"]
fn cornell_box_matches_mitsuba_in_rgb() {
    cbox_z_test(
        IntegratorKind::Path,
        ColorMode::Rgb,
        "reference.exr",
        "reference-variance.exr",
    );
}

#[test]
#[ignore = "full suite (cargo test -- --include-ignored): over 10 s"]
fn cornell_box_matches_mitsuba_spectrally() {
    cbox_z_test(
        IntegratorKind::Path,
        ColorMode::Spectral,
        "reference-spectral.exr",
        "reference-spectral-variance.exr",
    );
}

/// The same path-traced image, bit for bit, with 1 and 2 threads, in both colour modes.
#[test]
fn path_traced_image_does_not_depend_on_thread_count() {
    let l = scene(&furnace(
        "[[lights]]\ntype = \"point\"\nposition = [0.2, 0.1, 0]\nintensity = 3",
        "",
    ));
    for color in [ColorMode::Rgb, ColorMode::Spectral] {
        let settings = path_settings(&l, 4, color, 9);
        let films: Vec<Vec<[f32; 3]>> = [1, 2]
            .iter()
            .map(|&n| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build()
                    .unwrap()
                    .install(|| draw(&l, &settings))
            })
            .collect();
        assert_eq!(films[0], films[1], "{color:?}");
    }
}

/// Every Whitted scene also renders under the path tracer, its Phong materials read as a
/// normalised BSDF: the built-in scene gives a finite, lit image.
#[test]
fn phong_scenes_render_under_the_path_tracer() {
    let mut l = plenum_scene::builtin_scene();
    l.defaults.width = 32;
    l.defaults.height = 24;
    for color in [ColorMode::Rgb, ColorMode::Spectral] {
        let pixels = draw(&l, &path_settings(&l, 4, color, 5));
        let m = mean(&pixels);
        assert!(
            m.iter().all(|v| v.is_finite() && *v > 0.01),
            "{color:?}: mean {m:?}"
        );
    }
}

/// Under a uniform sky of radiance 1 a convex diffuse object of reflectance 0.5 has
/// radiance 0.5 everywhere (E = π·L, and nothing shadows it), and the sky shows 1: for a
/// constant infinite light and for an environment image of 1s in both layouts, sampled by
/// importance and by the BSDF with MIS (±0.015 on the mean of the pixels within 3 of the
/// centre at 256 spp, about four standard errors).
#[test]
fn a_diffuse_sphere_under_a_uniform_sky() {
    let dir = tempfile::tempdir().unwrap();
    let sky = dir.path().join("sky.pfm");
    plenum_image::write_image(&sky, 16, 16, &vec![[1.0f32; 3]; 256], 0.0).unwrap();
    let lights = [
        "[[lights]]\ntype = \"infinite\"\ncolor = [1, 1, 1]".to_string(),
        format!(
            "[[lights]]\ntype = \"infinite\"\nfile = {:?}\nlayout = \"latlong\"",
            sky.display().to_string()
        ),
        format!(
            "[[lights]]\ntype = \"infinite\"\nfile = {:?}\nlayout = \"equalarea\"\nup = [0, 0, 1]",
            sky.display().to_string()
        ),
    ];
    for light in lights {
        let l = scene(&format!(
            r#"
[render]
max_depth = 3
[camera]
position = [0, 0, 5]
look_at = [0, 0, 0]
fov = 20
resolution = [16, 16]
[materials.half]
type = "diffuse"
reflectance = 0.5
[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 0.5
material = "half"
{light}
"#
        ));
        for color in [ColorMode::Rgb, ColorMode::Spectral] {
            let px = draw(&l, &path_settings(&l, 256, color, 11));
            let centre: Vec<[f32; 3]> = (0..256)
                .filter(|i| {
                    let (x, y) = ((i % 16) as f64 - 7.5, (i / 16) as f64 - 7.5);
                    x * x + y * y <= 9.0
                })
                .map(|i| px[i])
                .collect();
            let corner: Vec<[f32; 3]> = [0, 15, 240, 255].iter().map(|&i| px[i]).collect();
            for (what, got, want) in [("sphere", mean(&centre), 0.5), ("sky", mean(&corner), 1.0)] {
                for v in got {
                    assert!(
                        (v - want).abs() <= 0.015,
                        "{light}, {color:?}: {what} {got:?}, expected {want}"
                    );
                }
            }
        }
    }
}

/// An RGB emitter seen directly renders as its own RGB value in both colour modes (the
/// illuminant uplift times D65 of unit luminance, integrated against the CIE observer,
/// within 1 % spectrally; exactly in RGB), and a scene of physically based materials only
/// is path traced unless told otherwise.
#[test]
fn an_rgb_emitter_seen_directly_shows_its_rgb() {
    let l = scene(
        r#"
[camera]
position = [0, 0, 3]
look_at = [0, 0, 0]
fov = 20
resolution = [8, 8]

[materials.black]
type = "diffuse"
reflectance = 0

[[objects]]
type = "mesh"
material = "black"
positions = [[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]]
indices = [[0, 1, 2], [0, 2, 3]]
emission = [17, 12, 4]
two_sided = false
"#,
    );
    assert_eq!(IntegratorKind::default_for(&l.scene), IntegratorKind::Path);
    for (color, tolerance) in [(ColorMode::Rgb, 1e-6), (ColorMode::Spectral, 0.01)] {
        let m = mean(&draw(&l, &path_settings(&l, 64, color, 2)));
        for (got, want) in m.iter().zip([17.0, 12.0, 4.0]) {
            assert!(
                (got / want - 1.0).abs() <= tolerance,
                "{color:?}: {m:?}, expected (17, 12, 4)"
            );
        }
    }
    assert_eq!(
        IntegratorKind::default_for(&plenum_scene::builtin_scene().scene),
        IntegratorKind::Whitted
    );
}

/// A mix of reflectances 0.3 and 0.7 half and half is, on average, reflectance 0.5: in the
/// furnace sphere lit by its own emission 0.5 it converges to radiance 1 (±0.01). Made
/// one-sided, the sphere seen from inside is black but for its emission, 0.5.
#[test]
fn mixes_average_and_one_sided_surfaces_are_black_behind() {
    let mix = r#"
[materials.dark]
type = "diffuse"
reflectance = 0.3
[materials.bright]
type = "diffuse"
reflectance = 0.7
[materials.half]
type = "mix"
materials = ["dark", "bright"]
amount = 0.5
"#;
    let text = furnace("", "emission = [0.5, 0.5, 0.5]").replace(
        "[materials.half]\ntype = \"diffuse\"\nreflectance = 0.5\n",
        mix,
    );
    let l = scene(&text);
    let m = mean(&draw(&l, &path_settings(&l, 256, ColorMode::Rgb, 4)));
    assert!(m.iter().all(|v| (v - 1.0).abs() <= 0.01), "mix: {m:?}");

    let one_sided = furnace("", "emission = [0.5, 0.5, 0.5]").replace(
        "type = \"diffuse\"\nreflectance = 0.5\n",
        "type = \"diffuse\"\nreflectance = 0.5\ntwo_sided = false\n",
    );
    let l = scene(&one_sided);
    let m = mean(&draw(&l, &path_settings(&l, 16, ColorMode::Rgb, 4)));
    assert!(
        m.iter().all(|v| (v - 0.5).abs() <= 1e-6),
        "one-sided: {m:?}"
    );
}

/// A Phong material's k_e is radiance under the path tracer: a black Phong wall of
/// k_e = (0.3, 0.6, 0.9) seen head-on shows exactly that in RGB, and within 1 % spectrally.
#[test]
fn phong_emission_is_seen_by_the_path_tracer() {
    let l = scene(
        r#"
[camera]
position = [0, 0, 3]
look_at = [0, 0, 0]
fov = 20
resolution = [8, 8]

[materials.glow]
emissive = [0.3, 0.6, 0.9]
diffuse = 0

[[objects]]
type = "polygon"
material = "glow"
vertices = [[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]]
"#,
    );
    for (color, tolerance) in [(ColorMode::Rgb, 1e-6), (ColorMode::Spectral, 0.01)] {
        let m = mean(&draw(&l, &path_settings(&l, 64, color, 2)));
        for (got, want) in m.iter().zip([0.3, 0.6, 0.9]) {
            assert!((got / want - 1.0).abs() <= tolerance, "{color:?}: {m:?}");
        }
    }
}

/// Under Whitted a mix is the blend of its materials' coefficients: half of reflectance 0.3
/// and half of 0.7 renders as reflectance 0.5 does (to 1e-6).
#[test]
fn whitted_blends_a_mix() {
    let lit = |materials: &str| {
        scene(&format!(
            r#"
[camera]
position = [0, 0, 4]
look_at = [0, 0, 0]
resolution = [8, 8]
{materials}
[[objects]]
type = "sphere"
radius = 1
material = "m"
[[lights]]
type = "point"
position = [2, 3, 4]
"#
        ))
    };
    let mix = lit(
        "[materials.a]\ntype = \"diffuse\"\nreflectance = 0.3\n[materials.b]\ntype = \"diffuse\"\nreflectance = 0.7\n[materials.m]\ntype = \"mix\"\nmaterials = [\"a\", \"b\"]\n",
    );
    let half = lit("[materials.m]\ntype = \"diffuse\"\nreflectance = 0.5\n");
    let whitted = |l: &LoadedScene| {
        let settings = RenderSettings {
            width: 8,
            height: 8,
            ..Default::default()
        };
        render(&l.scene, &settings, &AtomicBool::new(false), &|_, _| {})
            .film
            .pixels()
            .to_vec()
    };
    let (a, b) = (whitted(&mix), whitted(&half));
    assert!(b.iter().flatten().any(|&v| v > 0.05), "the image is lit");
    for (p, q) in a.iter().zip(&b) {
        for c in 0..3 {
            assert!((p[c] - q[c]).abs() < 1e-6, "{p:?} vs {q:?}");
        }
    }
}

/// A one-sided emitter's light leaves the side that a ray hitting it sees as its front:
/// a concave polygon under a mirroring transform, a polyhedron mirrored, and a mesh whose
/// vertex normals oppose its winding. Each point the light samples, approached along the
/// normal it was sampled with, is hit on the face whose normal is that one; and the
/// concave polygon's sampled points all lie on it (its emitter's area is its own, 3).
#[test]
fn one_sided_emitters_agree_on_their_side() {
    use plenum_core::light::Light;
    use plenum_core::math::Ray;
    let l = plenum_scene::parse_scene(
        std::path::Path::new("sides.toml"),
        r#"
[camera]
position = [0, 0, 10]
look_at = [0, 0, 0]

[[objects]]
type = "polygon"
vertices = [[2, 1, 0], [1, 1, 0], [1, 2, 0], [0, 2, 0], [0, 0, 0], [2, 0, 0]]
emission = [1, 1, 1]
two_sided = false
transform = [{ scale = [-1, 1, 1] }, { rotate = { axis = [1, 1, 0], degrees = 30 } }]

[[objects]]
type = "polyhedron"
vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
emission = [1, 1, 1]
two_sided = false
transform = [{ scale = [1, -1, 1] }, { translate = [4, 0, 0] }]

[[objects]]
type = "mesh"
positions = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
indices = [[0, 1, 2]]
normals = [[0, 0, -1], [0, 0, -1], [0, 0, -1]]
emission = [1, 1, 1]
two_sided = false
transform = [{ translate = [-4, 0, 0] }]
"#,
        std::path::Path::new("."),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let s = &l.scene;
    let mut checked = 0;
    for (i, light) in s.lights.iter().enumerate() {
        let Light::Area {
            shape, two_sided, ..
        } = light
        else {
            continue;
        };
        assert!(!two_sided);
        if i == 0 {
            assert!(
                (shape.area() - 3.0).abs() < 1e-9,
                "L-shaped polygon area {}",
                shape.area()
            );
        }
        for j in 0..64 {
            let u = [(j % 8) as f64 / 8.0 + 0.0625, (j / 8) as f64 / 8.0 + 0.0625];
            let (p, n) = shape.sample_area(u).unwrap();
            let ray = Ray::new(p + n * 0.01, -n);
            let (prim, hit) = s
                .geometry
                .intersect(&ray, 0.02)
                .unwrap_or_else(|| panic!("light {i}: sampled point {p:?} is not on the surface"));
            assert_eq!(s.area_light(prim), Some(i as u32), "light {i}");
            let it = s.geometry.interaction(&ray, prim, &hit);
            assert!(
                it.n.dot(n) > 0.999,
                "light {i}: sampled normal {n:?}, hit normal {:?}",
                it.n
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 3 * 64);
}
