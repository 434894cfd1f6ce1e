//! Shapes: the surfaces rays hit.
//!
//! Every shape answers two questions, in two phases so that the closest-hit search stays
//! cheap: `intersect` finds the nearest parametric distance t in (0, t_max) and a few numbers
//! to remember the hit by ([`HitRecord`]); `surface` then rebuilds the full
//! [`SurfaceGeometry`] for the one hit that wins. Each `surface` also bounds the rounding
//! error of the point it returns (see [`crate::math::float`]).
//!
//! Shapes live in their own coordinates; a [`crate::scene::Primitive`] adds the transform.
//! Normals from `surface` are geometric, unit length and point *out* of solids (for planar
//! shapes: along the normal the scene gave); the integrator flips them toward the viewer.

mod cone;
mod cuboid;
mod cylinder;
mod disk;
pub mod mesh;
mod partial;
mod plane;
mod polygon;
mod polyhedron;
mod sphere;

pub use cone::Cone;
pub use cuboid::Cuboid;
pub use cylinder::Cylinder;
pub use disk::Disk;
pub use mesh::TriangleMesh;
pub use partial::Partial;
pub use plane::Plane;
pub use polygon::{Polygon, PolygonError};
pub use polyhedron::{Polyhedron, PolyhedronError};
pub use sphere::Sphere;

use crate::accel::Coherence;
use crate::math::{Bounds3, Ray, Vec3};
use std::sync::Arc;

/// What the closest-hit search remembers of a candidate hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HitRecord {
    /// Distance along the ray, in units of |direction|.
    pub t: f64,
    /// Shape-specific surface coordinates (barycentrics for triangles).
    pub u: f64,
    pub v: f64,
    /// Which part was hit: a face of a polyhedron or box, a triangle of a mesh, a cap.
    pub part: u32,
}

/// Whose (u, v) a sphere, disk or cylinder reports. The formats Plenum reads lay these
/// shapes about z and map them each their own way, and a texture lands where its file says
/// only under that map. (Every map here has v up the image, as Plenum's textures.)
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum UvMap {
    /// Plenum's own: a sphere's poles on y; see docs/scene-format.md.
    #[default]
    Plenum,
    /// pbrt-v4's: u = φ/φ_max about z from +x toward +y; v up a sphere's θ between its cut
    /// heights, in from a disk's rim to its inner radius, up a cylinder's height.
    Pbrt,
    /// Mitsuba 3's, its v turned up: a sphere's as pbrt's; a disk's u its radius and v
    /// 1 − φ/2π; a cylinder's v 1 − height/length.
    Mitsuba,
}

/// The local geometry at a hit, in the shape's coordinates.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceGeometry {
    pub p: Vec3,
    /// Conservative bound on the absolute rounding error of `p`, per axis.
    pub p_error: Vec3,
    /// Unit geometric normal, outward for solids.
    pub n: Vec3,
    /// Unit shading normal (interpolated vertex normals for smooth meshes), same side as `n`.
    pub shading_n: Vec3,
    /// Texture coordinates.
    pub uv: [f64; 2],
}

impl SurfaceGeometry {
    fn flat(p: Vec3, p_error: Vec3, n: Vec3, uv: [f64; 2]) -> Self {
        SurfaceGeometry {
            p,
            p_error,
            n,
            shading_n: n,
            uv,
        }
    }
}

/// The closed set of shapes, dispatched by `match` (no virtual calls on the hot path).
#[derive(Clone, Debug)]
pub enum Shape {
    Sphere(Sphere),
    Plane(Plane),
    Disk(Disk),
    Cuboid(Cuboid),
    Cylinder(Cylinder),
    Cone(Cone),
    Polygon(Box<Polygon>),
    Polyhedron(Box<Polyhedron>),
    /// A triangle mesh, shared by every instance that places it.
    Mesh(Arc<TriangleMesh>),
}

impl Shape {
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<HitRecord> {
        match self {
            Shape::Sphere(s) => s.intersect(ray, t_max),
            Shape::Plane(s) => s.intersect(ray, t_max),
            Shape::Disk(s) => s.intersect(ray, t_max),
            Shape::Cuboid(s) => s.intersect(ray, t_max),
            Shape::Cylinder(s) => s.intersect(ray, t_max),
            Shape::Cone(s) => s.intersect(ray, t_max),
            Shape::Polygon(s) => s.intersect(ray, t_max),
            Shape::Polyhedron(s) => s.intersect(ray, t_max),
            Shape::Mesh(s) => s.intersect(ray, t_max),
        }
    }

    /// Some hit in (0, t_max), not necessarily the nearest: enough for a shadow ray that
    /// only asks whether the shape is in the way. Meshes stop at their first hit, walking
    /// their BVH as suits `coherence` rays.
    pub fn intersect_any(&self, ray: &Ray, t_max: f64, coherence: Coherence) -> Option<HitRecord> {
        match self {
            Shape::Mesh(s) => s.intersect_any_as(ray, t_max, coherence),
            _ => self.intersect(ray, t_max),
        }
    }

    /// The geometry at a hit. Texture coordinates cost trigonometry on curved shapes, so
    /// they are computed only when `want_uv` is set (otherwise they may be zero).
    pub fn surface(&self, ray: &Ray, hit: &HitRecord, want_uv: bool) -> SurfaceGeometry {
        match self {
            Shape::Sphere(s) => s.surface(ray, hit, want_uv),
            Shape::Plane(s) => s.surface(ray, hit),
            Shape::Disk(s) => s.surface(ray, hit, want_uv),
            Shape::Cuboid(s) => s.surface(ray, hit),
            Shape::Cylinder(s) => s.surface(ray, hit, want_uv),
            Shape::Cone(s) => s.surface(ray, hit, want_uv),
            Shape::Polygon(s) => s.surface(ray, hit),
            Shape::Polyhedron(s) => s.surface(ray, hit),
            Shape::Mesh(s) => s.surface(ray, hit),
        }
    }

    /// The texture coordinates at `p` (on the surface, in the shape's coordinates) of part
    /// `part`: what a hit there would report. For points no ray found, such as an area
    /// light's samples.
    pub fn uv_at(&self, p: Vec3, part: u32) -> [f64; 2] {
        let hit = |u, v| HitRecord { t: 0.0, u, v, part };
        let at = Ray::new(p, Vec3::Z);
        match self {
            Shape::Mesh(m) => {
                let [b1, b2] = m.barycentrics(part, p);
                m.surface(&at, &hit(b1, b2)).uv
            }
            _ => self.surface(&at, &hit(0.0, 0.0), true).uv,
        }
    }

    /// ∂p/∂u and ∂p/∂v at a hit whose geometry is `g` (computed with texture coordinates),
    /// in the shape's coordinates: the tangent frame of normal and bump maps (a mesh with
    /// tangents gives its interpolated tangent and bitangent instead). Where the
    /// parametrisation is singular (a sphere's pole, a disk's centre, a triangle with
    /// degenerate uvs) some orthonormal pair around the normal.
    pub fn uv_derivatives(&self, hit: &HitRecord, g: &SurfaceGeometry) -> [Vec3; 2] {
        let [dpdu, dpdv] = match self {
            Shape::Sphere(s) => s.uv_derivatives(g.p),
            Shape::Plane(s) => s.uv_derivatives(),
            Shape::Disk(s) => s.uv_derivatives(g.p),
            Shape::Cuboid(s) => s.uv_derivatives(hit),
            Shape::Cylinder(s) => s.uv_derivatives(hit, g.p),
            Shape::Cone(s) => s.uv_derivatives(hit, g.p),
            Shape::Polygon(s) => s.uv_derivatives(),
            Shape::Polyhedron(s) => s.uv_derivatives(hit),
            // glTF's tangents, where given, in place of the uvs' derivatives.
            Shape::Mesh(s) => s
                .tangent_frame(hit)
                .unwrap_or_else(|| s.uv_derivatives(hit)),
        };
        let spanned = dpdu.cross(dpdv).length_squared();
        if spanned > 1e-24 * dpdu.length_squared() * dpdv.length_squared() && spanned.is_finite() {
            [dpdu, dpdv]
        } else {
            let (s, t) = g.shading_n.orthonormal_basis();
            [s, t]
        }
    }

    /// Bounds in the shape's coordinates; `None` for unbounded shapes (the infinite plane).
    pub fn bounds(&self) -> Option<Bounds3> {
        match self {
            Shape::Sphere(s) => Some(s.bounds()),
            Shape::Plane(_) => None,
            Shape::Disk(s) => Some(s.bounds()),
            Shape::Cuboid(s) => Some(s.bounds()),
            Shape::Cylinder(s) => Some(s.bounds()),
            Shape::Cone(s) => Some(s.bounds()),
            Shape::Polygon(s) => Some(s.bounds()),
            Shape::Polyhedron(s) => Some(s.bounds()),
            Shape::Mesh(s) => Some(s.bounds()),
        }
    }

    /// Whether the shape bounds a solid that rays enter and leave (the plane bounds a
    /// half-space); thin sheets such as polygons, disks and open shells do not.
    pub fn is_closed(&self) -> bool {
        match self {
            Shape::Sphere(s) => s.partial.is_none(),
            Shape::Plane(_) | Shape::Cuboid(_) | Shape::Polyhedron(_) => true,
            Shape::Cylinder(s) => s.is_capped() && s.partial().is_none(),
            Shape::Cone(s) => s.capped && s.partial.is_none(),
            Shape::Disk(_) | Shape::Polygon(_) => false,
            Shape::Mesh(m) => m.is_closed(),
        }
    }

    /// A lower-case word for messages and the ray tree.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Shape::Sphere(_) => "sphere",
            Shape::Plane(_) => "plane",
            Shape::Disk(_) => "disk",
            Shape::Cuboid(_) => "box",
            Shape::Cylinder(_) => "cylinder",
            Shape::Cone(_) => "cone",
            Shape::Polygon(_) => "polygon",
            Shape::Polyhedron(_) => "polyhedron",
            Shape::Mesh(_) => "mesh",
        }
    }
}

/// Solves the quadratic of a quadric and returns the nearest root in (0, t_max) that
/// `accept` admits (a height test for finite cylinders and cones).
fn nearest_root(
    roots: Option<(f64, f64)>,
    t_max: f64,
    accept: impl Fn(f64) -> bool,
) -> Option<f64> {
    let (t0, t1) = roots?;
    [t0, t1]
        .into_iter()
        .find(|&t| t > 0.0 && t < t_max && accept(t))
}

/// Intersection of a ray with the plane n·p = dist, in (0, t_max).
fn plane_distance(ray: &Ray, n: Vec3, dist: f64, t_max: f64) -> Option<f64> {
    let denom = n.dot(ray.direction);
    if denom == 0.0 {
        return None;
    }
    let t = (dist - n.dot(ray.origin)) / denom;
    (t > 0.0 && t < t_max).then_some(t)
}

/// The point o + t·d moved onto the plane n·p = dist (n unit), with its error bound. The
/// projection removes the error of t along the normal, which is the error that matters.
fn project_onto_plane(ray: &Ray, t: f64, n: Vec3, dist: f64) -> (Vec3, Vec3) {
    let p = ray.at(t);
    let p = p - n * (n.dot(p) - dist);
    let scale = n.abs().dot(p.abs()) + dist.abs();
    let err = (p.abs() + n.abs() * scale) * crate::math::gamma(8);
    (p, err)
}

#[cfg(test)]
pub(crate) mod test_util {
    use crate::math::Vec3;

    pub fn assert_close(a: Vec3, b: Vec3, tol: f64) {
        assert!((a - b).length() <= tol, "{a:?} != {b:?} (tolerance {tol})");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// A shape and the ∂p/∂u, ∂p/∂v it gives at a point of it.
    type Derivatives = Box<dyn Fn(Vec3) -> [Vec3; 2]>;

    /// pbrt-v4's and Mitsuba's (u, v) on spheres, disks and cylinders at points whose
    /// (u, v) their definitions give by hand, and ∂p/∂u, ∂p/∂v that move (u, v) by what
    /// they say.
    #[test]
    fn each_uv_map_places_known_points_and_its_derivatives_follow_it() {
        let v = Vec3::new;
        let pbrt_band = Partial {
            z_min: -1.0,
            z_max: 1.0,
            phi_max: PI,
            ..Partial::WHOLE
        };
        let ring = Partial {
            inner_radius: 1.0,
            phi_max: PI,
            ..Partial::WHOLE
        };
        let sector = Partial {
            phi_max: PI,
            ..Partial::WHOLE
        };
        let pbrt_sphere = Sphere::new(Vec3::ZERO, 2.0).with_uv_map(UvMap::Pbrt);
        let band = pbrt_sphere.with_partial(pbrt_band);
        let mitsuba_sphere = Sphere::new(v(1.0, 0.0, 0.0), 2.0).with_uv_map(UvMap::Mitsuba);
        let pbrt_disk = Disk::new(Vec3::ZERO, Vec3::Z, 2.0)
            .with_uv_map(UvMap::Pbrt)
            .with_partial(ring);
        let reversed_disk = Disk::new(Vec3::ZERO, -Vec3::Z, 2.0).with_uv_map(UvMap::Pbrt);
        let mitsuba_disk = Disk::new(Vec3::ZERO, Vec3::Z, 1.0).with_uv_map(UvMap::Mitsuba);
        let pbrt_cylinder = Cylinder::new(1.0, 2.0, false)
            .with_uv_map(UvMap::Pbrt)
            .with_partial(sector);
        let mitsuba_cylinder = Cylinder::new(1.0, 2.0, false).with_uv_map(UvMap::Mitsuba);
        let side = HitRecord {
            t: 0.0,
            u: 0.0,
            v: 0.0,
            part: 0,
        };
        let theta = |z: f64| (z / 2.0_f64).acos();
        // (shape, its derivatives, [(point, (u, v))]).
        let cases: Vec<(Shape, Derivatives, Vec<(Vec3, [f64; 2])>)> = vec![
            (
                Shape::Sphere(pbrt_sphere),
                Box::new(move |p| pbrt_sphere.uv_derivatives(p)),
                vec![
                    (v(2.0, 0.0, 0.0), [0.0, 0.5]),
                    (v(0.0, 2.0, 0.0), [0.25, 0.5]),
                    (v(-2.0, 0.0, 0.0), [0.5, 0.5]),
                    (
                        v(0.0, -1.0, 3f64.sqrt()),
                        [0.75, 1.0 - theta(3f64.sqrt()) / PI],
                    ),
                ],
            ),
            (
                Shape::Sphere(band),
                Box::new(move |p| band.uv_derivatives(p)),
                // θ runs from 2π/3 (z = −1) up to π/3 (z = 1); φ over π.
                vec![
                    (v(0.0, 2.0, 0.0), [0.5, 0.5]),
                    (v(3f64.sqrt(), 0.0, 1.0), [0.0, 1.0]),
                ],
            ),
            (
                Shape::Sphere(mitsuba_sphere),
                Box::new(move |p| mitsuba_sphere.uv_derivatives(p)),
                // About its centre; θ = 2π/3 is v = ⅓.
                vec![
                    (v(1.0, 2.0, 0.0), [0.25, 0.5]),
                    (v(1.0 + 3f64.sqrt(), 0.0, -1.0), [0.0, 1.0 / 3.0]),
                ],
            ),
            (
                Shape::Disk(pbrt_disk),
                Box::new(move |p| pbrt_disk.uv_derivatives(p)),
                // v from the rim (0) in to the inner radius (1).
                vec![
                    (v(1.5, 0.0, 0.0), [0.0, 0.5]),
                    (v(0.0, 1.2, 0.0), [0.5, 0.8]),
                ],
            ),
            (
                Shape::Disk(reversed_disk),
                Box::new(move |p| reversed_disk.uv_derivatives(p)),
                // The angle is about +z whichever way the disk faces.
                vec![(v(0.0, 1.0, 0.0), [0.25, 0.5])],
            ),
            (
                Shape::Disk(mitsuba_disk),
                Box::new(move |p| mitsuba_disk.uv_derivatives(p)),
                vec![
                    (v(0.0, 0.5, 0.0), [0.5, 0.75]),
                    (
                        v(-0.3, 0.4, 0.0),
                        [0.5, 1.0 - 0.4f64.atan2(-0.3) / (2.0 * PI)],
                    ),
                ],
            ),
            (
                Shape::Cylinder(pbrt_cylinder),
                Box::new(move |p| pbrt_cylinder.uv_derivatives(&side, p)),
                vec![
                    (v(0.0, 1.0, 1.0), [0.5, 0.5]),
                    (v(1.0, 0.0, 0.5), [0.0, 0.25]),
                ],
            ),
            (
                Shape::Cylinder(mitsuba_cylinder),
                Box::new(move |p| mitsuba_cylinder.uv_derivatives(&side, p)),
                vec![
                    (v(1.0, 0.0, 0.5), [0.0, 0.75]),
                    (v(0.0, -1.0, 1.0), [0.75, 0.5]),
                ],
            ),
        ];
        for (shape, derivatives, points) in cases {
            for (p, want) in points {
                let got = shape.uv_at(p, 0);
                assert!(
                    (got[0] - want[0]).abs() < 1e-12 && (got[1] - want[1]).abs() < 1e-12,
                    "{shape:?} at {p:?}: {got:?}, expected {want:?}"
                );
                // Along ∂p/∂u (∂p/∂v), u (v) moves by the step and the other not.
                let [dpdu, dpdv] = derivatives(p);
                let e = 1e-6;
                for (k, d) in [dpdu, dpdv].into_iter().enumerate() {
                    let moved = shape.uv_at(p + d * e, 0);
                    let du = [(moved[0] - got[0]) / e, (moved[1] - got[1]) / e];
                    let mut expected = [0.0, 0.0];
                    expected[k] = 1.0;
                    assert!(
                        (du[0] - expected[0]).abs() < 1e-4 && (du[1] - expected[1]).abs() < 1e-4,
                        "{shape:?} at {p:?}: ∂(u, v) along ∂p/∂{} is {du:?}",
                        ["u", "v"][k]
                    );
                }
            }
        }
    }
}
