//! The scene's geometry queries: its primitives in an acceleration structure, the nearest hit
//! of a ray, the hits of a shadow ray, and where they are in world space.

use super::primitive::{Interaction, Primitive};
use crate::accel::{cost, Accel, AccelKind, Coherence, LeafSize};
use crate::camera::Camera;
use crate::geometry::{HitRecord, Shape, TriangleMesh};
use crate::math::{Bounds3, Ray, Vec3};
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct Geometry {
    pub primitives: Vec<Primitive>,
    /// A name per primitive, for the ray tree and messages.
    pub names: Vec<String>,
    /// Per primitive: some light can pass through (a transmissive material or vertex material).
    transmissive: Vec<bool>,
    /// Per primitive: its material looks something up by texture coordinates.
    needs_uv: Vec<bool>,
    accel: Accel,
    /// Primitive index of each item of `accel`, which holds the bounded primitives only.
    bounded: Vec<u32>,
    /// Primitives without bounds (infinite planes), tested on every ray.
    unbounded: Vec<u32>,
}

impl Geometry {
    /// The primitives, and the triangles of every mesh, in `kind` structures; `transmissive`
    /// and `needs_uv` are per primitive, as their materials say.
    pub(super) fn new(
        mut primitives: Vec<Primitive>,
        names: Vec<String>,
        transmissive: Vec<bool>,
        needs_uv: Vec<bool>,
        kind: AccelKind,
    ) -> Geometry {
        rebuild_meshes(&mut primitives, kind);
        let mut bounds = Vec::new();
        let mut bounded = Vec::new();
        let mut unbounded = Vec::new();
        for (i, p) in primitives.iter().enumerate() {
            match p.world_bounds() {
                Some(b) => {
                    bounds.push(b);
                    bounded.push(i as u32);
                }
                None => unbounded.push(i as u32),
            }
        }
        Geometry {
            accel: Accel::build(kind, &bounds, LeafSize::SINGLE),
            primitives,
            names,
            transmissive,
            needs_uv,
            bounded,
            unbounded,
        }
    }

    /// The nearest hit in (0, t_max): the primitive's index and the hit.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<(u32, HitRecord)> {
        let mut best = None;
        self.accel.traverse(ray, t_max, |items, t_max| {
            cost::tested(items.len());
            for &i in items {
                let prim = self.bounded[i as usize];
                if let Some(hit) = self.primitives[prim as usize].intersect(ray, *t_max) {
                    *t_max = hit.t;
                    best = Some((prim, hit));
                }
            }
            true
        });
        cost::tested(self.unbounded.len());
        for &i in &self.unbounded {
            let limit = best.map_or(t_max, |(_, h)| h.t);
            if let Some(hit) = self.primitives[i as usize].intersect(ray, limit) {
                best = Some((i, hit));
            }
        }
        best
    }

    /// Calls `visit(primitive, hit)` once for each primitive hit in (0, t_max), in no
    /// particular order, until `visit` returns false: the query of shadow rays. A
    /// transmissive primitive reports its nearest hit (where its material is looked up);
    /// an opaque one, the first hit found, a mesh walked as suits `coherence` rays.
    pub fn for_each_hit(
        &self,
        ray: &Ray,
        t_max: f64,
        coherence: Coherence,
        mut visit: impl FnMut(u32, &HitRecord) -> bool,
    ) {
        let hit_of = |prim: u32| {
            cost::tested(1);
            let p = &self.primitives[prim as usize];
            if self.transmissive[prim as usize] {
                p.intersect(ray, t_max)
            } else {
                p.intersect_any(ray, t_max, coherence)
            }
        };
        let mut go_on = true;
        self.accel.traverse(ray, t_max, |items, _| {
            for &i in items {
                let prim = self.bounded[i as usize];
                if let Some(hit) = hit_of(prim) {
                    go_on = visit(prim, &hit);
                    if !go_on {
                        break;
                    }
                }
            }
            go_on
        });
        for &i in &self.unbounded {
            if !go_on {
                return;
            }
            if let Some(hit) = hit_of(i) {
                go_on = visit(i, &hit);
            }
        }
    }

    /// Whether anything is hit in (0, t_max), for one of `coherence` rays.
    pub fn occluded(&self, ray: &Ray, t_max: f64, coherence: Coherence) -> bool {
        let mut hit = false;
        self.for_each_hit(ray, t_max, coherence, |_, _| {
            hit = true;
            false
        });
        hit
    }

    /// The primitives, and the triangles of every mesh, in `kind` structures.
    pub fn with_accel(mut self, kind: AccelKind) -> Geometry {
        rebuild_meshes(&mut self.primitives, kind);
        let bounds: Vec<Bounds3> = self
            .bounded
            .iter()
            .filter_map(|&i| self.primitives[i as usize].world_bounds())
            .collect();
        self.accel = Accel::build(kind, &bounds, LeafSize::SINGLE);
        self
    }

    /// Whether some primitive moves while the shutter is open.
    pub fn moves(&self) -> bool {
        self.primitives.iter().any(|p| p.motion.is_some())
    }

    /// Which structure holds the primitives (and the triangles of every mesh).
    pub fn accel_kind(&self) -> AccelKind {
        self.accel.kind()
    }

    /// The structures that had to bound their cells' references (see `Grid::capped`,
    /// `Octree::capped`), named for a warning: "the scene's primitives" or the objects whose
    /// mesh it is.
    pub fn capped_structures(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.accel.capped() {
            out.push("the scene's primitives".to_string());
        }
        let mut seen = std::collections::HashSet::new();
        for (p, name) in self.primitives.iter().zip(&self.names) {
            if let Shape::Mesh(m) = &p.shape {
                if seen.insert(Arc::as_ptr(m)) && m.accel_capped() {
                    out.push(format!("the triangles of `{name}`"));
                }
            }
        }
        out
    }

    /// Bytes of the acceleration structures: the scene's and every distinct mesh's (with
    /// the mesh's vertices and indices).
    pub fn accel_memory_bytes(&self) -> usize {
        let mut seen = std::collections::HashSet::new();
        let meshes: usize = self
            .primitives
            .iter()
            .filter_map(|p| match &p.shape {
                Shape::Mesh(m) if seen.insert(Arc::as_ptr(m)) => Some(m.memory_bytes()),
                _ => None,
            })
            .sum();
        self.accel.memory_bytes() + self.bounded.len() * 4 + meshes
    }

    /// The hit on `primitive` in world space.
    pub fn interaction(&self, ray: &Ray, primitive: u32, hit: &HitRecord) -> Interaction {
        let want_uv = self.needs_uv[primitive as usize];
        self.primitives[primitive as usize].interaction(ray, hit, primitive, want_uv)
    }

    /// Whether light can pass through the primitive anywhere.
    pub fn is_transmissive(&self, primitive: u32) -> bool {
        self.transmissive[primitive as usize]
    }

    /// Bounds of all bounded primitives.
    pub fn bounds(&self) -> Bounds3 {
        self.accel.bounds()
    }

    /// The centre of everything bounded (the origin for an empty scene) and the radius of a
    /// sphere about it: where light from infinity enters the scene.
    pub fn bounding_sphere(&self) -> (Vec3, f64) {
        let b = self.bounds();
        let center = if b.min.x.is_finite() && b.max.x.is_finite() {
            (b.min + b.max) * 0.5
        } else {
            Vec3::ZERO
        };
        (center, self.radius())
    }

    /// Where light from infinity enters the scene for light paths and photons: the sphere
    /// about everything bounded, widened, where the scene has unbounded primitives (an
    /// infinite floor or wall), to take in what `camera` sees of them within [`ENTRY_REACH`]
    /// times (their radius + the camera's distance) of the bounded objects' centre. Without
    /// that, no light path or photon from the sky reaches the part of a floor or wall the
    /// camera sees beyond the bounded objects.
    pub fn entry_sphere(&self, camera: &Camera) -> (Vec3, f64) {
        let (center, radius) = self.bounding_sphere();
        if self.unbounded.is_empty() {
            return (center, radius);
        }
        let mut b = self.bounds();
        let reach = ENTRY_REACH * (radius + (camera.position() - center).length());
        let (w, h) = camera.raster_size();
        for j in 0..=ENTRY_GRID {
            for i in 0..=ENTRY_GRID {
                let (x, y) = (i as f64 / ENTRY_GRID as f64, j as f64 / ENTRY_GRID as f64);
                let ray = camera.ray(x * w, y * h);
                let Some((prim, hit)) = self.intersect(&ray, f64::INFINITY) else {
                    continue;
                };
                let p = ray.at(hit.t);
                if self.unbounded.contains(&prim) && (p - center).length() <= reach {
                    b = if b.is_empty() {
                        Bounds3::new(p, p)
                    } else {
                        b.union_point(p)
                    };
                }
            }
        }
        if b.is_empty() {
            return (center, radius);
        }
        let r = 0.5 * (b.max - b.min).length();
        (
            (b.min + b.max) * 0.5,
            if r > 0.0 { r.max(radius) } else { radius },
        )
    }

    /// The ray of light from infinity along `ray`'s direction through its origin, a point
    /// of the entry disk: started instead beyond every unbounded primitive that the line
    /// crosses behind that point. The disk lies outside everything bounded, not outside an
    /// infinite plane; light started in front of a floor that it has crossed on its way from
    /// infinity would reach, through the floor, what the floor shades (the light from below
    /// the horizon on a wall above a floor).
    pub fn from_infinity(&self, ray: Ray) -> Ray {
        let mut origin = ray.origin;
        // A plane is crossed once; a shape with several crossings takes several rounds.
        for _ in 0..=4 * self.unbounded.len() {
            let back = Ray::new(origin, -ray.direction);
            let far = self
                .unbounded
                .iter()
                .filter_map(|&i| self.primitives[i as usize].intersect(&back, f64::INFINITY))
                .map(|hit| hit.t)
                .fold(0.0, f64::max);
            if far == 0.0 {
                break;
            }
            origin = back.at(far + 1e-6 * (1.0 + far));
        }
        Ray { origin, ..ray }
    }

    /// The radius of a sphere about everything bounded (1 for an empty scene).
    pub fn radius(&self) -> f64 {
        let b = self.bounds();
        let r = 0.5 * (b.max - b.min).length();
        if r.is_finite() && r > 0.0 {
            r
        } else {
            1.0
        }
    }
}

/// How far from the bounded objects' centre [`Geometry::entry_sphere`] takes in what the
/// camera sees of unbounded primitives, in their radius plus the camera's distance: a floor
/// toward the horizon is cut there, as photons spread over a wider disk thin out everywhere.
pub const ENTRY_REACH: f64 = 2.0;
/// Camera rays per side of the grid that finds what the camera sees of them.
const ENTRY_GRID: u32 = 16;

/// Puts the triangles of every mesh not already in a `kind` structure into one, each distinct
/// mesh once, so instances stay shared.
fn rebuild_meshes(primitives: &mut [Primitive], kind: AccelKind) {
    let mut rebuilt: std::collections::HashMap<*const TriangleMesh, Arc<TriangleMesh>> =
        Default::default();
    for p in primitives {
        if let Shape::Mesh(m) = &mut p.shape {
            if m.accel_kind() != kind {
                let new = rebuilt
                    .entry(Arc::as_ptr(m))
                    .or_insert_with(|| Arc::new(m.with_accel(kind)));
                *m = new.clone();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::camera::{Camera, CameraSettings};
    use crate::geometry::{Plane, Shape, Sphere};
    use crate::kit;
    use crate::math::{Transform, Vec3};
    use crate::scene::SceneBuilder;

    /// A small sphere before an infinite wall: light from infinity must enter through a
    /// sphere that holds the part of the wall the camera sees (each corner ray's hit), not
    /// only the sphere about the ball; without unbounded primitives it is the ball's.
    #[test]
    fn light_from_infinity_enters_where_the_camera_sees_an_infinite_wall() {
        let mut b = SceneBuilder::default();
        b.camera = CameraSettings {
            position: Vec3::new(0.0, 0.0, 8.0),
            look_at: Vec3::ZERO,
            fov_degrees: 50.0,
            ..CameraSettings::default()
        };
        let m = b.add_material("grey", kit::diffuse(crate::Color::gray(0.5)));
        let ball = Shape::Sphere(Sphere::new(Vec3::ZERO, 0.5));
        b.add_object("ball", ball.clone(), Transform::IDENTITY, m);
        let alone = {
            let camera = b.camera.clone();
            let mut b = SceneBuilder::default();
            b.camera = camera;
            let m = b.add_material("grey", kit::diffuse(crate::Color::gray(0.5)));
            b.add_object("ball", ball, Transform::IDENTITY, m);
            b.build()
        };
        let wall = Shape::Plane(Plane::new(Vec3::new(0.0, 0.0, -3.0), Vec3::Z));
        b.add_object("wall", wall, Transform::IDENTITY, m);
        let scene = b.build();
        let camera = Camera::new(&scene.camera, 64, 48);
        assert_eq!(
            alone.geometry.entry_sphere(&camera),
            alone.geometry.bounding_sphere()
        );
        let (center, radius) = scene.geometry.entry_sphere(&camera);
        for (x, y) in [(0.0, 0.0), (64.0, 0.0), (0.0, 48.0), (64.0, 48.0)] {
            let ray = camera.ray(x, y);
            let t = (-3.0 - ray.origin.z) / ray.direction.z;
            let corner = ray.at(t);
            assert!(
                (corner - center).length() <= radius * (1.0 + 1e-9),
                "{corner:?} outside the sphere at {center:?} of radius {radius}"
            );
        }
        assert!(radius < 10.0, "{radius}: no wider than it needs");
    }
}
