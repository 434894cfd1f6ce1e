//! Triangle meshes with their own acceleration structure, intersected by the watertight
//! ray–triangle test of Woop, Benthin and Wald (JCGT 2013): no ray slips through a shared
//! edge or vertex. Vertices are stored in f32, like Embree and pbrt, and four triangles are
//! tested at once in f32 SIMD; the rare hit exactly on an edge is settled in f64. Error
//! bounds follow pbrt-v4 §6.8.4. With a BVH the triangles are kept in its leaf order, so a
//! leaf's triangles lie side by side in memory.

use super::{HitRecord, SurfaceGeometry};
use crate::accel::ray_f32::{gamma_f32, round_up};
use crate::accel::simd::F4;
use crate::accel::{Accel, AccelKind, LeafSize};
use crate::math::{gamma, Bounds3, Ray, Vec3};
use std::ops::Range;

/// Four triangles per SIMD test, up to two tests per BVH leaf.
const LEAF: LeafSize = LeafSize {
    max_leaf: 8,
    block: 4,
};

#[derive(Clone, Debug)]
pub struct TriangleMesh {
    /// Positions in f32, the geometry the SIMD test sees, padded to four lanes; they are
    /// the mesh's only copy (shading widens them to f64, exactly).
    packed: Vec<[f32; 4]>,
    /// Per-vertex shading normals, or empty for flat shading.
    normals: Vec<Vec3>,
    /// Per-vertex texture coordinates, or empty.
    uvs: Vec<[f64; 2]>,
    /// Stored in the BVH's leaf order, so a leaf is a run of consecutive triangles.
    triangles: Vec<[u32; 3]>,
    /// The position of each stored triangle in the list the mesh was made from.
    source: Vec<u32>,
    accel: Accel,
    bounds: Bounds3,
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
        // Each coordinate rounded to f32, as it is stored.
        let positions: Vec<Vec3> = positions
            .iter()
            .map(|p| Vec3::new(p.x as f32 as f64, p.y as f32 as f64, p.z as f32 as f64))
            .collect();
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(MeshError::NonFinitePosition(i));
        }
        let packed = positions
            .iter()
            .map(|p| [p.x as f32, p.y as f32, p.z as f32, 0.0])
            .collect();
        let closed = is_closed(&positions, &triangles);
        let mut mesh = TriangleMesh {
            bounds: Bounds3::from_points(positions.iter().copied()),
            packed,
            normals,
            uvs,
            source: (0..triangles.len() as u32).collect(),
            triangles,
            accel: Accel::default(),
            closed,
        };
        mesh.set_accel(AccelKind::Bvh);
        Ok(mesh)
    }

    /// The mesh with its triangles in a `kind` structure instead.
    pub fn with_accel(&self, kind: AccelKind) -> TriangleMesh {
        let mut mesh = self.clone_without_accel();
        mesh.set_accel(kind);
        mesh
    }

    /// Rebuilds the triangles' structure as a `kind` one. A BVH reorders the triangles to
    /// its leaf order (see [`TriangleMesh::source_triangle`]).
    pub fn set_accel(&mut self, kind: AccelKind) {
        self.accel = Accel::build(kind, &self.triangle_bounds(), LEAF);
        if let Accel::Bvh(bvh) = &mut self.accel {
            let mut order = bvh.take_order();
            // Every triangle has a box, so every one is in the order; but keep any left out.
            if order.len() < self.triangles.len() {
                let mut listed = vec![false; self.triangles.len()];
                order.iter().for_each(|&i| listed[i as usize] = true);
                order.extend((0..self.triangles.len() as u32).filter(|&i| !listed[i as usize]));
            }
            self.triangles = order.iter().map(|&i| self.triangles[i as usize]).collect();
            self.source = order.iter().map(|&i| self.source[i as usize]).collect();
            self.number_vertices_by_first_use();
        }
    }

    /// Renumbers the vertices in the order the triangles first use them, so that the corners
    /// of a leaf's triangles share a few cache lines instead of scattering over the mesh.
    fn number_vertices_by_first_use(&mut self) {
        const UNSEEN: u32 = u32::MAX;
        let mut new_index = vec![UNSEEN; self.packed.len()];
        let mut old_index = Vec::with_capacity(self.packed.len());
        for v in self.triangles.iter_mut().flatten() {
            if new_index[*v as usize] == UNSEEN {
                new_index[*v as usize] = old_index.len() as u32;
                old_index.push(*v);
            }
            *v = new_index[*v as usize];
        }
        // Vertices no triangle uses keep their place after the others.
        old_index
            .extend((0..self.packed.len() as u32).filter(|&v| new_index[v as usize] == UNSEEN));
        fn permute<T: Copy>(values: &mut Vec<T>, old_index: &[u32]) {
            if !values.is_empty() {
                *values = old_index.iter().map(|&v| values[v as usize]).collect();
            }
        }
        permute(&mut self.packed, &old_index);
        permute(&mut self.normals, &old_index);
        permute(&mut self.uvs, &old_index);
    }

    fn clone_without_accel(&self) -> TriangleMesh {
        TriangleMesh {
            packed: self.packed.clone(),
            normals: self.normals.clone(),
            uvs: self.uvs.clone(),
            triangles: self.triangles.clone(),
            source: self.source.clone(),
            accel: Accel::default(),
            bounds: self.bounds,
            closed: self.closed,
        }
    }

    fn triangle_bounds(&self) -> Vec<Bounds3> {
        self.triangles
            .iter()
            .map(|t| Bounds3::from_points(t.iter().map(|&i| self.position(i))))
            .collect()
    }

    /// Bytes the mesh occupies: vertices, indices, attributes and the acceleration structure.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<TriangleMesh>()
            + self.packed.len() * std::mem::size_of::<[f32; 4]>()
            + self.normals.len() * std::mem::size_of::<Vec3>()
            + self.uvs.len() * std::mem::size_of::<[f64; 2]>()
            + self.triangles.len() * std::mem::size_of::<[u32; 3]>()
            + self.source.len() * std::mem::size_of::<u32>()
            + self.accel.memory_bytes()
    }

    pub fn is_closed(&self) -> bool {
        self.closed
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    pub fn vertex_count(&self) -> usize {
        self.packed.len()
    }

    /// The position of vertex `vertex`.
    pub fn position(&self, vertex: u32) -> Vec3 {
        let [x, y, z, _] = self.packed[vertex as usize];
        Vec3::new(x as f64, y as f64, z as f64)
    }

    /// The positions of all vertices, in the mesh's numbering.
    pub fn positions(&self) -> impl ExactSizeIterator<Item = Vec3> + '_ {
        (0..self.packed.len() as u32).map(|v| self.position(v))
    }

    /// Per-vertex shading normals; empty when the mesh is flat-shaded.
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }

    /// Per-vertex texture coordinates; empty when the mesh has none.
    pub fn uvs(&self) -> &[[f64; 2]] {
        &self.uvs
    }

    /// The triangles, in the order the mesh stores them (a BVH's leaf order), which is the
    /// order hits name them in ([`HitRecord::part`]).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Where stored triangle `part` was in the list the mesh was made from.
    pub fn source_triangle(&self, part: u32) -> u32 {
        self.source[part as usize]
    }

    pub fn bounds(&self) -> Bounds3 {
        self.bounds
    }

    fn vertices(&self, index: u32) -> [Vec3; 3] {
        self.triangles[index as usize].map(|i| self.position(i))
    }

    /// The nearest hit in (0, t_max).
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<HitRecord> {
        // Prepared at the first leaf: most rays that miss never reach one.
        let mut sheared = None;
        let mut best = None;
        self.visit_blocks::<true>(ray, t_max, |ids, count, t_max| {
            let r = sheared.get_or_insert_with(|| ShearedRay::new(ray));
            if let Some(hit) = self.intersect_block(r, ray, ids, count, *t_max) {
                *t_max = hit.t;
                best = Some(hit);
            }
            true
        });
        best
    }

    /// Some hit in (0, t_max), not necessarily the nearest: stops at the first one found.
    pub fn intersect_any(&self, ray: &Ray, t_max: f64) -> Option<HitRecord> {
        let mut sheared = None;
        let mut found = None;
        self.visit_blocks::<false>(ray, t_max, |ids, count, t_max| {
            let r = sheared.get_or_insert_with(|| ShearedRay::new(ray));
            found = self.intersect_block(r, ray, ids, count, *t_max);
            found.is_none()
        });
        found
    }

    /// Hands `test(ids, count, t_max)` blocks of up to four triangles the ray may meet,
    /// roughly nearest first if `NEAREST_FIRST`, until it returns false. Lanes past `count`
    /// repeat the last triangle.
    #[inline(always)]
    fn visit_blocks<const NEAREST_FIRST: bool>(
        &self,
        ray: &Ray,
        t_max: f64,
        mut test: impl FnMut([u32; 4], usize, &mut f64) -> bool,
    ) {
        if let Accel::Bvh(bvh) = &self.accel {
            // Leaves are runs of the stored triangles: no index to read per triangle.
            let visit_run = |run: Range<usize>, t_max: &mut f64| {
                let last = run.end as u32 - 1;
                for base in run.step_by(4).map(|b| b as u32) {
                    let ids = [0, 1, 2, 3].map(|lane| (base + lane).min(last));
                    let count = (last - base + 1).min(4) as usize;
                    if !test(ids, count, t_max) {
                        return false;
                    }
                }
                true
            };
            if NEAREST_FIRST {
                bvh.traverse_runs(ray, t_max, &self.triangles, visit_run);
            } else {
                bvh.traverse_runs_any_order(ray, t_max, &self.triangles, visit_run);
            }
            return;
        }
        // A triangle met again in another cell is simply tested again: no stamps needed.
        self.accel.traverse_repeating(ray, t_max, |items, t_max| {
            for block in items.chunks(4) {
                let last = block.len() - 1;
                let ids = [0, 1, 2, 3].map(|lane| block[lane.min(last)]);
                if !test(ids, block.len(), t_max) {
                    return false;
                }
            }
            true
        });
    }

    /// The corners of four triangles in lanes: `[corner][axis]`.
    #[inline(always)]
    fn corners(&self, ids: [u32; 4]) -> [[F4; 3]; 3] {
        debug_assert!(ids.iter().all(|&i| (i as usize) < self.triangles.len()));
        // SAFETY: ids come from the structure built over these triangles.
        let tri = |lane: usize| unsafe { *self.triangles.get_unchecked(ids[lane] as usize) };
        let (t0, t1, t2, t3) = (tri(0), tri(1), tri(2), tri(3));
        let corner = |k: usize| {
            let p = |t: [u32; 3]| {
                // SAFETY: every index was checked against the vertex count in `new`.
                F4::load(unsafe { self.packed.get_unchecked(t[k] as usize) })
            };
            let [x, y, z, _] = F4::transpose([p(t0), p(t1), p(t2), p(t3)]);
            [x, y, z]
        };
        [corner(0), corner(1), corner(2)]
    }

    /// The nearest hit among up to four triangles, tested together; lanes from `count` on
    /// are ignored.
    #[inline(always)]
    fn intersect_block(
        &self,
        r: &ShearedRay,
        ray: &Ray,
        block: [u32; 4],
        count: usize,
        t_max: f64,
    ) -> Option<HitRecord> {
        let corners = &self.corners(block);
        // One copy of the test per axis the ray runs along, so the permutation is static.
        match r.axes[2] {
            0 => self.intersect_block_along::<0>(r, ray, corners, block, count, t_max),
            1 => self.intersect_block_along::<1>(r, ray, corners, block, count, t_max),
            _ => self.intersect_block_along::<2>(r, ray, corners, block, count, t_max),
        }
    }

    #[inline(always)]
    fn intersect_block_along<const KZ: usize>(
        &self,
        r: &ShearedRay,
        ray: &Ray,
        corners: &[[F4; 3]; 3],
        block: [u32; 4],
        count: usize,
        t_max: f64,
    ) -> Option<HitRecord> {
        let (kx, ky) = ((KZ + 1) % 3, (KZ + 2) % 3);
        let corner = |k: usize| {
            let p = &corners[k];
            let x = p[kx].sub(r.origin[0]);
            let y = p[ky].sub(r.origin[1]);
            let z = p[KZ].sub(r.origin[2]);
            // Shear so the ray is the +z axis.
            [x.add(r.shear[0].mul(z)), y.add(r.shear[1].mul(z)), z]
        };
        let (a, b, c) = (corner(0), corner(1), corner(2));
        let lanes = (1u32 << count) - 1;
        let e0 = b[0].mul(c[1]).sub(b[1].mul(c[0]));
        let e1 = c[0].mul(a[1]).sub(c[1].mul(a[0]));
        let e2 = a[0].mul(b[1]).sub(a[1].mul(b[0]));
        let zero = F4::splat(0.0);
        let negative = e0.lt(zero) | e1.lt(zero) | e2.lt(zero);
        let positive = zero.lt(e0) | zero.lt(e1) | zero.lt(e2);
        let mut inside = !(negative & positive) & lanes;
        if inside == 0 {
            return None;
        }
        // An edge function exactly zero in f32 may be a rounding artefact: settle in f64.
        let on_edge = (e0.eq(zero) | e1.eq(zero) | e2.eq(zero)) & inside;
        inside &= !on_edge;
        let det = e0.add(e1).add(e2);
        let sz = r.shear[2];
        let (az, bz, cz) = (a[2].mul(sz), b[2].mul(sz), c[2].mul(sz));
        let t_scaled = e0.mul(az).add(e1.mul(bz)).add(e2.mul(cz));
        let t = t_scaled.div(det);
        let limit = F4::splat(round_up(t_max));
        inside &= zero.lt(t) & t.lt(limit) & !det.eq(zero);
        let mut best: Option<HitRecord> = None;
        if inside != 0 {
            // Is t conservatively positive? (pbrt-v4 §6.8.4, in f32.)
            let max3 = |p: F4, q: F4, s: F4| p.abs().max(q.abs()).max(s.abs());
            let max_z = max3(az, bz, cz);
            let max_x = max3(a[0], b[0], c[0]);
            let max_y = max3(a[1], b[1], c[1]);
            let delta_z = max_z.mul(F4::splat(gamma_f32(3)));
            let delta_x = max_x.add(max_z).mul(F4::splat(gamma_f32(5)));
            let delta_y = max_y.add(max_z).mul(F4::splat(gamma_f32(5)));
            let delta_e = max_x
                .mul(max_y)
                .mul(F4::splat(gamma_f32(2)))
                .add(delta_y.mul(max_x))
                .add(delta_x.mul(max_y))
                .mul(F4::splat(2.0));
            let max_e = max3(e0, e1, e2);
            let delta_t = max_e
                .mul(max_z)
                .mul(F4::splat(gamma_f32(3)))
                .add(delta_e.mul(max_z))
                .add(delta_z.mul(max_e))
                .mul(F4::splat(3.0))
                .div(det.abs());
            inside &= delta_t.lt(t);
            let (t, e1, e2, det) = (t.to_array(), e1.to_array(), e2.to_array(), det.to_array());
            while inside != 0 {
                let lane = inside.trailing_zeros() as usize;
                inside &= inside - 1;
                if best.is_none_or(|h| (t[lane] as f64) < h.t) {
                    best = Some(HitRecord {
                        t: t[lane] as f64,
                        u: (e1[lane] / det[lane]) as f64,
                        v: (e2[lane] / det[lane]) as f64,
                        part: block[lane],
                    });
                }
            }
        }
        let mut on_edge = on_edge;
        while on_edge != 0 {
            let lane = on_edge.trailing_zeros() as usize;
            on_edge &= on_edge - 1;
            let limit = best.map_or(t_max, |h| h.t);
            if let Some((t, b1, b2)) = intersect_triangle(ray, limit, self.vertices(block[lane])) {
                best = Some(HitRecord {
                    t,
                    u: b1,
                    v: b2,
                    part: block[lane],
                });
            }
        }
        best
    }

    pub fn surface(&self, _ray: &Ray, hit: &HitRecord) -> SurfaceGeometry {
        let [p0, p1, p2] = self.vertices(hit.part);
        let (b1, b2) = (hit.u, hit.v);
        let b0 = 1.0 - b1 - b2;
        let p = p0 * b0 + p1 * b1 + p2 * b2;
        // Bounded as if computed in f32: a ray leaving the point is then tested in f32 from
        // an origin rounded to f32, and must stay clear of the triangle it leaves.
        let p_error = ((p0 * b0).abs() + (p1 * b1).abs() + (p2 * b2).abs()) * gamma_f32(7) as f64;
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

/// A ray prepared for the watertight test: axes permuted so the direction's largest
/// component is z, and the shear that turns the ray into the +z axis (all in f32).
struct ShearedRay {
    axes: [usize; 3],
    origin: [F4; 3],
    shear: [F4; 3],
}

impl ShearedRay {
    #[inline]
    fn new(ray: &Ray) -> ShearedRay {
        // Arrays indexed through a table: a `Vec3` indexed by a variable axis branches.
        const NEXT: [usize; 3] = [1, 2, 0];
        let kz = ray.direction.max_abs_axis();
        let (kx, ky) = (NEXT[kz], NEXT[NEXT[kz]]);
        let (o, d) = (ray.origin, ray.direction);
        let o = [o.x, o.y, o.z].map(|v| v as f32);
        let d = [d.x, d.y, d.z].map(|v| v as f32);
        // The three quotients in one division.
        let [sx, sy, sz, _] = F4::from_array([-d[kx], -d[ky], 1.0, 1.0])
            .div(F4::splat(d[kz]))
            .to_array();
        ShearedRay {
            axes: [kx, ky, kz],
            origin: [kx, ky, kz].map(|a| F4::splat(o[a])),
            shear: [F4::splat(sx), F4::splat(sy), F4::splat(sz)],
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
