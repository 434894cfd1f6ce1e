//! `plenum render model.obj` (or `.ply`): a mesh on its own, framed by a default camera and
//! lit by default lights so it can be seen at once. OBJ files keep their MTL materials.

use crate::diagnostics::SceneError;
use crate::{mtl, obj, ply, RenderDefaults};
use plenum_core::camera::CameraSettings;
use plenum_core::color::Color;
use plenum_core::geometry::{Shape, TriangleMesh};
use plenum_core::light::{Attenuation, Light};
use plenum_core::material::PhongMaterial;
use plenum_core::math::{Transform, Vec3};
use plenum_core::scene::SceneBuilder;
use plenum_core::texture::Texture;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// Field of view of the framing camera, in degrees.
const FOV: f64 = 35.0;

/// A mesh file's bytes as a whole scene; `path` names it and locates its material libraries.
pub fn model_from_bytes(
    path: &Path,
    extension: &str,
    bytes: Vec<u8>,
) -> Result<(SceneBuilder, RenderDefaults, Vec<String>), SceneError> {
    let base = path.parent().unwrap_or(Path::new("."));
    let mut warnings = Vec::new();
    let groups: Vec<(String, PhongMaterial, TriangleMesh)> = if extension == "ply" {
        let mesh = ply::parse_ply_with(path, &bytes, false)?;
        vec![("model".into(), default_material(), mesh)]
    } else {
        let (text, not_utf8) = crate::text::lenient(path, bytes);
        warnings.extend(not_utf8);
        let model = obj::parse_obj_model(path, &text, true)?;
        warnings.extend(model.warnings.iter().cloned());
        let mut materials: HashMap<String, PhongMaterial> = HashMap::new();
        for lib in &model.material_libraries {
            let lib_path = base.join(lib);
            match crate::text::read_lenient(&lib_path) {
                Ok((t, not_utf8)) => {
                    warnings.extend(not_utf8);
                    let (m, w) = mtl::parse_mtl(&lib_path, &t, lib_path.parent().unwrap_or(base))?;
                    materials.extend(m);
                    warnings.extend(w);
                }
                Err(e) => warnings.push(format!(
                    "warning: {}: cannot read material library {}: {e}; using grey",
                    path.display(),
                    lib_path.display()
                )),
            }
        }
        model
            .groups
            .into_iter()
            .map(|(name, mesh)| {
                let m = name.as_ref().and_then(|n| materials.get(n).cloned());
                (
                    name.unwrap_or_else(|| "model".into()),
                    m.unwrap_or_else(default_material),
                    mesh,
                )
            })
            .collect()
    };
    let mut builder = SceneBuilder::default();
    let mut bounds = plenum_core::math::Bounds3::default();
    for (name, material, mesh) in groups {
        bounds = bounds.union(&mesh.bounds());
        let id = builder.add_material(name.clone(), material);
        builder.add_object(name, Shape::Mesh(Arc::new(mesh)), Transform::IDENTITY, id);
    }
    // Frame the bounding sphere from the front-right, above; y is up, as in most OBJ files.
    let (center, radius) = bounds.bounding_sphere();
    let radius = radius.max(1e-9);
    let direction = Vec3::new(0.6, 0.45, 1.0).normalized();
    let distance = radius / (FOV.to_radians() * 0.5).sin() * 1.05;
    let position = center + direction * distance;
    builder.camera = CameraSettings {
        position,
        look_at: center,
        up: Vec3::Y,
        fov_degrees: FOV,
        ..CameraSettings::default()
    };
    builder.background = Color::new(0.18, 0.2, 0.24);
    builder.ambient = Color::gray(0.12);
    let key = center + Vec3::new(-0.8, 1.2, 1.0).normalized() * distance * 1.5;
    let fill = center + Vec3::new(1.2, 0.3, 0.6).normalized() * distance * 1.5;
    for (name, at, level) in [("key", key, 0.85), ("fill", fill, 0.35)] {
        builder.add_light(
            name,
            Light::Point {
                position: at,
                intensity: Color::gray(level),
                attenuation: Attenuation::default(),
            },
        );
    }
    Ok((builder, RenderDefaults::default(), warnings))
}

fn default_material() -> PhongMaterial {
    PhongMaterial {
        diffuse: Texture::Constant(Color::new(0.75, 0.72, 0.68)),
        ambient: Texture::Constant(Color::new(0.75, 0.72, 0.68)),
        specular: Texture::Constant(Color::gray(0.25)),
        shininess: 40.0,
        ..PhongMaterial::default()
    }
}
