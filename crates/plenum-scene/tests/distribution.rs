//! Distribution ray tracing checked against closed forms: the irradiance from a sphere light,
//! the penumbra of a rectangle light behind a straight edge, the thin-lens circle of
//! confusion, and a motion-blurred edge. Every render here has a fixed seed; tolerances are
//! stated with each test.

use plenum_core::integrator::{RayCounts, Whitted, WhittedConfig};
use plenum_core::math::Ray;
use plenum_core::render::{render, RenderSettings};
use plenum_core::sampling::{PixelSampler, Rng, SampleStream};
use plenum_core::scene::Scene;
use plenum_core::Vec3;
use plenum_scene::{parse_scene, LoadedScene};
use std::f64::consts::PI;
use std::path::Path;
use std::sync::atomic::AtomicBool;

fn scene(text: &str) -> LoadedScene {
    parse_scene(Path::new("test.toml"), text, Path::new(".")).unwrap_or_else(|e| panic!("{e}"))
}

/// Red radiance seen by a ray straight down onto the floor at (x, 0, z), from just above it.
fn floor_radiance(scene: &Scene, x: f64, z: f64) -> f64 {
    let whitted = Whitted::new(scene, WhittedConfig::default());
    let ray = Ray::new(Vec3::new(x, 0.01, z), -Vec3::Y);
    let mut stream = SampleStream::random(Rng::new(7, 0));
    whitted
        .camera_ray(&ray, &mut stream, &mut RayCounts::default(), None)
        .r
}

/// A white floor (k_d = 1, no ambient): its radiance under an area light is the irradiance.
const FLOOR: &str = r#"
[materials.floor]
diffuse = 1
ambient = 0

[[objects]]
type = "plane"
material = "floor"
normal = [0, 1, 0]
"#;

/// E = π·L·sin²α·cos θ from a sphere of radiance L subtending half-angle α, its centre at
/// angle θ from the normal (exact while the sphere is wholly above the horizon). 1024
/// stratified shadow rays per point; tolerance 0.5 %.
#[test]
fn sphere_light_gives_the_closed_form_irradiance() {
    let (height, radius, radiance) = (3.0, 0.5, 2.0);
    let loaded = scene(&format!(
        r#"{FLOOR}
[[lights]]
type = "sphere"
center = [0, {height}, 0]
radius = {radius}
intensity = {radiance}
samples = 1024
"#
    ));
    for x in [0.0, 1.0, 2.5] {
        let d2 = x * x + height * height;
        let expected = PI * radiance * (radius * radius / d2) * (height / d2.sqrt());
        let e = floor_radiance(&loaded.scene, x, 0.0);
        assert!(
            (e / expected - 1.0).abs() < 5e-3,
            "x = {x}: {e} vs {expected}"
        );
    }
}

/// Irradiance from a uniform polygonal emitter of radiance L (Lambert 1760):
/// E = L/2 · Σ_edges Θ_i · (n · Γ_i), Θ_i the angle the edge subtends at p and Γ_i the unit
/// normal of the plane through p and the edge.
fn polygon_irradiance(p: Vec3, n: Vec3, vertices: &[Vec3], radiance: f64) -> f64 {
    let mut sum = 0.0;
    for i in 0..vertices.len() {
        let a = (vertices[i] - p).normalized();
        let b = (vertices[(i + 1) % vertices.len()] - p).normalized();
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        sum += theta * n.dot(a.cross(b).normalized());
    }
    0.5 * radiance * sum.abs()
}

/// A 2 × 2 rectangle light at height 3, a horizontal opaque sheet at height 1.5 covering
/// x < 0: from a floor point at x the sheet hides the part of the light left of −x (similar
/// triangles), so across x ∈ [−1, 1] the floor passes from umbra to full light. Expected:
/// Lambert's formula for the visible part. 32 × 32 stratified shadow rays per point;
/// tolerance 1 % of the unshadowed irradiance.
#[test]
fn rectangle_penumbra_behind_an_edge_matches_lamberts_formula() {
    let (a, height, sheet, radiance) = (1.0, 3.0, 1.5, 1.0);
    let text = format!(
        r#"{FLOOR}
[materials.sheet]
diffuse = 0
ambient = 0

[[objects]]
type = "polygon"
material = "sheet"
vertices = [[-20, {sheet}, -20], [0, {sheet}, -20], [0, {sheet}, 20], [-20, {sheet}, 20]]

[[lights]]
type = "rectangle"
corner = [-{a}, {height}, -{a}]
edge_u = [{w}, 0, 0]
edge_v = [0, 0, {w}]
intensity = {radiance}
samples = 1024
"#,
        w = 2.0 * a
    );
    let loaded = scene(&text);
    let full = polygon_irradiance(
        Vec3::ZERO,
        Vec3::Y,
        &[
            Vec3::new(-a, height, -a),
            Vec3::new(a, height, -a),
            Vec3::new(a, height, a),
            Vec3::new(-a, height, a),
        ],
        radiance,
    );
    for k in 0..=10 {
        let x = -1.25 + 0.25 * k as f64;
        // Visible part of the light: x_light > x·(1 − height/sheet).
        let cut = (x * (1.0 - height / sheet)).clamp(-a, a);
        let expected = if cut >= a {
            0.0
        } else {
            let p = Vec3::new(x, 0.0, 0.0);
            polygon_irradiance(
                p,
                Vec3::Y,
                &[
                    Vec3::new(cut, height, -a),
                    Vec3::new(a, height, -a),
                    Vec3::new(a, height, a),
                    Vec3::new(cut, height, a),
                ],
                radiance,
            )
        };
        let e = floor_radiance(&loaded.scene, x, 0.0);
        assert!(
            (e - expected).abs() < 0.01 * full,
            "x = {x}: {e} vs {expected} (unshadowed {full})"
        );
    }
}

fn film_row_means(loaded: &LoadedScene, settings: &RenderSettings) -> Vec<f64> {
    let film = render(&loaded.scene, settings, &AtomicBool::new(false), &|_, _| {}).film;
    (0..film.width)
        .map(|x| (0..film.height).map(|y| film.get(x, y).r).sum::<f64>() / film.height as f64)
        .collect()
}

/// The mean over pixel [u − ½, u + ½] of a profile, by the midpoint rule.
fn pixel_average(profile: impl Fn(f64) -> f64, u: f64) -> f64 {
    let n = 200;
    (0..n)
        .map(|k| profile(u - 0.5 + (k as f64 + 0.5) / n as f64))
        .sum::<f64>()
        / n as f64
}

/// A camera (`camera`'s keys; at the origin looking down −z in most tests) facing a bright half-plane
/// x > 0 at depth `depth` (plus `object`'s keys), on black: a straight vertical edge.
fn edge_scene(camera: &str, object: &str, depth: f64) -> LoadedScene {
    scene(&format!(
        r#"
[camera]
{camera}

[materials.white]
emissive = 1
diffuse = 0
ambient = 0

[[objects]]
type = "polygon"
material = "white"
vertices = [[0, -50, -{depth}], [50, -50, -{depth}], [50, 50, -{depth}], [0, 50, -{depth}]]
{object}
"#
    ))
}

/// Thin lens: a point at depth z, with the lens (radius R) focused at depth s, spreads over
/// a disk of radius c = R·|z − s| / z on the plane of focus — c / (pixel size at s) pixels in
/// the image. A bright half-plane x > 0 at depth z therefore blurs into the fraction of that
/// disk beyond the edge: the circular-segment profile. Rendered with 256 Sobol samples per
/// pixel over 8 rows; tolerance 0.03 per column.
#[test]
fn defocused_edge_follows_the_circle_of_confusion() {
    let (width, height, fov) = (96u32, 8u32, 5.0f64);
    let (radius, focus, depth) = (1.0, 4.0, 10.0);
    for blades in [0, 6] {
        let loaded = edge_scene(
            &format!(
                "position = [0, 0, 0]\nlook_at = [0, 0, -1]\nfov = {fov}\nresolution = [{width}, {height}]\n\
                 aperture = {radius}\nfocus_distance = {focus}\nblades = {blades}"
            ),
            "",
            depth,
        );
        let pixel_size = 2.0 * (fov.to_radians() / 2.0).tan() / height as f64;
        let c = radius * (depth - focus) / depth / (focus * pixel_size);
        assert!(c > 5.0 && c < 20.0, "a blur of {c} pixels tests little");
        let settings = RenderSettings {
            width,
            height,
            sampler: PixelSampler::Sobol { spp: 256 },
            seed: 3,
            ..Default::default()
        };
        let row = film_row_means(&loaded, &settings);
        // Fraction of the disk centred u pixels right of the edge that lies right of it.
        let segment = |d: f64| {
            let d = d.clamp(-1.0, 1.0);
            (d.acos() - d * (1.0 - d * d).sqrt()) / PI
        };
        let disk = |u: f64| 1.0 - segment(u / c);
        let centre = width as f64 / 2.0;
        for (x, value) in row.iter().enumerate() {
            let u = x as f64 + 0.5 - centre;
            let expected = pixel_average(disk, u);
            // A hexagon is not a disk: only the extent of the blur is the same (its inscribed
            // and circumscribed circles bound it).
            if blades == 0 {
                assert!(
                    (value - expected).abs() < 0.03,
                    "column {x}: {value} vs {expected} (blur radius {c:.2} px)"
                );
            } else if u.abs() > c + 1.0 {
                assert!((value - if u > 0.0 { 1.0 } else { 0.0 }).abs() < 1e-9);
            }
        }
    }
}

/// Motion blur: a bright half-plane whose edge moves D pixels to the right while the shutter
/// is open covers each pixel on its path for a share of the time that grows linearly across
/// it: a linear ramp D pixels wide. 256 Sobol samples per pixel (time stratified) over 8
/// rows; tolerance 0.02 per column.
#[test]
fn moving_edge_blurs_into_a_linear_ramp() {
    let (width, height, fov, depth) = (96u32, 8u32, 20.0f64, 10.0f64);
    let pixel_size = 2.0 * (fov.to_radians() / 2.0).tan() / height as f64;
    let travel_pixels = 30.0;
    let travel = travel_pixels * pixel_size * depth;
    let half = travel / 2.0;
    let view = format!("fov = {fov}\nresolution = [{width}, {height}]");
    let loaded = edge_scene(
        &format!("position = [0, 0, 0]\nlook_at = [0, 0, -1]\n{view}\nshutter = [0, 1]"),
        &format!(
            "transform = [{{ translate = [-{half}, 0, 0] }}]\n\
             transform_close = [{{ translate = [{half}, 0, 0] }}]"
        ),
        depth,
    );
    let settings = RenderSettings {
        width,
        height,
        sampler: PixelSampler::Sobol { spp: 256 },
        seed: 5,
        ..Default::default()
    };
    let row = film_row_means(&loaded, &settings);
    let centre = width as f64 / 2.0;
    let ramp = |u: f64| ((u + travel_pixels / 2.0) / travel_pixels).clamp(0.0, 1.0);
    for (x, value) in row.iter().enumerate() {
        let expected = pixel_average(ramp, x as f64 + 0.5 - centre);
        assert!(
            (value - expected).abs() < 0.02,
            "column {x}: {value} vs {expected}"
        );
    }
    // The camera moving the other way instead gives the same ramp: only relative motion
    // counts.
    let mut camera_moves = edge_scene(
        &format!(
            "position = [{half}, 0, 0]\nlook_at = [{half}, 0, -1]\n\
             position_close = [-{half}, 0, 0]\nlook_at_close = [-{half}, 0, -1]\n{view}"
        ),
        "",
        depth,
    );
    let moving_camera = film_row_means(&camera_moves, &settings);
    for (x, (a, b)) in moving_camera.iter().zip(&row).enumerate() {
        assert!(
            (a - b).abs() < 0.02,
            "moving camera, column {x}: {a} vs {b}"
        );
    }
    camera_moves.scene.camera.motion = None;
    let still = film_row_means(&camera_moves, &settings);
    assert!(
        still.iter().all(|&v| v == 0.0 || v == 1.0),
        "a still camera sees a sharp edge"
    );

    // Half a shutter: half the ramp.
    let mut half_open = loaded;
    half_open.scene.camera.shutter = [0.0, 0.5];
    let row = film_row_means(&half_open, &settings);
    let ramp = |u: f64| ((u + travel_pixels / 2.0) / (travel_pixels / 2.0)).clamp(0.0, 1.0);
    for (x, value) in row.iter().enumerate() {
        let expected = pixel_average(ramp, x as f64 + 0.5 - centre);
        assert!((value - expected).abs() < 0.02, "half shutter, column {x}");
    }
}

/// Every acceleration structure bounds moving objects over their whole path: a still frame
/// late in the motion (shutter [0.9, 0.9]) renders exactly as the same scene with each moving
/// object placed statically at its pose of time 0.9. A structure that bounded only the pose
/// at time 0 would lose the ball, which has moved out of its first box by then.
#[test]
fn every_structure_bounds_moving_objects() {
    use plenum_core::accel::AccelKind;
    let loaded = plenum_scene::load_scene(Path::new("../../scenes/motion-blur.toml"))
        .unwrap_or_else(|e| panic!("{e}"));
    let settings = RenderSettings {
        width: 48,
        height: 32,
        seed: 2,
        ..Default::default()
    };
    let draw = |scene: &Scene| {
        render(scene, &settings, &AtomicBool::new(false), &|_, _| {})
            .film
            .pixels()
            .to_vec()
    };
    let mut moving = loaded.scene.clone();
    moving.camera.shutter = [0.9, 0.9];
    let mut posed = moving.clone();
    for p in &mut posed.geometry.primitives {
        if let Some(m) = p.motion.take() {
            p.to_world = Some(Box::new(m.at(0.9)));
        }
    }
    for kind in AccelKind::ALL {
        let (a, b) = (
            draw(&moving.clone().with_accel(kind)),
            draw(&posed.clone().with_accel(kind)),
        );
        assert!(a == b, "{}", kind.name());
    }
}
