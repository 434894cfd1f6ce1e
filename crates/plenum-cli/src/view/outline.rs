//! The scene as lines for the page's 3-D view (`/api/scene`): each object's outline in
//! world space (a sphere's three great circles, a disk's rim, a polygon's edges, a small
//! mesh's edges, any other object's box), each infinite plane as a grid about the scene,
//! the camera's frustum to the image's corners (a box for an orthographic camera: its
//! corner rays start apart), and the lights.

use plenum_core::camera::Camera;
use plenum_core::geometry::Shape;
use plenum_core::light::Light;
use plenum_core::math::{Bounds3, Vec3};
use plenum_core::scene::{Primitive, Scene};
use serde_json::{json, Value};

/// Meshes with more triangles are drawn as their box: their edges would hide the rays.
const MESH_EDGES: usize = 2000;
/// Segments of a drawn circle.
const CIRCLE: usize = 48;

/// The scene's outlines, camera and lights as JSON: points as [x, y, z], each object a list
/// of polylines.
pub fn scene_json(scene: &Scene, width: u32, height: u32) -> Value {
    let geometry = &scene.geometry;
    let (center, radius) = geometry.bounding_sphere();
    let objects: Vec<Value> = geometry
        .primitives
        .iter()
        .enumerate()
        .map(|(i, p)| {
            json!({
                "name": geometry.names[i],
                "emitter": p.light.is_some(),
                "lines": outline(p, center, radius).iter().map(|l| l.iter().map(|v| xyz(*v)).collect::<Vec<_>>()).collect::<Vec<_>>(),
            })
        })
        .collect();
    let camera = Camera::new(&scene.camera, width, height);
    let eye = scene.camera.position;
    // The frustum to a plane at the distance of the scene's centre.
    let depth = (center - eye).length().max(radius * 0.5).max(1e-3);
    // The rays through the image's corners: where they start (the eye, or for an
    // orthographic camera the corners of its view) and where they reach that plane.
    let rays: Vec<([f64; 3], [f64; 3])> = [
        (0.0, 0.0),
        (width as f64, 0.0),
        (width as f64, height as f64),
        (0.0, height as f64),
    ]
    .iter()
    .map(|&(x, y)| {
        let r = camera.ray(x, y);
        let d = r.direction.normalized();
        let forward = (scene.camera.look_at - eye).normalized();
        let along = depth / d.dot(forward).max(1e-3);
        (xyz(r.origin), xyz(r.origin + d * along))
    })
    .collect();
    let origins: Vec<[f64; 3]> = rays.iter().map(|r| r.0).collect();
    let corners: Vec<[f64; 3]> = rays.iter().map(|r| r.1).collect();
    let lights: Vec<Value> = scene
        .lights
        .iter()
        .zip(&scene.lights.names)
        .filter_map(|(light, name)| match light {
            Light::Point { position, .. }
            | Light::Spot { position, .. }
            | Light::Profiled { position, .. } => {
                Some(json!({ "name": name, "position": xyz(*position) }))
            }
            Light::Directional { direction, .. } => {
                Some(json!({ "name": name, "direction": xyz(*direction) }))
            }
            _ => None,
        })
        .collect();
    json!({
        "center": xyz(center),
        "radius": radius,
        "objects": objects,
        "camera": {
            "position": xyz(eye),
            "up": xyz(scene.camera.up),
            "origins": origins,
            "corners": corners,
        },
        "lights": lights,
    })
}

fn xyz(v: Vec3) -> [f64; 3] {
    [v.x, v.y, v.z]
}

/// Polylines in world space that outline `p`; an infinite plane as a grid over the scene's
/// bounding sphere (`center`, `radius`).
fn outline(p: &Primitive, center: Vec3, radius: f64) -> Vec<Vec<Vec3>> {
    let to_world = |v: Vec3| p.to_world.as_ref().map_or(v, |t| t.point(v));
    let lines: Vec<Vec<Vec3>> = match &p.shape {
        Shape::Sphere(s) => [(Vec3::X, Vec3::Y), (Vec3::Y, Vec3::Z), (Vec3::Z, Vec3::X)]
            .iter()
            .map(|&(a, b)| circle(s.center, a * s.radius, b * s.radius))
            .collect(),
        Shape::Disk(d) => {
            let (a, b) = d.normal.orthonormal_basis();
            vec![circle(d.center, a * d.radius, b * d.radius)]
        }
        Shape::Polygon(poly) => {
            let mut l = poly.vertices().to_vec();
            l.extend(poly.vertices().first().copied());
            vec![l]
        }
        Shape::Mesh(m) if m.triangle_count() <= MESH_EDGES => m
            .triangles()
            .map(|(_, [a, b, c])| vec![a, b, c, a])
            .collect(),
        Shape::Plane(plane) if p.to_world.is_none() => {
            // A grid of 8 × 8 squares about the point of the plane nearest the centre.
            let foot = center - plane.normal * plane.normal.dot(center - plane.point);
            let (s, t) = plane.normal.orthonormal_basis();
            let half = radius.max(1e-3) * 1.5;
            (0..=8)
                .flat_map(|k| {
                    let u = -half + 2.0 * half * k as f64 / 8.0;
                    [
                        vec![foot + s * u - t * half, foot + s * u + t * half],
                        vec![foot + t * u - s * half, foot + t * u + s * half],
                    ]
                })
                .collect()
        }
        _ => match p.world_bounds() {
            Some(b) => return box_edges(&b),
            None => Vec::new(),
        },
    };
    lines
        .into_iter()
        .map(|l| l.into_iter().map(to_world).collect())
        .collect()
}

/// A circle about `c` through `c + a` and `c + b` (a, b at right angles, of equal length).
fn circle(c: Vec3, a: Vec3, b: Vec3) -> Vec<Vec3> {
    (0..=CIRCLE)
        .map(|k| {
            let phi = std::f64::consts::TAU * k as f64 / CIRCLE as f64;
            c + a * phi.cos() + b * phi.sin()
        })
        .collect()
}

/// A box's twelve edges, as four polylines.
fn box_edges(b: &Bounds3) -> Vec<Vec<Vec3>> {
    let p = |x: bool, y: bool, z: bool| {
        Vec3::new(
            if x { b.max.x } else { b.min.x },
            if y { b.max.y } else { b.min.y },
            if z { b.max.z } else { b.min.z },
        )
    };
    let (f, t) = (false, true);
    vec![
        vec![p(f, f, f), p(t, f, f), p(t, t, f), p(f, t, f), p(f, f, f)],
        vec![p(f, f, t), p(t, f, t), p(t, t, t), p(f, t, t), p(f, f, t)],
        vec![p(f, f, f), p(f, f, t)],
        vec![p(t, f, f), p(t, f, t)],
        vec![p(t, t, f), p(t, t, t)],
        vec![p(f, t, f), p(f, t, t)],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use plenum_core::accel::AccelKind;

    /// The built-in scene's outline: every object drawn; through an orthographic camera
    /// 2 units high the corner rays start 2 apart, top to bottom, and run parallel.
    #[test]
    fn an_orthographic_cameras_outline_is_a_box() {
        let mut scene = plenum_scene::builtin_scene_with(AccelKind::Bvh).scene;
        scene.camera.orthographic = Some(2.0);
        let v = scene_json(&scene, 40, 30);
        let objects = v["objects"].as_array().unwrap();
        assert_eq!(objects.len(), scene.geometry.primitives.len());
        assert!(objects
            .iter()
            .all(|o| !o["lines"].as_array().unwrap().is_empty()));
        let point = |key: &str, i: usize| {
            let p = &v["camera"][key][i];
            Vec3::new(
                p[0].as_f64().unwrap(),
                p[1].as_f64().unwrap(),
                p[2].as_f64().unwrap(),
            )
        };
        let (top, bottom) = (point("origins", 0), point("origins", 3));
        assert!(((top - bottom).length() - 2.0).abs() < 1e-9);
        let (a, b) = (point("corners", 0) - top, point("corners", 3) - bottom);
        assert!((a - b).length() < 1e-9, "{a:?} {b:?}");
    }
}
