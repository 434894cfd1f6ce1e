//! Rendered images checked against values computed by hand from the closed forms.

use plenum_core::camera::Camera;
use plenum_core::integrator::IntegratorConfig;
use plenum_core::render::{render, RenderSettings};
use plenum_core::sampling::PixelSampler;
use plenum_core::{Color, Vec3};
use plenum_scene::{builtin_scene, parse_scene, LoadedScene};
use std::path::Path;
use std::sync::atomic::AtomicBool;

fn scene(text: &str) -> LoadedScene {
    parse_scene(Path::new("test.toml"), text, Path::new(".")).unwrap_or_else(|e| panic!("{e}"))
}

fn draw(loaded: &LoadedScene, spp: u32) -> plenum_core::film::Film {
    let settings = RenderSettings {
        width: loaded.defaults.width,
        height: loaded.defaults.height,
        sampler: PixelSampler::grid_for(spp),
        integrator: IntegratorConfig::default(),
        seed: 1,
        corners: false,
        ..Default::default()
    };
    render(
        &loaded.scene,
        &settings,
        &AtomicBool::new(false),
        &|_, _| {},
    )
    .film
}

fn close(a: Color, b: Color, tol: f64) -> bool {
    (a.r - b.r).abs() <= tol && (a.g - b.g).abs() <= tol && (a.b - b.b).abs() <= tol
}

const DIFFUSE_SPHERE: &str = r#"
[camera]
position = [0, 0, 0]
look_at = [0, 0, -1]
fov = 40
resolution = [64, 48]
[materials.matte]
diffuse = [0.8, 0.6, 0.4]
[[lights]]
type = "point"
position = [4, 5, 2]
intensity = 1.5
attenuation = [0, 0, 1]
[[objects]]
type = "sphere"
center = [0, 0, -5]
radius = 1.5
material = "matte"
"#;

/// Every pixel of a diffuse sphere under one point light with inverse-square falloff:
/// k_d · I · max(0, N·L) / d², from the analytic ray–sphere hit.
#[test]
fn diffuse_sphere_matches_lambert_and_inverse_square() {
    let loaded = scene(DIFFUSE_SPHERE);
    let film = draw(&loaded, 1);
    let cam = Camera::new(&loaded.scene.camera, 64, 48);
    let (centre, radius) = (Vec3::new(0.0, 0.0, -5.0), 1.5);
    let light = Vec3::new(4.0, 5.0, 2.0);
    let kd = Color::new(0.8, 0.6, 0.4);
    let mut lit = 0;
    for y in 0..48 {
        for x in 0..64 {
            let ray = cam.ray(x as f64 + 0.5, y as f64 + 0.5);
            let d = ray.direction;
            let b = d.dot(ray.origin - centre);
            let c = (ray.origin - centre).length_squared() - radius * radius;
            let disc = b * b - c;
            let expected = if disc < 0.0 {
                Color::BLACK
            } else {
                let p = ray.origin + d * (-b - disc.sqrt());
                let n = (p - centre) / radius;
                let to_light = light - p;
                let dist = to_light.length();
                let cos = n.dot(to_light / dist).max(0.0);
                if cos > 0.0 {
                    lit += 1;
                }
                kd * (1.5 * cos * (1.0 / (dist * dist)).min(1.0))
            };
            let got = film.get(x, y);
            assert!(
                close(got, expected, 1e-5),
                "pixel ({x}, {y}): {got:?} vs {expected:?}"
            );
        }
    }
    assert!(lit > 200, "the test must see a lit sphere");
}

/// A tilted mirror shows an emissive wall: the pixel is k_r times the wall's colour.
#[test]
fn mirror_reflects_a_known_colour() {
    let loaded = scene(
        r#"
[camera]
position = [0, 0, 0]
look_at = [0, 0, -1]
fov = 30
resolution = [16, 16]
[materials.mirror]
diffuse = 0
reflective = 0.9
[materials.wall]
diffuse = 0
emissive = [0.2, 0.5, 0.7]
[[objects]]
type = "plane"
point = [0, 0, -5]
normal = [0, 1, 1]
material = "mirror"
[[objects]]
type = "plane"
point = [0, 10, 0]
normal = [0, -1, 0]
material = "wall"
"#,
    );
    let film = draw(&loaded, 1);
    for y in 0..16 {
        for x in 0..16 {
            let want = Color::new(0.2, 0.5, 0.7) * 0.9;
            assert!(
                close(film.get(x, y), want, 1e-6),
                "({x}, {y}): {:?}",
                film.get(x, y)
            );
        }
    }
}

/// Brightness-weighted column of an emissive vertical line in the middle row.
fn line_centre(film: &plenum_core::film::Film) -> f64 {
    let y = film.height / 2;
    let (mut sum, mut weighted) = (0.0, 0.0);
    for x in 0..film.width {
        let v = film.get(x, y).g;
        sum += v;
        weighted += v * (x as f64 + 0.5);
    }
    assert!(sum > 0.5, "the line must be visible");
    weighted / sum
}

/// A glass slab of thickness T tilted by θ shifts a line seen through it sideways by
/// T·sin(θ − θ_t)/cos θ_t, with sin θ = η sin θ_t (Snell's law).
#[test]
fn glass_slab_shifts_a_line_as_snell_predicts() {
    let base = r#"
background = 0
[camera]
position = [0, 0, 100]
look_at = [0, 0, 0]
fov = 2
resolution = [400, 21]
[materials.light]
diffuse = 0
emissive = 1
[materials.glass]
diffuse = 0
transmissive = 1
ior = 1.5
[[objects]]
type = "polygon"
material = "light"
vertices = [[-0.1, -20, 0], [0.1, -20, 0], [0.1, 20, 0], [-0.1, 20, 0]]
"#;
    let slab = r#"
[[objects]]
type = "box"
material = "glass"
min = [-30, -30, -1]
max = [30, 30, 1]
transform = [{ rotate = { axis = [0, 1, 0], degrees = 30 } }, { translate = [0, 0, 20] }]
"#;
    let plain = draw(&scene(base), 16);
    let through = draw(&scene(&format!("{base}{slab}")), 16);
    // Width of the view at the line's distance, per pixel.
    let half_height = 100.0 * (1f64.to_radians()).tan();
    let pixel = 2.0 * half_height * (400.0 / 21.0) / 400.0;
    let shift = (line_centre(&through) - line_centre(&plain)).abs() * pixel;
    let theta = 30f64.to_radians();
    let theta_t = (theta.sin() / 1.5).asin();
    let expected = 2.0 * (theta - theta_t).sin() / theta_t.cos();
    // Rays off the axis meet the slab up to 0.3° off θ: allow 2% (about 0.1 pixel).
    assert!(
        (shift - expected).abs() < 0.02 * expected,
        "shift {shift} vs Snell {expected}"
    );
}

const SHADOW_SCENE: &str = r#"
background = 0
[camera]
position = [3, 10, 0]
look_at = [3, 0, 0]
up = [0, 0, -1]
fov = 30
resolution = [9, 9]
[materials.floor]
diffuse = 0.5
[materials.green_glass]
diffuse = 0
transmissive = [0.2, 0.8, 0.2]
ior = 1.5
[materials.textured_glass]
diffuse = 0
transmissive = { texture = "checker3d", even = [0.2, 0.8, 0.2], odd = [0.2, 0.8, 0.2] }
ior = 1.5
[materials.opaque]
diffuse = 0.5
[[lights]]
type = "point"
position = [13, 10, 0]
[[objects]]
type = "plane"
normal = [0, 1, 0]
material = "floor"
"#;

/// The floor point under the centre pixel sees the light through green glass: its colour is
/// k_d · cos θ · k_t. An opaque ball there gives a black shadow; two glass balls, k_t².
/// k_t is read from the material where it is uniform and looked up at the hit where it is
/// a texture: both give the same colour.
#[test]
fn shadows_through_glass_are_coloured_by_k_t() {
    let cos = 0.5f64.sqrt();
    let ball = |at: &str, m: &str| {
        format!("[[objects]]\ntype = \"sphere\"\ncenter = {at}\nradius = 1\nmaterial = \"{m}\"\n")
    };
    let open = draw(&scene(SHADOW_SCENE), 1).get(4, 4);
    assert!(close(open, Color::gray(0.5 * cos), 1e-6), "{open:?}");
    let glass = draw(
        &scene(&format!(
            "{SHADOW_SCENE}{}",
            ball("[8, 5, 0]", "green_glass")
        )),
        1,
    )
    .get(4, 4);
    assert!(
        close(glass, Color::new(0.2, 0.8, 0.2) * (0.5 * cos), 1e-6),
        "{glass:?}"
    );
    let textured = draw(
        &scene(&format!(
            "{SHADOW_SCENE}{}",
            ball("[8, 5, 0]", "textured_glass")
        )),
        1,
    )
    .get(4, 4);
    assert_eq!(textured, glass);
    let two = format!(
        "{SHADOW_SCENE}{}{}",
        ball("[8, 5, 0]", "green_glass"),
        ball("[10.5, 7.5, 0]", "green_glass")
    );
    let twice = draw(&scene(&two), 1).get(4, 4);
    assert!(
        close(twice, Color::new(0.04, 0.64, 0.04) * (0.5 * cos), 1e-6),
        "{twice:?}"
    );
    let opaque = draw(
        &scene(&format!("{SHADOW_SCENE}{}", ball("[8, 5, 0]", "opaque"))),
        1,
    )
    .get(4, 4);
    assert_eq!(opaque, Color::BLACK);
}

/// The same image, bit for bit, with 1, 2 and 3 threads, with random sample positions
/// (jittered sampling draws from each sample's own generator).
#[test]
fn image_does_not_depend_on_thread_count() {
    let loaded = builtin_scene();
    let settings = RenderSettings {
        width: 96,
        height: 72,
        sampler: PixelSampler::new(plenum_core::sampling::SamplerKind::Jittered, 4),
        integrator: IntegratorConfig::default(),
        seed: 42,
        corners: false,
        ..Default::default()
    };
    let films = films_with_threads(&loaded, &settings, &[1, 2, 3]);
    assert!(
        films[0].iter().any(|p| p[0] > 0.1),
        "the image must not be black"
    );
    assert_eq!(films[0], films[1]);
    assert_eq!(films[0], films[2]);
}

/// The image rendered with each thread count.
fn films_with_threads(
    loaded: &LoadedScene,
    settings: &RenderSettings,
    threads: &[usize],
) -> Vec<Vec<[f32; 3]>> {
    threads
        .iter()
        .map(|&n| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .unwrap();
            pool.install(|| {
                render(&loaded.scene, settings, &AtomicBool::new(false), &|_, _| {})
                    .film
                    .pixels()
                    .to_vec()
            })
        })
        .collect()
}

/// Every example scene of a distribution effect gives the same image, bit for bit, with 1
/// and 3 threads: with a fixed-count sampler and a filter with negative lobes, and with
/// both adaptive modes (whose second pass reads the first pass's neighbours).
#[test]
fn distribution_effects_do_not_depend_on_thread_count() {
    use plenum_core::render::Adaptive;
    use plenum_core::sampling::{Filter, FilterKind, SamplerKind};
    for name in ["soft-shadows", "depth-of-field", "motion-blur", "glossy"] {
        let loaded = plenum_scene::load_scene(Path::new(&format!("../../scenes/{name}.toml")))
            .unwrap_or_else(|e| panic!("{e}"));
        let base = RenderSettings {
            width: 40,
            height: 30,
            sampler: PixelSampler::new(SamplerKind::Jittered, 4),
            filter: Filter::new(FilterKind::Mitchell, 2.0).unwrap(),
            seed: 8,
            ..Default::default()
        };
        for adaptive in [
            None,
            Some(Adaptive::Variance {
                threshold: 0.05,
                min_spp: 4,
                max_spp: 16,
            }),
            Some(Adaptive::Subdivide {
                contrast: 0.1,
                depth: 2,
            }),
        ] {
            let settings = RenderSettings {
                adaptive,
                ..base.clone()
            };
            let films = films_with_threads(&loaded, &settings, &[1, 3]);
            assert!(films[0] == films[1], "{name}, {adaptive:?}");
            assert!(films[0].iter().flatten().all(|v| v.is_finite()));
        }
    }
}
