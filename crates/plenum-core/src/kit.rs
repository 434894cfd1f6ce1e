//! Scenes built in Rust for the core's own tests, with no file format in between: a test of
//! light transport here fails for light transport's reasons.

use crate::camera::CameraSettings;
use crate::color::Color;
use crate::geometry::{Polygon, Shape, Sphere};
use crate::light::Emitter;
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
