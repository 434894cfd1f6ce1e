//! Area lights whose emission is a texture: every physically based method against Lambert's
//! closed form for the irradiance of a polygon, and against each other on a textured sphere.

use plenum_core::camera::Camera;
use plenum_core::integrator::{ColorMode, IntegratorKind};
use plenum_core::math::Vec3;

mod common;
use common::integrators::*;

/// The methods that converge to the physically based image.
const PHYSICAL: [IntegratorKind; 5] = [
    IntegratorKind::Path,
    IntegratorKind::Light,
    IntegratorKind::Bdpt,
    IntegratorKind::Photon,
    IntegratorKind::Sppm,
];

/// The checker's two radiances: x < 0 under `EVEN`, x > 0 under `ODD`.
const EVEN: [f64; 3] = [2.0, 0.5, 1.0];
const ODD: [f64; 3] = [0.5, 1.0, 3.0];
const ALBEDO: f64 = 0.5;
const SIZE: u32 = 12;

/// A square light at height 1 facing down onto a floor of reflectance 0.5, its (u, v) running
/// over x with v held below ½, so that a checker of two squares per unit splits it into two
/// halves at x = 0: swapping u and v, or turning either, would split it otherwise. The
/// camera looks down at the floor from the side, under the light.
fn floor_under_a_checker() -> String {
    let [e, o] = [EVEN, ODD];
    format!(
        r#"
[render]
max_depth = 3

[camera]
position = [0.3, -2.4, 0.5]
look_at = [0.3, -0.2, 0]
up = [0, 0, 1]
fov = 20
resolution = [{SIZE}, {SIZE}]

[materials.floor]
type = "diffuse"
reflectance = {ALBEDO}

[[objects]]
type = "mesh"
positions = [[-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]]
indices = [[0, 2, 1], [0, 3, 2]]
uvs = [[0, 0], [1, 0], [1, 0.4], [0, 0.4]]
emission = {{ texture = "checker", even = {e:?}, odd = {o:?}, scale = 2 }}
two_sided = false

[[objects]]
type = "plane"
point = [0, 0, 0]
normal = [0, 0, 1]
material = "floor"
"#
    )
}

/// The projected solid angle of the polygon `vertices` seen from `p` with unit normal `n`
/// (Lambert 1760): ½ Σ βₖ (n · γₖ), with βₖ the angle the edge k subtends and γₖ the unit
/// normal of the plane through p and the edge. The irradiance of a polygon of constant
/// radiance L is L times this.
fn projected_solid_angle(p: Vec3, n: Vec3, vertices: &[Vec3]) -> f64 {
    let k = vertices.len();
    let sum: f64 = (0..k)
        .map(|i| {
            let a = (vertices[i] - p).normalized();
            let b = (vertices[(i + 1) % k] - p).normalized();
            let beta = a.dot(b).clamp(-1.0, 1.0).acos();
            beta * n.dot(a.cross(b).normalized())
        })
        .sum();
    0.5 * sum.abs()
}

/// The floor's radiance at `p`: ρ/π times the irradiance of the two halves.
fn floor_radiance(p: Vec3) -> [f64; 3] {
    let half = |x0: f64, x1: f64| {
        let corners = [[x0, -1.0], [x1, -1.0], [x1, 1.0], [x0, 1.0]];
        projected_solid_angle(p, Vec3::Z, &corners.map(|[x, y]| Vec3::new(x, y, 1.0)))
    };
    let (left, right) = (half(-1.0, 0.0), half(0.0, 1.0));
    [0, 1, 2].map(|c| ALBEDO / std::f64::consts::PI * (EVEN[c] * left + ODD[c] * right))
}

/// Each pixel's expected value: the floor's radiance averaged over 8 × 8 points of the
/// pixel (a box filter), where the camera's rays through them meet the floor.
fn expected_image(l: &plenum_scene::LoadedScene) -> Vec<[f64; 3]> {
    let camera = Camera::new(&l.scene.camera, SIZE, SIZE);
    let mut image = Vec::new();
    for j in 0..SIZE {
        for i in 0..SIZE {
            let mut sum = [0.0; 3];
            for (a, b) in (0..64).map(|k| (k % 8, k / 8)) {
                let x = i as f64 + (a as f64 + 0.5) / 8.0;
                let y = j as f64 + (b as f64 + 0.5) / 8.0;
                let ray = camera.ray(x, y);
                let t = -ray.origin.z / ray.direction.z;
                let radiance = floor_radiance(ray.origin + ray.direction * t);
                for c in 0..3 {
                    sum[c] += radiance[c] / 64.0;
                }
            }
            image.push(sum);
        }
    }
    image
}

/// Every physically based method lights the floor under a textured light as Lambert's
/// formula says: the image mean within 0.5 % per channel (photon mapping, whose density
/// estimate blurs the kink under the checker's edge, 1 %), RGB, seed 11, 1024 spp (light
/// tracing 4096); the spectral path tracer's within 1 % (8192 spp); and the path tracer's
/// pixels pass Mitsuba's z-test against the closed form (16 renders of 64 spp, the closed
/// form taken as exact).
#[test]
fn a_textured_light_lights_the_floor_as_lamberts_formula_says() {
    let l = scene(&floor_under_a_checker());
    let expected = expected_image(&l);
    let reference = mean_of(&expected);
    for kind in PHYSICAL {
        let (spp, tolerance) = match kind {
            IntegratorKind::Light => (4096, 0.005),
            IntegratorKind::Photon => (1024, 0.01),
            _ => (1024, 0.005),
        };
        let image = draw(&l, &settings_for(&l, kind, spp, ColorMode::Rgb, 11));
        assert_mean_within(kind.name(), mean(&image), "Lambert", reference, tolerance);
    }
    // Spectral: the texture's RGB uplifted as an illuminant comes back as that RGB.
    let image = draw(
        &l,
        &settings_for(&l, IntegratorKind::Path, 8192, ColorMode::Spectral, 11),
    );
    assert_mean_within("spectral path", mean(&image), "Lambert", reference, 0.01);
    let renders: Vec<Vec<[f32; 3]>> = (0..16)
        .map(|seed| draw(&l, &path_settings(&l, 64, ColorMode::Rgb, 100 + seed)))
        .collect();
    let (m, variance) = mean_and_variance(&renders);
    let exact = vec![[0.0; 3]; expected.len()];
    assert_z_test_passes(&m, &variance, &expected, &exact);
}

/// Mitsuba's z-test of `a` (variance `va`) against `b` (variance `vb`): 99.75 % of pixel
/// channels pass, and the squared error is what the variances predict (0.7 to 1.4 times).
fn assert_z_test_passes(a: &[[f64; 3]], va: &[[f64; 3]], b: &[[f64; 3]], vb: &[[f64; 3]]) {
    let (rate, ratio, _) = z_test(a, va, b, vb);
    assert!(
        rate >= 0.9975,
        "only {:.2} % of pixel channels pass",
        100.0 * rate
    );
    assert!(
        (0.7..=1.4).contains(&ratio),
        "squared error is {ratio} × what noise predicts"
    );
}

fn mean_of(image: &[[f64; 3]]) -> [f64; 3] {
    let mut m = [0.0; 3];
    for p in image {
        for c in 0..3 {
            m[c] += p[c] / image.len() as f64;
        }
    }
    m
}

/// A sphere light placed by a turn, a scale and a move, its emission a bilinear blend of
/// four colours over its (u, v), over a floor; `camera` looks at one or the other.
fn textured_sphere(camera: &str) -> String {
    format!(
        r#"
[render]
max_depth = 2

[camera]
{camera}
up = [0, 0, 1]
resolution = [16, 16]

[materials.floor]
type = "diffuse"
reflectance = 0.5

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 1
emission = {{ texture = "bilerp", corners = [[3, 0.2, 0.2], [0.2, 3, 0.2], [0.2, 0.2, 3], [2, 2, 0.2]] }}
transform = [{{ rotate = {{ axis = [1, 1, 0], degrees = 50 }} }}, {{ scale = 0.6 }}, {{ translate = [0.2, 0, 0.9] }}]

[[objects]]
type = "plane"
point = [0, 0, 0]
normal = [0, 0, 1]
material = "floor"
"#
    )
}

/// Light tracing finds a textured light's radiance only at the points it samples on the
/// surface, the path tracer where its rays meet it: looking at a sphere placed by a
/// rotation, a scale and a move (it fills the view), the two agree pixel by pixel
/// (Mitsuba's z-test, 16 renders each of 16 and 64 spp, seeds 200 and 300 on). Where the
/// sphere lights the floor, next-event estimation samples it by the cone it subtends: the
/// image means of path tracing, BDPT and light tracing agree within 1 % (1024, 1024 and
/// 4096 spp, seed 5).
#[test]
fn every_method_sees_a_textured_sphere_alike() {
    let l = scene(&textured_sphere(
        "position = [0.2, -3, 1.4]\nlook_at = [0.2, 0, 0.9]\nfov = 12",
    ));
    let renders = |kind, spp, seed: u64| -> Vec<Vec<[f32; 3]>> {
        (0..16)
            .map(|k| draw(&l, &settings_for(&l, kind, spp, ColorMode::Rgb, seed + k)))
            .collect()
    };
    let (path, path_var) = mean_and_variance(&renders(IntegratorKind::Path, 16, 200));
    let (light, light_var) = mean_and_variance(&renders(IntegratorKind::Light, 64, 300));
    assert_z_test_passes(&path, &path_var, &light, &light_var);
    let l = scene(&textured_sphere(
        "position = [1.5, -2.5, 0.4]\nlook_at = [0.2, 0, 0]\nfov = 30",
    ));
    let path = mean(&draw(
        &l,
        &settings_for(&l, IntegratorKind::Path, 1024, ColorMode::Rgb, 5),
    ));
    for (kind, spp) in [(IntegratorKind::Bdpt, 1024), (IntegratorKind::Light, 4096)] {
        let m = mean(&draw(&l, &settings_for(&l, kind, spp, ColorMode::Rgb, 5)));
        assert_mean_within(kind.name(), m, "path", path, 0.01);
    }
}

/// `plenum convert` writes a textured emission as its texture (scaled by the radiance where
/// that is not white), and the scene read back renders the same image, bit for bit.
#[test]
fn convert_keeps_a_textured_emission() {
    let l = scene(&floor_under_a_checker());
    let text = plenum_scene::to_toml(&l.scene, &l.defaults);
    assert!(
        text.contains("emission = { texture = \"checker\""),
        "the emission is written as its texture:\n{text}"
    );
    let back = scene(&text);
    for kind in [IntegratorKind::Path, IntegratorKind::Light] {
        let s = settings_for(&l, kind, 4, ColorMode::Rgb, 1);
        assert_eq!(draw(&l, &s), draw(&back, &s), "{}", kind.name());
    }
}
