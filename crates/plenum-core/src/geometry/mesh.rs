//! Triangle meshes with their own BVH, intersected by the watertight ray–triangle test of
//! Woop, Benthin and Wald (JCGT 2013): no ray slips through a shared edge or vertex.
//! Error bounds follow pbrt-v4 §6.8.4.

use super::{HitRecord, SurfaceGeometry};
use crate::accel::Bvh;
use crate::math::{gamma, Bounds3, Ray, Vec3};

#[derive(Clone, Debug)]
pub struct TriangleMesh {
    positions: Vec<Vec3>,
    /// Per-vertex shading normals, or empty for flat shading.
    normals: Vec<Vec3>,
    /// Per-vertex texture coordinates, or empty.
    uvs: Vec<[f64; 2]>,
    triangles: Vec<[u32; 3]>,
    bvh: Bvh,
    /// Every edge joins exactly two triangles: the mesh bounds a solid.
    closed: bool,
}

/// Why arrays do not make a mesh.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshError {
    NoTriangles,
    IndexOutOfRange {
        triangle: usize,
        index: u32,
        vertices: usize,
    },
    NonFinitePosition(usize),
    CountMismatch {
        what: &'static str,
        found: usize,
        vertices: usize,
    },
}

impl std::fmt::Display for MeshError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MeshError::NoTriangles => write!(f, "the mesh has no triangles"),
            MeshError::IndexOutOfRange {
                triangle,
                index,
                vertices,
            } => write!(
                f,
                "triangle {triangle} refers to vertex {index}, but there are only {vertices} vertices"
            ),
            MeshError::NonFinitePosition(i) => write!(f, "vertex {i} is not a finite point"),
            MeshError::CountMismatch {
                what,
                found,
                vertices,
            } => write!(f, "{found} {what} for {vertices} vertices: give one per vertex"),
        }
    }
}

impl TriangleMesh {
    pub fn new(
        positions: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
        normals: Vec<Vec3>,
        uvs: Vec<[f64; 2]>,
    ) -> Result<TriangleMesh, MeshError> {
        if triangles.is_empty() {
            return Err(MeshError::NoTriangles);
        }
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(MeshError::NonFinitePosition(i));
        }
        for (what, found) in [("normals", normals.len()), ("uvs", uvs.len())] {
            if found != 0 && found != positions.len() {
                return Err(MeshError::CountMismatch {
                    what,
                    found,
                    vertices: positions.len(),
                });
            }
        }
        for (triangle, tri) in triangles.iter().enumerate() {
            if let Some(&index) = tri.iter().find(|&&i| i as usize >= positions.len()) {
                return Err(MeshError::IndexOutOfRange {
                    triangle,
                    index,
                    vertices: positions.len(),
                });
            }
        }
        let bounds: Vec<Bounds3> = triangles
            .iter()
            .map(|t| Bounds3::from_points(t.iter().map(|&i| positions[i as usize])))
            .collect();
        let bvh = Bvh::build(&bounds);
        let closed = is_closed(&positions, &triangles);
        Ok(TriangleMesh {
            positions,
            normals,
            uvs,
            triangles,
            bvh,
            closed,
        })
    }

    pub fn is_closed(&self) -> bool {
        self.closed
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// Per-vertex shading normals; empty when the mesh is flat-shaded.
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }

    /// Per-vertex texture coordinates; empty when the mesh has none.
    pub fn uvs(&self) -> &[[f64; 2]] {
        &self.uvs
    }

    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    pub fn bounds(&self) -> Bounds3 {
        self.bvh.bounds()
    }

    fn vertices(&self, index: u32) -> [Vec3; 3] {
        self.triangles[index as usize].map(|i| self.positions[i as usize])
    }

    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<HitRecord> {
        self.bvh
            .intersect(ray, t_max, |i, t_max| {
                intersect_triangle(ray, t_max, self.vertices(i)).map(|(t, b1, b2)| HitRecord {
                    t,
                    u: b1,
                    v: b2,
                    part: i,
                })
            })
            .map(|(_, hit)| hit)
    }

    pub fn surface(&self, _ray: &Ray, hit: &HitRecord) -> SurfaceGeometry {
        let [p0, p1, p2] = self.vertices(hit.part);
        let (b1, b2) = (hit.u, hit.v);
        let b0 = 1.0 - b1 - b2;
        let p = p0 * b0 + p1 * b1 + p2 * b2;
        let p_error = ((p0 * b0).abs() + (p1 * b1).abs() + (p2 * b2).abs()) * gamma(7);
        let mut n = (p1 - p0).cross(p2 - p0).normalized();
        let idx = self.triangles[hit.part as usize];
        let shading_n = if self.normals.is_empty() {
            n
        } else {
            let [n0, n1, n2] = idx.map(|i| self.normals[i as usize]);
            let ns = (n0 * b0 + n1 * b1 + n2 * b2).normalized();
            if ns.length_squared() == 0.0 {
                n
            } else {
                // The vertex normals say which side is outside.
                n = n.face_forward(ns);
                ns
            }
        };
        let uv = if self.uvs.is_empty() {
            [b1, b2]
        } else {
            let [t0, t1, t2] = idx.map(|i| self.uvs[i as usize]);
            [
                t0[0] * b0 + t1[0] * b1 + t2[0] * b2,
                t0[1] * b0 + t1[1] * b1 + t2[1] * b2,
            ]
        };
        SurfaceGeometry {
            p,
            p_error,
            n,
            shading_n,
            uv,
        }
    }
}

/// Whether every edge is shared by exactly two triangles. Vertices are matched by position,
/// since file formats split a corner into several vertices where normals or uvs differ.
fn is_closed(positions: &[Vec3], triangles: &[[u32; 3]]) -> bool {
    use std::collections::HashMap;
    let mut canonical: HashMap<[u64; 3], u32> = HashMap::new();
    let ids: Vec<u32> = positions
        .iter()
        .map(|p| {
            let next = canonical.len() as u32;
            *canonical
                .entry([p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
                .or_insert(next)
        })
        .collect();
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    for t in triangles {
        let v = t.map(|i| ids[i as usize]);
        for (a, b) in [(v[0], v[1]), (v[1], v[2]), (v[2], v[0])] {
            *edges.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    edges.values().all(|&n| n == 2)
}

/// a·b − c·d with one rounding error's worth of accuracy (Kahan's algorithm with FMA).
fn difference_of_products(a: f64, b: f64, c: f64, d: f64) -> f64 {
    let cd = c * d;
    let err = (-c).mul_add(d, cd);
    a.mul_add(b, -cd) + err
}

/// The watertight test. Returns (t, b1, b2) with the hit at b0·p0 + b1·p1 + b2·p2.
pub fn intersect_triangle(
    ray: &Ray,
    t_max: f64,
    [p0, p1, p2]: [Vec3; 3],
) -> Option<(f64, f64, f64)> {
    // Translate to the ray origin, permute so z is the direction's largest axis, then shear
    // so the ray runs along +z: the test becomes a 2-D edge-function test at the origin.
    let d = ray.direction;
    let kz = d.max_abs_axis();
    let kx = (kz + 1) % 3;
    let ky = (kx + 1) % 3;
    let permute = |v: Vec3| Vec3::new(v[kx], v[ky], v[kz]);
    let d = permute(d);
    let (mut a, mut b, mut c) = (
        permute(p0 - ray.origin),
        permute(p1 - ray.origin),
        permute(p2 - ray.origin),
    );
    let (sx, sy, sz) = (-d.x / d.z, -d.y / d.z, 1.0 / d.z);
    for p in [&mut a, &mut b, &mut c] {
        p.x += sx * p.z;
        p.y += sy * p.z;
    }
    let e0 = difference_of_products(b.x, c.y, b.y, c.x);
    let e1 = difference_of_products(c.x, a.y, c.y, a.x);
    let e2 = difference_of_products(a.x, b.y, a.y, b.x);
    if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
        return None;
    }
    let det = e0 + e1 + e2;
    if det == 0.0 {
        return None;
    }
    a.z *= sz;
    b.z *= sz;
    c.z *= sz;
    let t_scaled = e0 * a.z + e1 * b.z + e2 * c.z;
    if det < 0.0 && (t_scaled >= 0.0 || t_scaled < t_max * det) {
        return None;
    }
    if det > 0.0 && (t_scaled <= 0.0 || t_scaled > t_max * det) {
        return None;
    }
    let inv_det = 1.0 / det;
    let t = t_scaled * inv_det;
    // Is t conservatively greater than zero? (pbrt-v4 §6.8.4)
    let max_z = a.z.abs().max(b.z.abs()).max(c.z.abs());
    let max_x = a.x.abs().max(b.x.abs()).max(c.x.abs());
    let max_y = a.y.abs().max(b.y.abs()).max(c.y.abs());
    let delta_z = gamma(3) * max_z;
    let delta_x = gamma(5) * (max_x + max_z);
    let delta_y = gamma(5) * (max_y + max_z);
    let delta_e = 2.0 * (gamma(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
    let max_e = e0.abs().max(e1.abs()).max(e2.abs());
    let delta_t =
        3.0 * (gamma(3) * max_e * max_z + delta_e * max_z + delta_z * max_e) * inv_det.abs();
    if t <= delta_t {
        return None;
    }
    Some((t, e1 * inv_det, e2 * inv_det))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn barycentrics_and_distance() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let ray = Ray::new(Vec3::new(0.25, 0.5, 2.0), -Vec3::Z);
        let (t, b1, b2) = intersect_triangle(&ray, 1e9, tri).unwrap();
        assert!((t - 2.0).abs() < 1e-15);
        assert!((b1 - 0.25).abs() < 1e-15 && (b2 - 0.5).abs() < 1e-15);
        let miss = Ray::new(Vec3::new(0.75, 0.5, 2.0), -Vec3::Z);
        assert!(intersect_triangle(&miss, 1e9, tri).is_none());
    }

    #[test]
    fn shared_edge_is_watertight() {
        // Two triangles sharing the diagonal of a square: a ray exactly through the diagonal
        // must hit at least one of them.
        let (a, b, c, d) = (Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y);
        for i in 0..=100 {
            let s = i as f64 / 100.0;
            let ray = Ray::new(Vec3::new(s, s, 1.0), Vec3::new(1e-3, -2e-3, -1.0));
            let hit1 = intersect_triangle(&ray, 1e9, [a, b, c]);
            let hit2 = intersect_triangle(&ray, 1e9, [a, c, d]);
            if (0.01..=0.99).contains(&s) {
                assert!(hit1.is_some() || hit2.is_some(), "gap at s = {s}");
            }
        }
    }

    #[test]
    fn mesh_normals_and_validation() {
        let mesh = TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            vec![[0, 1, 2]],
            vec![],
            vec![],
        )
        .unwrap();
        let ray = Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z);
        let hit = mesh.intersect(&ray, 1e9).unwrap();
        assert_eq!(mesh.surface(&ray, &hit).n, Vec3::Z);
        assert!(!mesh.is_closed());
        let tetrahedron = TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
            vec![],
            vec![],
        )
        .unwrap();
        assert!(tetrahedron.is_closed());
        assert_eq!(
            TriangleMesh::new(vec![Vec3::ZERO], vec![[0, 1, 2]], vec![], vec![]).unwrap_err(),
            MeshError::IndexOutOfRange {
                triangle: 0,
                index: 1,
                vertices: 1
            }
        );
    }
}
