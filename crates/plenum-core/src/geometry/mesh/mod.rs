//! Triangle meshes with their own acceleration structure, intersected by the watertight
//! ray–triangle test of Woop, Benthin and Wald (JCGT 2013): no ray slips through a shared
//! edge or vertex. Corners are stored in f32, like Embree and pbrt, and four triangles are
//! tested at once in f32 SIMD; the rare hit exactly on an edge is settled in f64. Error
//! bounds follow pbrt-v4 §6.8.4.
//!
//! The corners are stored four triangles to a block, in the lanes the SIMD test loads, as
//! Embree's precomputed leaves are: each BVH leaf is a run of whole blocks, read without an
//! index, stored right after the node that names it. Vertex indices are kept only where
//! something is given per vertex (normals, uvs, or data the caller keeps, such as a scene's
//! per-vertex materials).
//!
//! Here the mesh is made and kept; `search` walks a ray through its blocks, and
//! `watertight` holds the test itself.

mod search;
#[cfg(test)]
mod tests;
mod watertight;

pub use watertight::intersect_triangle;

use super::{HitRecord, SurfaceGeometry};
use crate::accel::pages::LargeArray;
use crate::accel::ray_f32::gamma_f32;
use crate::accel::{bytes_of, Accel, AccelKind, LeafSize, SahCost, EMBED_LIMIT, EMBED_UNIT, PAD};
use crate::math::{Bounds3, Ray, Vec3};

/// Four triangles per block, up to two blocks per BVH leaf, tested at once with AVX: the
/// call and the first block cost a node visit and a quarter, the second block a quarter
/// more (close to their instructions, and the fewest per ray among the costs tried; see
/// docs/acceleration.md).
const LEAF: LeafSize = LeafSize {
    max_leaf: 8,
    block: 4,
    leaf_cost: 1.25,
    block_cost: 0.25,
};

/// Triangles per block.
const LANES: usize = 4;

/// Four triangles' corners in f32, `[corner][axis][lane]`: the lanes the SIMD test loads;
/// and where each lane's triangle was in the list the mesh was made from, or [`PAD`].
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
struct Block {
    corners: [[[f32; LANES]; 3]; 3],
    source: [u32; LANES],
}

impl Block {
    /// The corners of the triangle in `lane`.
    fn corners(&self, lane: usize) -> Corners {
        [0, 1, 2].map(|k| [0, 1, 2].map(|a| self.corners[k][a][lane]))
    }
}

/// A block's size in the units in which its place is counted: a stored triangle, a *part*
/// ([`HitRecord::part`]), is its block's place (its offset from the first block's place, in
/// [`EMBED_UNIT`]s) times [`LANES`] plus its lane.
const BLOCK_UNITS: usize = std::mem::size_of::<Block>() / EMBED_UNIT;

/// A triangle's corners in f32, `[corner][axis]`.
type Corners = [[f32; 3]; 3];

/// A corner widened to f64, exactly.
fn widened(p: [f32; 3]) -> Vec3 {
    Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
}

#[derive(Clone, Debug)]
pub struct TriangleMesh {
    /// The triangles' corners in the structure's order, four to a block: the mesh's only
    /// copy of its positions (shading widens them to f64, exactly). A grid or an octree
    /// holds a triangle once in each of its cells. Empty with a BVH, which holds the blocks
    /// among its nodes ([`crate::accel::Bvh::embed_blocks`]). On huge pages where there are
    /// many (see [`crate::accel::pages`]).
    blocks: LargeArray<Block>,
    /// Per triangle of the list the mesh was made from, its vertex indices where
    /// `keeps_indices`; else empty.
    indices: Vec<[u32; 3]>,
    /// The vertex indices the mesh was made with are kept (for normals, uvs, or the caller).
    keeps_indices: bool,
    /// Per-vertex shading normals, or empty for flat shading.
    normals: Vec<Vec3>,
    /// Per-vertex texture coordinates, or empty.
    uvs: Vec<[f64; 2]>,
    /// Without per-vertex uvs, the (u, v) of every triangle's corners, in its order; `None`:
    /// the barycentric coordinates (b1, b2).
    corner_uvs: Option<[[f64; 2]; 3]>,
    /// Per-vertex tangents (xyz) and the bitangent's sign (w), as glTF gives them; or empty.
    tangents: Vec<[f64; 4]>,
    vertex_count: usize,
    triangle_count: usize,
    accel: Accel,
    /// Where a BVH holds every triangle in one leaf (a mesh of up to `LEAF.max_leaf`
    /// triangles): its run's place among the nodes and its count. Such a mesh is searched
    /// by that leaf's test alone, without the root's boxes, which the scene's structure
    /// has already narrowed down to this mesh.
    single_leaf: Option<(usize, usize)>,
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
    /// A mesh of `triangles` over `positions`, with per-vertex `normals` and `uvs` or none.
    /// Its triangles are in no structure yet (`AccelKind::None`, tested one by one): a
    /// scene gives each mesh the structure its render asks for when it is built, so no
    /// structure is built twice. Outside a scene, [`TriangleMesh::set_accel`] builds one.
    pub fn new(
        positions: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
        normals: Vec<Vec3>,
        uvs: Vec<[f64; 2]>,
    ) -> Result<TriangleMesh, MeshError> {
        let keep_indices = !normals.is_empty() || !uvs.is_empty();
        TriangleMesh::make(positions, triangles, normals, uvs, keep_indices)
    }

    /// [`TriangleMesh::new`] keeping the vertex indices whatever else is given, for data per
    /// vertex that the caller keeps ([`TriangleMesh::vertex_indices`]).
    pub fn new_keeping_indices(
        positions: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
        normals: Vec<Vec3>,
        uvs: Vec<[f64; 2]>,
    ) -> Result<TriangleMesh, MeshError> {
        TriangleMesh::make(positions, triangles, normals, uvs, true)
    }

    fn make(
        positions: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
        normals: Vec<Vec3>,
        uvs: Vec<[f64; 2]>,
        keep_indices: bool,
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
        let positions: Vec<[f32; 3]> = positions
            .iter()
            .map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .collect();
        if let Some(i) = positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(MeshError::NonFinitePosition(i));
        }
        let closed = is_closed(&positions, &triangles);
        let corners: Vec<Corners> = triangles
            .iter()
            .map(|t| t.map(|i| positions[i as usize]))
            .collect();
        let mut mesh = TriangleMesh {
            blocks: LargeArray::default(),
            indices: Vec::new(),
            keeps_indices: keep_indices,
            normals,
            uvs,
            corner_uvs: None,
            tangents: Vec::new(),
            vertex_count: positions.len(),
            triangle_count: triangles.len(),
            accel: Accel::default(),
            single_leaf: None,
            bounds: Bounds3::from_points(positions.iter().copied().map(widened)),
            closed,
        };
        let indices = if keep_indices { triangles } else { Vec::new() };
        mesh.store(&corners, &indices, AccelKind::None, EMBED_LIMIT);
        Ok(mesh)
    }

    /// Whether its structure had to bound its cells' references (see `Accel::capped`).
    pub fn accel_capped(&self) -> bool {
        self.accel.capped()
    }

    /// Which structure holds its triangles.
    pub fn accel_kind(&self) -> AccelKind {
        self.accel.kind()
    }

    /// The mesh with every triangle's corners at (u, v) `corners` where it has no uvs per
    /// vertex, as some formats say (pbrt-v4: (0, 0), (1, 0), (1, 1)); by default the
    /// barycentric coordinates, (0, 0), (1, 0), (0, 1).
    pub fn with_corner_uvs(mut self, corners: [[f64; 2]; 3]) -> TriangleMesh {
        self.corner_uvs = Some(corners);
        self
    }

    /// The mesh with per-vertex `tangents` (xyz, and w the sign of the bitangent
    /// n × t, glTF's `TANGENT`), which then give normal maps their frame. The mesh must
    /// keep its vertex indices (it has normals or uvs).
    pub fn with_tangents(mut self, tangents: Vec<[f64; 4]>) -> Result<TriangleMesh, MeshError> {
        if tangents.len() != self.vertex_count || !self.keeps_indices {
            return Err(MeshError::CountMismatch {
                what: "tangents",
                found: tangents.len(),
                vertices: self.vertex_count,
            });
        }
        self.tangents = tangents;
        Ok(self)
    }

    /// The tangent and bitangent at a hit, interpolated from the vertices' tangents (the
    /// bitangent n × t times the sign w, n the shading normal); `None` without tangents.
    pub fn tangent_frame(&self, hit: &HitRecord) -> Option<[Vec3; 2]> {
        if self.tangents.is_empty() {
            return None;
        }
        let idx = self.vertex_indices(hit.part)?;
        let weights = [1.0 - hit.u - hit.v, hit.u, hit.v];
        let (mut t, mut w) = (Vec3::ZERO, 0.0);
        for (i, b) in idx.iter().zip(weights) {
            let [x, y, z, s] = self.tangents[*i as usize];
            t = t + Vec3::new(x, y, z) * b;
            w += s * b;
        }
        let n = if self.normals.is_empty() {
            let [p0, p1, p2] = self.triangle(hit.part);
            (p1 - p0).cross(p2 - p0)
        } else {
            idx.iter()
                .zip(weights)
                .fold(Vec3::ZERO, |a, (i, b)| a + self.normals[*i as usize] * b)
        };
        let sign = if w < 0.0 { -1.0 } else { 1.0 };
        Some([t, n.normalized().cross(t) * sign])
    }

    /// The mesh with its triangles in a `kind` structure instead.
    pub fn with_accel(&self, kind: AccelKind) -> TriangleMesh {
        self.rebuilt(kind, EMBED_LIMIT)
    }

    /// [`TriangleMesh::with_accel`], a BVH holding the blocks among its nodes only if all
    /// comes to at most `embed_limit` bytes (see [`crate::accel::Bvh::embed_blocks`]).
    fn rebuilt(&self, kind: AccelKind, embed_limit: usize) -> TriangleMesh {
        let (corners, indices) = self.in_source_order();
        let mut mesh = TriangleMesh {
            blocks: LargeArray::default(),
            indices: Vec::new(),
            normals: self.normals.clone(),
            uvs: self.uvs.clone(),
            tangents: self.tangents.clone(),
            accel: Accel::default(),
            ..*self
        };
        mesh.store(&corners, &indices, kind, embed_limit);
        mesh
    }

    /// Rebuilds the triangles' structure as a `kind` one. A BVH reorders the triangles to
    /// its leaf order (see [`TriangleMesh::source_triangle`]).
    pub fn set_accel(&mut self, kind: AccelKind) {
        let (corners, indices) = self.in_source_order();
        self.store(&corners, &indices, kind, EMBED_LIMIT);
    }

    /// Builds a `kind` structure over triangles given in the order the mesh was made from
    /// (with their vertex indices, or none), and stores them in blocks in its order: every
    /// BVH leaf, grid cell or octree leaf a run of whole blocks.
    fn store(
        &mut self,
        corners: &[Corners],
        indices: &[[u32; 3]],
        kind: AccelKind,
        embed_limit: usize,
    ) {
        let bounds: Vec<Bounds3> = corners
            .iter()
            .map(|c| Bounds3::from_points(c.map(widened)))
            .collect();
        // Cells take a triangle only where it passes through them, not wherever its box
        // does: fewer triangles per cell, and more cells left empty.
        let reaches =
            |i: u32, cell: &Bounds3| cell.meets_triangle(corners[i as usize].map(widened));
        let mut accel = Accel::build_with(kind, &bounds, LEAF, Some(&reaches));
        let mut order = match &mut accel {
            Accel::Bvh(bvh) => {
                let mut order = bvh.take_padded_order(LANES);
                // Every triangle has a box, so every one is in the order; but keep any left
                // out, after the leaves.
                let mut listed = vec![false; corners.len()];
                order
                    .iter()
                    .filter(|&&s| s != PAD)
                    .for_each(|&s| listed[s as usize] = true);
                order.extend((0..corners.len() as u32).filter(|&s| !listed[s as usize]));
                order
            }
            Accel::Grid(grid) => grid.take_padded_runs(LANES),
            Accel::Octree(octree) => octree.take_padded_runs(LANES),
            // Brute force names the triangles one by one, as given.
            Accel::None(_) => (0..corners.len() as u32).collect(),
        };
        order.resize(order.len().next_multiple_of(LANES), PAD);
        let blocks: Vec<Block> = order
            .chunks(LANES)
            .map(|slots| {
                // A padding lane's corners are NaN: every comparison fails, so no ray hits it.
                let mut block = Block {
                    corners: [[[f32::NAN; LANES]; 3]; 3],
                    source: [PAD; LANES],
                };
                for (lane, &s) in slots.iter().enumerate().filter(|(_, &s)| s != PAD) {
                    for (k, corner) in corners[s as usize].iter().enumerate() {
                        for (a, &v) in corner.iter().enumerate() {
                            block.corners[k][a][lane] = v;
                        }
                    }
                    block.source[lane] = s;
                }
                block
            })
            .collect();
        // Beside a BVH's nodes, unless that would take it past what its references reach
        // (some 40 million triangles): then in an array of their own, as for a grid.
        let embedded = match &mut accel {
            Accel::Bvh(bvh) => bvh.embed_blocks(&blocks, LANES, embed_limit),
            _ => false,
        };
        self.single_leaf = match &accel {
            Accel::Bvh(bvh) if embedded => match bvh.embedded_leaves()[..] {
                [(place, count)] if count <= LEAF.max_leaf => Some((place, count)),
                _ => None,
            },
            _ => None,
        };
        self.blocks = if embedded {
            LargeArray::default()
        } else {
            blocks.into()
        };
        self.indices = if self.keeps_indices {
            indices.to_vec()
        } else {
            Vec::new()
        };
        self.accel = accel;
    }

    /// The triangles' corners, and the vertex indices the mesh was made with where it keeps
    /// them (else none), in the order the mesh was made from.
    fn in_source_order(&self) -> (Vec<Corners>, Vec<[u32; 3]>) {
        let mut corners = vec![[[0.0; 3]; 3]; self.triangle_count];
        for (part, s) in self.stored_parts() {
            corners[s as usize] = self.corners_f32(part);
        }
        // Kept in that order already (or empty).
        (corners, self.indices.clone())
    }

    /// Bytes the mesh occupies: corners, indices, attributes and the acceleration structure.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<TriangleMesh>()
            + self.blocks.len() * std::mem::size_of::<Block>()
            + self.indices.len() * std::mem::size_of::<[u32; 3]>()
            + self.normals.len() * std::mem::size_of::<Vec3>()
            + self.uvs.len() * std::mem::size_of::<[f64; 2]>()
            + self.tangents.len() * std::mem::size_of::<[f64; 4]>()
            + self.accel.memory_bytes()
    }

    /// The BVH's expected cost per ray, in blocks of four triangles; None for another
    /// structure.
    pub fn sah_cost(&self) -> Option<SahCost> {
        match &self.accel {
            Accel::Bvh(bvh) => Some(bvh.sah_cost(LANES)),
            _ => None,
        }
    }

    pub fn is_closed(&self) -> bool {
        self.closed
    }

    pub fn triangle_count(&self) -> usize {
        self.triangle_count
    }

    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// Per-vertex shading normals; empty when the mesh is flat-shaded.
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }

    /// Per-vertex texture coordinates; empty when the mesh has none.
    pub fn uvs(&self) -> &[[f64; 2]] {
        &self.uvs
    }

    /// The stored triangles, each once, as a part hits name it by ([`HitRecord::part`]) and
    /// its corners.
    pub fn triangles(&self) -> impl Iterator<Item = (u32, [Vec3; 3])> + '_ {
        // A grid or an octree stores a triangle in each of its cells: the first stands.
        let mut seen = vec![false; self.triangle_count];
        self.stored_parts()
            .filter(move |&(_, s)| !std::mem::replace(&mut seen[s as usize], true))
            .map(|(part, _)| (part, self.triangle(part)))
    }

    /// Each triangle once with its part, wound so that its corners' cross product points the
    /// way a hit on it reports its normal: by the winding, or where the mesh has vertex
    /// normals, to their side (as [`TriangleMesh::surface`] turns it). What an emitter
    /// samples.
    pub fn outward_triangles(&self) -> impl Iterator<Item = (u32, [Vec3; 3])> + '_ {
        self.triangles().map(|(part, [p0, p1, p2])| {
            let normals = self
                .vertex_indices(part)
                .filter(|_| !self.normals.is_empty());
            let shading = normals.map_or(Vec3::ZERO, |idx| {
                idx.iter()
                    .fold(Vec3::ZERO, |a, &i| a + self.normals[i as usize])
            });
            if (p1 - p0).cross(p2 - p0).dot(shading) < 0.0 {
                (part, [p0, p2, p1])
            } else {
                (part, [p0, p1, p2])
            }
        })
    }

    /// Every stored triangle (each copy, in a grid or an octree) with its position in the
    /// list the mesh was made from.
    fn stored_parts(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        let places: Vec<usize> = match &self.accel {
            Accel::Bvh(bvh) if bvh.is_embedded() => bvh
                .embedded_leaves()
                .into_iter()
                .flat_map(|(place, count)| {
                    (0..count.div_ceil(LANES)).map(move |b| place + b * BLOCK_UNITS)
                })
                .collect(),
            _ => (0..self.blocks.len()).map(|b| b * BLOCK_UNITS).collect(),
        };
        places.into_iter().flat_map(move |place| {
            let block = self.block_at(place);
            (0..LANES)
                .filter(move |&lane| block.source[lane] != PAD)
                .map(move |lane| ((place * LANES + lane) as u32, block.source[lane]))
        })
    }

    /// The stored blocks, as bytes: the BVH's nodes among them, or the blocks alone.
    fn block_bytes(&self) -> &[u8] {
        match &self.accel {
            Accel::Bvh(bvh) if bvh.is_embedded() => bvh.embedded(),
            _ => bytes_of(&self.blocks),
        }
    }

    /// The block at `place` (see [`BLOCK_UNITS`]). Panics if none is there.
    fn block_at(&self, place: usize) -> &Block {
        let bytes = &self.block_bytes()[place * EMBED_UNIT..][..std::mem::size_of::<Block>()];
        // SAFETY: in bounds, at a multiple of EMBED_UNIT from a base aligned to a block,
        // and any bytes are a block (plain f32 and u32).
        unsafe { &*(bytes.as_ptr() as *const Block) }
    }

    /// The corners of stored triangle `part`.
    pub fn triangle(&self, part: u32) -> [Vec3; 3] {
        self.corners_f32(part).map(widened)
    }

    /// The barycentric coordinates [b1, b2] (the weights of the second and third corners)
    /// of `p` projected onto the plane of stored triangle `part`.
    pub fn barycentrics(&self, part: u32, p: Vec3) -> [f64; 2] {
        let [p0, p1, p2] = self.triangle(part);
        let (e1, e2, d) = (p1 - p0, p2 - p0, p - p0);
        let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
        let (d1, d2) = (d.dot(e1), d.dot(e2));
        let det = d11 * d22 - d12 * d12;
        if det == 0.0 {
            return [0.0, 0.0];
        }
        [(d22 * d1 - d12 * d2) / det, (d11 * d2 - d12 * d1) / det]
    }

    fn corners_f32(&self, part: u32) -> Corners {
        let (place, lane) = (part as usize / LANES, part as usize % LANES);
        self.block_at(place).corners(lane)
    }

    /// The vertex indices of stored triangle `part`, where the mesh keeps them (it has
    /// normals or uvs, or was made by [`TriangleMesh::new_keeping_indices`]).
    pub fn vertex_indices(&self, part: u32) -> Option<[u32; 3]> {
        self.keeps_indices
            .then(|| self.indices[self.source_triangle(part) as usize])
    }

    /// Where stored triangle `part` was in the list the mesh was made from.
    pub fn source_triangle(&self, part: u32) -> u32 {
        let (place, lane) = (part as usize / LANES, part as usize % LANES);
        self.block_at(place).source[lane]
    }

    /// The mesh as positions and vertex indices, the triangles in the order it was made
    /// from. Where the mesh keeps its indices they are the ones it was made with (a vertex
    /// no triangle uses comes back at the origin); else the vertices are the distinct corner
    /// positions, numbered as the triangles first use them.
    pub fn indexed(&self) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let (corners, indices) = self.in_source_order();
        let (vertices, triangles) = index_corners(&corners, &indices, self.vertex_count);
        (vertices.iter().copied().map(widened).collect(), triangles)
    }

    pub fn bounds(&self) -> Bounds3 {
        self.bounds
    }

    pub fn surface(&self, _ray: &Ray, hit: &HitRecord) -> SurfaceGeometry {
        let [p0, p1, p2] = self.triangle(hit.part);
        let (b1, b2) = (hit.u, hit.v);
        let b0 = 1.0 - b1 - b2;
        let p = p0 * b0 + p1 * b1 + p2 * b2;
        // Bounded as if computed in f32: a ray leaving the point is then tested in f32 from
        // an origin rounded to f32, and must stay clear of the triangle it leaves.
        let p_error = ((p0 * b0).abs() + (p1 * b1).abs() + (p2 * b2).abs()) * gamma_f32(7) as f64;
        let mut n = (p1 - p0).cross(p2 - p0).normalized();
        // Kept wherever there are normals or uvs.
        let idx = self.vertex_indices(hit.part).unwrap_or_default();
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
            match self.corner_uvs {
                None => [b1, b2],
                Some([t0, t1, t2]) => [
                    t0[0] * b0 + t1[0] * b1 + t2[0] * b2,
                    t0[1] * b0 + t1[1] * b1 + t2[1] * b2,
                ],
            }
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

    /// ∂p/∂u and ∂p/∂v across stored triangle `hit.part`, from its corners' uvs (pbrt-v4's
    /// solution of the 2×2 system); without uvs, the map of `surface`, u and v the second
    /// and third barycentric coordinates. Zero where the uvs are degenerate.
    pub fn uv_derivatives(&self, hit: &HitRecord) -> [Vec3; 2] {
        let [p0, p1, p2] = self.triangle(hit.part);
        let [t0, t1, t2] = match self.vertex_indices(hit.part) {
            Some(idx) if !self.uvs.is_empty() => idx.map(|i| self.uvs[i as usize]),
            _ => match self.corner_uvs {
                None => return [p1 - p0, p2 - p0],
                Some(corners) => corners,
            },
        };
        let (duv02, duv12) = (
            [t0[0] - t2[0], t0[1] - t2[1]],
            [t1[0] - t2[0], t1[1] - t2[1]],
        );
        let (dp02, dp12) = (p0 - p2, p1 - p2);
        let det = duv02[0] * duv12[1] - duv02[1] * duv12[0];
        if det.abs() < 1e-12 {
            return [Vec3::ZERO; 2];
        }
        [
            (dp02 * duv12[1] - dp12 * duv02[1]) / det,
            (dp12 * duv02[0] - dp02 * duv12[0]) / det,
        ]
    }
}

/// Vertices and vertex indices for triangles given by their corners. With the indices the
/// mesh was made with, its `vertex_count` vertices (one no triangle uses is left at the
/// origin); without, the distinct corner positions, numbered as the triangles first use them.
fn index_corners(
    corners: &[Corners],
    indices: &[[u32; 3]],
    vertex_count: usize,
) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    if !indices.is_empty() {
        let mut vertices = vec![[0.0; 3]; vertex_count];
        for (c, t) in corners.iter().zip(indices) {
            for k in 0..3 {
                vertices[t[k] as usize] = c[k];
            }
        }
        return (vertices, indices.to_vec());
    }
    let mut numbers: std::collections::HashMap<[u32; 3], u32> = Default::default();
    let mut vertices = Vec::new();
    let triangles = corners
        .iter()
        .map(|c| {
            c.map(|p| {
                *numbers.entry(p.map(f32::to_bits)).or_insert_with(|| {
                    vertices.push(p);
                    vertices.len() as u32 - 1
                })
            })
        })
        .collect();
    (vertices, triangles)
}

/// Whether every edge is shared by exactly two triangles. Vertices are matched by position,
/// since file formats split a corner into several vertices where normals or uvs differ.
fn is_closed(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> bool {
    use std::collections::HashMap;
    let mut canonical: HashMap<[u32; 3], u32> = HashMap::new();
    let ids: Vec<u32> = positions
        .iter()
        .map(|p| {
            let next = canonical.len() as u32;
            *canonical.entry(p.map(f32::to_bits)).or_insert(next)
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
