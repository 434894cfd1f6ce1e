//! Scenes built in Rust for the core's own tests, with no file format in between: a test of
//! light transport here fails for light transport's reasons.

use crate::camera::CameraSettings;
use crate::color::Color;
use crate::geometry::{Plane, Polygon, Shape, Sphere};
use crate::light::{Attenuation, Emitter, Light};
use crate::material::{
    ConductorMaterial, ConductorSpec, DiffuseMaterial, FloatTexture, Material, MaterialId,
    Roughness, SpectralTexture, SpectrumKind,
};
use crate::math::{Transform, Vec3};
use crate::scene::{Scene, SceneBuilder};

/// A diffuse material of constant reflectance.
pub fn diffuse(reflectance: Color) -> Material {
    Material::Diffuse(DiffuseMaterial {
        reflectance: SpectralTexture::constant(reflectance, SpectrumKind::Albedo),
    })
}

/// A rough conductor (GGX, α = `roughness`) of reflectance `r0` at normal incidence.
pub fn rough_conductor(r0: Color, roughness: f64) -> Material {
    Material::Conductor(ConductorMaterial {
        spec: ConductorSpec::Reflectance(SpectralTexture::constant(r0, SpectrumKind::Albedo)),
        roughness: Roughness {
            u: FloatTexture::Constant(roughness),
            v: FloatTexture::Constant(roughness),
            remap: false,
        },
    })
}

/// Adds the quadrilateral `corners` (in order) made of `material`.
fn quad(b: &mut SceneBuilder, name: &str, corners: [Vec3; 4], material: MaterialId) {
    let polygon = Polygon::new(corners.to_vec()).expect("a planar convex quadrilateral");
    b.add_object(
        name,
        Shape::Polygon(Box::new(polygon)),
        Transform::IDENTITY,
        material,
    );
}

/// A Cornell box: the cube [−1, 1]³ open toward the camera at z = 4, white floor, ceiling
/// and back wall, a red left and a green right wall, and a square lamp of radiance 10
/// just under the ceiling. With `glossy`, the back wall is a rough conductor (α = 0.3).
pub fn cornell_box(glossy: bool) -> Scene {
    let mut b = SceneBuilder::default();
    b.camera = CameraSettings {
        position: Vec3::new(0.0, 0.0, 4.0),
        look_at: Vec3::ZERO,
        fov_degrees: 38.0,
        ..CameraSettings::default()
    };
    let white = b.add_material("white", diffuse(Color::gray(0.75)));
    let red = b.add_material("red", diffuse(Color::new(0.6, 0.05, 0.05)));
    let green = b.add_material("green", diffuse(Color::new(0.1, 0.5, 0.1)));
    let back = if glossy {
        b.add_material("metal", rough_conductor(Color::gray(0.9), 0.3))
    } else {
        white
    };
    let v = |x: f64, y: f64, z: f64| Vec3::new(x, y, z);
    quad(
        &mut b,
        "floor",
        [
            v(-1., -1., 1.),
            v(1., -1., 1.),
            v(1., -1., -1.),
            v(-1., -1., -1.),
        ],
        white,
    );
    quad(
        &mut b,
        "ceiling",
        [
            v(-1., 1., -1.),
            v(1., 1., -1.),
            v(1., 1., 1.),
            v(-1., 1., 1.),
        ],
        white,
    );
    quad(
        &mut b,
        "back",
        [
            v(-1., -1., -1.),
            v(1., -1., -1.),
            v(1., 1., -1.),
            v(-1., 1., -1.),
        ],
        back,
    );
    quad(
        &mut b,
        "left",
        [
            v(-1., -1., 1.),
            v(-1., -1., -1.),
            v(-1., 1., -1.),
            v(-1., 1., 1.),
        ],
        red,
    );
    quad(
        &mut b,
        "right",
        [
            v(1., -1., -1.),
            v(1., -1., 1.),
            v(1., 1., 1.),
            v(1., 1., -1.),
        ],
        green,
    );
    b.add_area_light(
        "lamp",
        Emitter::Rectangle {
            corner: v(-0.3, 0.99, -0.3),
            edge_u: v(0.6, 0.0, 0.0),
            edge_v: v(0.0, 0.0, 0.6),
        },
        Color::gray(10.0),
        1,
    );
    b.build()
}

/// A furnace: the camera (fov 90°) at the centre of a sphere of radius 1, diffuse of
/// reflectance `albedo` and emitting `radiance` on both sides. Radiance is the same along
/// every ray: L = L_e·Σ_{k≤D+1} ρ^k over paths of up to D + 1 scattering vertices
/// (`max_depth` D), L_e/(1 − ρ) without a bound.
pub fn furnace(albedo: f64, radiance: f64) -> Scene {
    let mut b = SceneBuilder::default();
    b.camera = CameraSettings {
        position: Vec3::ZERO,
        look_at: Vec3::new(0.0, 0.0, -1.0),
        fov_degrees: 90.0,
        ..CameraSettings::default()
    };
    let wall = b.add_material("wall", diffuse(Color::gray(albedo)));
    let sphere = Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0));
    let radiance = Color::gray(radiance);
    b.add_emissive_object(
        "sphere",
        sphere,
        Transform::IDENTITY,
        wall,
        radiance,
        true,
        1,
    );
    b.build()
}

/// A diffuse floor (the plane y = 0, 40 wide, reflectance `albedo`) under a lamp 1 above the
/// origin: a disk of radius 1 and radiance 1 facing down, or (`point`) a point light of
/// intensity 1. The camera, at (0, 0.8, 3) with a 20° field, sees the floor and nothing
/// else; [`lamp_over_floor_radiance`] is what it sees.
pub fn lamp_over_floor(albedo: f64, point: bool) -> Scene {
    let mut b = SceneBuilder::default();
    b.camera = CameraSettings {
        position: Vec3::new(0.0, 0.8, 3.0),
        look_at: Vec3::ZERO,
        fov_degrees: 20.0,
        ..CameraSettings::default()
    };
    let floor = b.add_material("floor", diffuse(Color::gray(albedo)));
    let corners = [(-20.0, 20.0), (20.0, 20.0), (20.0, -20.0), (-20.0, -20.0)]
        .map(|(x, z)| Vec3::new(x, 0.0, z));
    quad(&mut b, "floor", corners, floor);
    let at = Vec3::new(0.0, 1.0, 0.0);
    if point {
        let intensity = Color::WHITE;
        let attenuation = Attenuation::default();
        b.add_light(
            "lamp",
            Light::Point {
                position: at,
                intensity,
                attenuation,
            },
        );
    } else {
        let disk = Emitter::Disk {
            center: at,
            normal: -Vec3::Y,
            radius: 1.0,
        };
        b.add_area_light("lamp", disk, Color::WHITE, 1);
    }
    b.build()
}

/// The radiance the floor of [`lamp_over_floor`] sends toward any direction from `p` on it:
/// ρ/π·E, with E = I h/(r² + h²)^{3/2} under the point light at height h (r the distance
/// from the point below it) and, under the disk of radius a,
/// E = (π L/2)·(1 − (h² + r² − a²)/√((h² + r² + a²)² − 4 a² r²)) (the view factor of a
/// coaxial parallel disk).
pub fn lamp_over_floor_radiance(albedo: f64, point: bool, p: Vec3) -> f64 {
    let (h, a) = (1.0f64, 1.0f64);
    let r2 = p.x * p.x + p.z * p.z;
    let e = if point {
        h / (r2 + h * h).powf(1.5)
    } else {
        let s = h * h + r2 + a * a;
        std::f64::consts::FRAC_PI_2
            * (1.0 - (h * h + r2 - a * a) / (s * s - 4.0 * a * a * r2).sqrt())
    };
    albedo * std::f64::consts::FRAC_1_PI * e
}

/// The mean over a `size`² image of [`lamp_over_floor`] of [`lamp_over_floor_radiance`],
/// each pixel the mean of 4 × 4 points of it.
pub fn lamp_over_floor_image_mean(albedo: f64, point: bool, size: u32) -> f64 {
    let scene = lamp_over_floor(albedo, point);
    image_mean(&scene, size, |p| lamp_over_floor_radiance(albedo, point, p))
}

/// The mean over a `size`² image of `scene` of `radiance` at the point each camera ray
/// first meets (which every ray must), each pixel the mean of 4 × 4 points of it.
fn image_mean(scene: &Scene, size: u32, radiance: impl Fn(Vec3) -> f64) -> f64 {
    let camera = crate::camera::Camera::new(&scene.camera, size, size);
    let mut sum = 0.0;
    for (x, y) in (0..size * size).map(|i| (i % size, i / size)) {
        for k in 0..16 {
            let (dx, dy) = ((k % 4) as f64 / 4.0 + 0.125, (k / 4) as f64 / 4.0 + 0.125);
            let ray = camera.sample_ray(x as f64 + dx, y as f64 + dy, [0.5; 2], 0.0);
            let (_, hit) = scene
                .geometry
                .intersect(&ray, f64::INFINITY)
                .expect("every camera ray meets the scene");
            sum += radiance(ray.at(hit.t));
        }
    }
    sum / (16 * size * size) as f64
}

/// Two infinite diffuse planes meeting at a right angle under a uniform sky of radiance 1:
/// the floor y = 0 (reflectance `floor`) and the wall z = −3 (reflectance `wall`), seen
/// from (0, 1.2, 7) with a 40° field, which meets nothing else. Light from infinity reaches
/// each plane from half of the sky, the rest hidden by the other plane, and the planes light
/// each other from far beyond what the camera sees: [`corner_under_sky_radiance`].
pub fn corner_under_sky(floor: f64, wall: f64) -> Scene {
    let mut b = SceneBuilder::default();
    b.camera = CameraSettings {
        position: Vec3::new(0.0, 1.2, 7.0),
        look_at: Vec3::new(0.0, 0.5, 0.0),
        fov_degrees: 40.0,
        ..CameraSettings::default()
    };
    for (name, albedo, point, normal) in [
        ("floor", floor, Vec3::ZERO, Vec3::Y),
        ("wall", wall, Vec3::new(0.0, 0.0, -3.0), Vec3::Z),
    ] {
        let m = b.add_material(name, diffuse(Color::gray(albedo)));
        let plane = Shape::Plane(Plane::new(point, normal));
        b.add_object(name, plane, Transform::IDENTITY, m);
    }
    let radiance = Color::WHITE;
    b.add_light("sky", Light::Infinite { radiance });
    b.build()
}

/// The radiance of the floor and of the wall of [`corner_under_sky`], the same at every
/// point and toward every direction, over paths of up to `max_depth` + 1 scattering
/// vertices. Each plane sees the other over exactly half its hemisphere's projected solid
/// angle wherever it is (the other is infinite), and the sky over the other half, so
/// B_f = ρ_f (L + B_w)/2 and B_w = ρ_w (L + B_f)/2: each bounce one more term.
pub fn corner_under_sky_radiance(floor: f64, wall: f64, max_depth: u32) -> (f64, f64) {
    let (mut f, mut w) = (0.5 * floor, 0.5 * wall);
    for _ in 0..max_depth {
        (f, w) = (0.5 * floor * (1.0 + w), 0.5 * wall * (1.0 + f));
    }
    (f, w)
}

/// The mean over a `size`² image of [`corner_under_sky`] of its radiance
/// ([`corner_under_sky_radiance`]), each pixel the mean of 4 × 4 points of it.
pub fn corner_under_sky_image_mean(floor: f64, wall: f64, max_depth: u32, size: u32) -> f64 {
    let (f, w) = corner_under_sky_radiance(floor, wall, max_depth);
    image_mean(&corner_under_sky(floor, wall), size, |p| {
        if p.y < 1e-9 {
            f
        } else {
            w
        }
    })
}
