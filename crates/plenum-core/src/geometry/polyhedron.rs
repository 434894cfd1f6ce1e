//! Closed polyhedra made of polygon faces, intersected as the lecture describes: reject rays
//! that miss the bounding sphere; then, for each front face (u·N < 0), intersect its
//! supporting plane, test the point against the polygon, and keep the nearest s.
//!
//! Back faces matter only for rays that start inside the solid, which only rays refracted
//! into a transparent polyhedron do; for opaque polyhedra they are culled.

use super::polygon::{newell_normal, PolygonError};
use super::{HitRecord, Polygon, Sphere, SurfaceGeometry};
use crate::math::{Bounds3, Ray, Vec3};

#[derive(Clone, Debug, PartialEq)]
pub struct Polyhedron {
    faces: Vec<Polygon>,
    bounding_sphere: Sphere,
    bounds: Bounds3,
    /// Skip faces turned away from the ray: valid when no ray can start inside.
    pub cull_back_faces: bool,
}

/// Why a face list is not a closed polyhedron.
#[derive(Clone, Debug, PartialEq)]
pub enum PolyhedronError {
    TooFewFaces(usize),
    /// An edge (two vertex indices) that does not join exactly two faces.
    OpenEdge(u32, u32, usize),
    /// Two faces run along a shared edge in the same direction: their windings disagree.
    InconsistentWinding(u32, u32),
    /// A face (by index) that is not a valid polygon.
    Face(usize, PolygonError),
}

impl std::fmt::Display for PolyhedronError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PolyhedronError::TooFewFaces(n) => {
                write!(f, "a closed polyhedron needs at least 4 faces, found {n}")
            }
            PolyhedronError::OpenEdge(a, b, n) => write!(
                f,
                "the polyhedron is not closed: edge {a}–{b} belongs to {n} face(s), not 2"
            ),
            PolyhedronError::InconsistentWinding(a, b) => write!(
                f,
                "the faces meeting at edge {a}–{b} are wound in the same direction: list every face's vertices in the same turning sense"
            ),
            PolyhedronError::Face(i, e) => write!(f, "face {i}: {e}"),
        }
    }
}

impl Polyhedron {
    /// Faces are index loops into `vertices`. The faces are turned to face outward, whichever
    /// way they were wound, as long as they are wound consistently.
    /// Indices must be in range (the scene reader checks them).
    pub fn new(vertices: &[Vec3], faces: &[Vec<u32>]) -> Result<Polyhedron, PolyhedronError> {
        if faces.len() < 4 {
            return Err(PolyhedronError::TooFewFaces(faces.len()));
        }
        if let Some(i) = faces.iter().position(|f| f.len() < 3) {
            return Err(PolyhedronError::Face(
                i,
                PolygonError::TooFewVertices(faces[i].len()),
            ));
        }
        check_closed(faces)?;
        let loops: Vec<Vec<Vec3>> = faces
            .iter()
            .map(|f| f.iter().map(|&i| vertices[i as usize]).collect())
            .collect();
        // Signed volume by the divergence theorem: negative means inward-facing normals.
        let volume: f64 = loops.iter().map(|l| l[0].dot(newell_normal(l)) / 6.0).sum();
        let faces = loops
            .into_iter()
            .enumerate()
            .map(|(i, mut l)| {
                if volume < 0.0 {
                    l.reverse();
                }
                Polygon::new(l).map_err(|e| PolyhedronError::Face(i, e))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let bounds = faces
            .iter()
            .fold(Bounds3::default(), |b, f| b.union(&f.bounds()));
        let (center, radius) = bounds.bounding_sphere();
        Ok(Polyhedron {
            faces,
            bounding_sphere: Sphere::new(center, radius),
            bounds,
            cull_back_faces: false,
        })
    }

    pub fn faces(&self) -> &[Polygon] {
        &self.faces
    }

    pub fn bounds(&self) -> Bounds3 {
        self.bounds
    }

    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<HitRecord> {
        // Bounding-sphere test: a ray that misses it, or meets it only behind its origin
        // or beyond t_max, cannot hit a face.
        let (t0, t1) = self.bounding_sphere.roots(ray)?;
        if t1 <= 0.0 || t0 >= t_max {
            return None;
        }
        let mut best: Option<HitRecord> = None;
        for (i, face) in self.faces.iter().enumerate() {
            if self.cull_back_faces && ray.direction.dot(face.normal()) >= 0.0 {
                continue;
            }
            let limit = best.map_or(t_max, |h| h.t);
            if let Some(t) = face.plane_hit(ray, limit) {
                if face.contains(ray.at(t)) {
                    best = Some(HitRecord {
                        t,
                        u: 0.0,
                        v: 0.0,
                        part: i as u32,
                    });
                }
            }
        }
        best
    }

    pub fn surface(&self, ray: &Ray, hit: &HitRecord) -> SurfaceGeometry {
        self.faces[hit.part as usize].surface(ray, hit)
    }

    pub fn uv_derivatives(&self, hit: &HitRecord) -> [Vec3; 2] {
        self.faces[hit.part as usize].uv_derivatives()
    }
}

/// Every edge of a closed surface joins exactly two faces, and consistently wound faces
/// run along a shared edge in opposite directions.
fn check_closed(faces: &[Vec<u32>]) -> Result<(), PolyhedronError> {
    // For each undirected edge: how many faces use it, and the net direction count.
    let mut edges: std::collections::HashMap<(u32, u32), (usize, i32)> = Default::default();
    for face in faces {
        for i in 0..face.len() {
            let (a, b) = (face[i], face[(i + 1) % face.len()]);
            let e = edges.entry((a.min(b), a.max(b))).or_default();
            e.0 += 1;
            e.1 += if a < b { 1 } else { -1 };
        }
    }
    let mut bad: Vec<_> = edges
        .into_iter()
        .filter(|&(_, (n, net))| n != 2 || net != 0)
        .collect();
    bad.sort();
    match bad.first() {
        Some(&((a, b), (2, _))) => Err(PolyhedronError::InconsistentWinding(a, b)),
        Some(&((a, b), (n, _))) => Err(PolyhedronError::OpenEdge(a, b, n)),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube with faces wound inward, to check they are turned outward.
    pub fn cube() -> Polyhedron {
        let v: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
            .collect();
        let faces = vec![
            vec![0, 1, 3, 2],
            vec![4, 6, 7, 5],
            vec![0, 4, 5, 1],
            vec![2, 3, 7, 6],
            vec![0, 2, 6, 4],
            vec![1, 5, 7, 3],
        ];
        Polyhedron::new(&v, &faces).unwrap()
    }

    #[test]
    fn faces_point_outward_and_nearest_face_wins() {
        let mut cube = cube();
        let ray = Ray::new(Vec3::new(0.5, 0.25, -3.0), Vec3::Z);
        for cull in [false, true] {
            cube.cull_back_faces = cull;
            let hit = cube.intersect(&ray, 1e9).unwrap();
            assert!((hit.t - 3.0).abs() < 1e-12);
            assert_eq!(cube.surface(&ray, &hit).n, -Vec3::Z);
        }
        // From inside, only the back faces can be hit.
        let inside = Ray::new(Vec3::splat(0.5), Vec3::X);
        cube.cull_back_faces = false;
        let hit = cube.intersect(&inside, 1e9).unwrap();
        assert!((hit.t - 0.5).abs() < 1e-12);
        assert_eq!(cube.surface(&inside, &hit).n, Vec3::X);
    }

    #[test]
    fn open_or_inconsistent_surfaces_are_rejected() {
        let v = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        let tetrahedron = vec![vec![0, 2, 1], vec![0, 1, 3], vec![0, 3, 2], vec![1, 2, 3]];
        assert!(Polyhedron::new(&v, &tetrahedron).is_ok());
        let open = vec![vec![0, 2, 1], vec![0, 1, 3], vec![0, 3, 2], vec![1, 2, 0]];
        assert!(matches!(
            Polyhedron::new(&v, &open),
            Err(PolyhedronError::OpenEdge(..))
        ));
        let mixed = vec![vec![0, 1, 2], vec![0, 1, 3], vec![0, 2, 3], vec![1, 2, 3]];
        assert!(matches!(
            Polyhedron::new(&v, &mixed),
            Err(PolyhedronError::InconsistentWinding(..))
        ));
    }
}
