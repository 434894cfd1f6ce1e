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

use super::{HitRecord, SurfaceGeometry};
use crate::accel::pages::LargeArray;
use crate::accel::ray_f32::{gamma_f32, round_up_distance};
#[cfg(target_arch = "x86_64")]
use crate::accel::simd::F8;
use crate::accel::simd::{Avx, Lanes, F4};
use crate::accel::{
    bytes_of, Accel, AccelKind, AmongNodes, Coherence, LeafItems, LeafPlaces, LeafSize, SahCost,
    EMBED_LIMIT, EMBED_UNIT, PAD,
};
use crate::math::{gamma, Bounds3, Ray, Vec3};
use std::ops::Range;

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
    vertex_count: usize,
    triangle_count: usize,
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
    /// A mesh of `triangles` over `positions`, with per-vertex `normals` and `uvs` or none.
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
            vertex_count: positions.len(),
            triangle_count: triangles.len(),
            accel: Accel::default(),
            bounds: Bounds3::from_points(positions.iter().copied().map(widened)),
            closed,
        };
        let indices = if keep_indices { triangles } else { Vec::new() };
        mesh.store(&corners, &indices, AccelKind::Bvh, EMBED_LIMIT);
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

    /// Each triangle once, wound so that its corners' cross product points the way a hit
    /// on it reports its normal: by the winding, or where the mesh has vertex normals, to
    /// their side (as [`TriangleMesh::surface`] turns it). What an emitter samples.
    pub fn outward_triangles(&self) -> impl Iterator<Item = [Vec3; 3]> + '_ {
        self.triangles().map(|(part, [p0, p1, p2])| {
            let normals = self
                .vertex_indices(part)
                .filter(|_| !self.normals.is_empty());
            let shading = normals.map_or(Vec3::ZERO, |idx| {
                idx.iter()
                    .fold(Vec3::ZERO, |a, &i| a + self.normals[i as usize])
            });
            if (p1 - p0).cross(p2 - p0).dot(shading) < 0.0 {
                [p0, p2, p1]
            } else {
                [p0, p1, p2]
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

    /// The nearest hit in (0, t_max).
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<HitRecord> {
        self.search::<true>(ray, t_max, Avx::detect(), Coherence::Incoherent)
    }

    /// Some hit in (0, t_max), not necessarily the nearest: stops at the first one found.
    pub fn intersect_any(&self, ray: &Ray, t_max: f64) -> Option<HitRecord> {
        self.intersect_any_as(ray, t_max, Coherence::Incoherent)
    }

    /// [`TriangleMesh::intersect_any`] for a ray that is one of `coherence` rays, which
    /// chooses how a BVH is walked (see [`Coherence`]); the answer is the same.
    pub fn intersect_any_as(
        &self,
        ray: &Ray,
        t_max: f64,
        coherence: Coherence,
    ) -> Option<HitRecord> {
        self.search::<false>(ray, t_max, Avx::detect(), coherence)
    }

    /// The nearest hit if `NEAREST`, else the first found: the structure hands over runs
    /// of slots (roughly nearest first if `NEAREST`), and their blocks are tested, two at a
    /// time with `avx`. `coherence` matters to a BVH's any-hit walk only.
    #[inline(always)]
    fn search<const NEAREST: bool>(
        &self,
        ray: &Ray,
        t_max: f64,
        avx: Option<Avx>,
        coherence: Coherence,
    ) -> Option<HitRecord> {
        let start = |blocks: &[u8]| Search {
            ray,
            sheared: None,
            hit: None,
            avx,
            blocks: blocks.as_ptr(),
        };
        match &self.accel {
            Accel::Bvh(bvh) if bvh.is_embedded() => {
                let mut search = start(bvh.embedded());
                // A leaf's run starts at its first block's place, counted from the start of
                // the nodes' array, where the search counts places from: the closures then
                // hold two references, which travel in registers.
                // SAFETY (both): the place lies within the nodes' array.
                let first = |search: &Search, run: &Range<usize>| unsafe {
                    search.blocks.add(run.start * EMBED_UNIT) as *const Block
                };
                // The instruction set chosen once, not at every leaf.
                #[cfg(target_arch = "x86_64")]
                if let Some(avx) = avx {
                    let state = &mut search;
                    let visit_run = move |run: Range<usize>, t_max: &mut f64| {
                        let (block, count) = (first(state, &run), run.end - run.start);
                        // SAFETY: `avx` says the CPU has AVX.
                        unsafe { self.search_leaf_avx::<NEAREST>(avx, block, count, t_max, state) }
                    };
                    traverse_bvh::<NEAREST>(bvh, ray, t_max, AmongNodes, coherence, visit_run);
                    return search.hit;
                }
                let visit_run = |run: Range<usize>, t_max: &mut f64| {
                    let (block, count) = (first(&search, &run), run.end - run.start);
                    self.search_run_sse::<NEAREST, true>(block, 0..count, t_max, &mut search)
                };
                traverse_bvh::<NEAREST>(bvh, ray, t_max, AmongNodes, coherence, visit_run);
                search.hit
            }
            _ => {
                // Not among nodes: the blocks are the mesh's own.
                let mut search = start(bytes_of(&self.blocks));
                self.search_cells::<NEAREST>(ray, t_max, &mut search);
                search.hit
            }
        }
    }

    /// [`TriangleMesh::search`] through the grid, the octree, brute force or a BVH too large
    /// to hold the blocks among its nodes: apart, so that their walks' state does not weigh
    /// on every BVH search.
    #[inline(never)]
    fn search_cells<const NEAREST: bool>(&self, ray: &Ray, t_max: f64, search: &mut Search) {
        // Their runs are of slots, block after block from the first.
        let visit_run = |run: Range<usize>, t_max: &mut f64| {
            // SAFETY: the runs are of the blocks' slots.
            let first = unsafe { self.blocks.as_ptr().add(run.start / LANES) };
            self.search_run::<NEAREST, true>(first, 0..run.len(), t_max, search)
        };
        match &self.accel {
            Accel::Bvh(bvh) => {
                let items = LeafItems::<{ std::mem::size_of::<Block>() / LANES }>::at(&self.blocks);
                traverse_bvh::<NEAREST>(bvh, ray, t_max, items, Coherence::Incoherent, visit_run);
            }
            Accel::Grid(grid) => grid.traverse_runs(ray, t_max, visit_run),
            Accel::Octree(octree) => octree.traverse_runs(ray, t_max, visit_run),
            Accel::None(brute) => brute.traverse(ray, t_max, |items, t_max| {
                items.iter().all(|&slot| {
                    let (block, lane) = (slot as usize / LANES, slot as usize % LANES);
                    // SAFETY: brute force names the slots of the blocks.
                    let first = unsafe { self.blocks.as_ptr().add(block) };
                    self.search_run::<NEAREST, false>(first, lane..lane + 1, t_max, search)
                })
            }),
        }
    }

    /// Tests a run of lanes of the blocks from `first` on, one after another, read in place:
    /// lowers `t_max` to each nearer hit if `NEAREST`, else returns false at the first. A
    /// structure's run is `PADDED`: it starts at the first block's first lane, and the lanes
    /// of its last block past its end are padding, which misses (NaN corners). Otherwise
    /// (brute force's single slots) lanes outside the run are left out. The loops themselves
    /// (`search_run_sse`, `search_run_avx`) are kept out of the traversal loop: inlined
    /// there, they leave it too few registers.
    #[inline(always)]
    fn search_run<const NEAREST: bool, const PADDED: bool>(
        &self,
        first: *const Block,
        run: Range<usize>,
        t_max: &mut f64,
        search: &mut Search,
    ) -> bool {
        #[cfg(target_arch = "x86_64")]
        if let Some(avx) = search.avx {
            // SAFETY: `avx` says the CPU has AVX.
            return unsafe {
                self.search_run_avx::<NEAREST, PADDED>(avx, first, run, t_max, search)
            };
        }
        self.search_run_sse::<NEAREST, PADDED>(first, run, t_max, search)
    }

    /// Tests a BVH leaf of `count` triangles in the blocks from `first` on, as
    /// [`TriangleMesh::search_run`] does a padded run: a leaf holds at most [`LEAF`]'s
    /// `max_leaf` (the build halves a larger run it cannot split by position), two blocks,
    /// which take one test in 256-bit instructions and no loop: 3 % fewer instructions per
    /// ray than the loop over a run's blocks.
    ///
    /// # Safety
    /// The CPU must support AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    #[inline(never)]
    unsafe fn search_leaf_avx<const NEAREST: bool>(
        &self,
        avx: Avx,
        first: *const Block,
        count: usize,
        t_max: &mut f64,
        search: &mut Search,
    ) -> bool {
        const { assert!(LEAF.max_leaf <= 2 * LANES) };
        debug_assert!(count <= LEAF.max_leaf);
        let pair = count > LANES;
        let lanes = if pair { 0xFF } else { 0xF };
        let avx = Some(avx);
        // SAFETY: a leaf's blocks are stored one after another, and a pair is taken only
        // where the leaf reaches into the second block.
        unsafe {
            match search.axis() {
                0 => self.test_blocks::<0, NEAREST>(avx, first, pair, lanes, t_max, search),
                1 => self.test_blocks::<1, NEAREST>(avx, first, pair, lanes, t_max, search),
                _ => self.test_blocks::<2, NEAREST>(avx, first, pair, lanes, t_max, search),
            }
        }
    }

    /// The leaf loop testing four triangles at a time.
    #[inline(never)]
    fn search_run_sse<const NEAREST: bool, const PADDED: bool>(
        &self,
        first: *const Block,
        run: Range<usize>,
        t_max: &mut f64,
        search: &mut Search,
    ) -> bool {
        self.search_run_with::<NEAREST, PADDED>(None, first, run, t_max, search)
    }

    /// The leaf loop testing two blocks, eight triangles, at a time where a run has them,
    /// in 256-bit instructions.
    ///
    /// # Safety
    /// The CPU must support AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    #[inline(never)]
    unsafe fn search_run_avx<const NEAREST: bool, const PADDED: bool>(
        &self,
        avx: Avx,
        first: *const Block,
        run: Range<usize>,
        t_max: &mut f64,
        search: &mut Search,
    ) -> bool {
        self.search_run_with::<NEAREST, PADDED>(Some(avx), first, run, t_max, search)
    }

    /// The leaf loop, testing blocks in pairs where `avx` is given.
    #[inline(always)]
    fn search_run_with<const NEAREST: bool, const PADDED: bool>(
        &self,
        avx: Option<Avx>,
        first: *const Block,
        run: Range<usize>,
        t_max: &mut f64,
        search: &mut Search,
    ) -> bool {
        // One copy of the loop per axis the ray runs along, so the permutation is static.
        match search.axis() {
            0 => self.search_run_along::<0, NEAREST, PADDED>(avx, first, run, t_max, search),
            1 => self.search_run_along::<1, NEAREST, PADDED>(avx, first, run, t_max, search),
            _ => self.search_run_along::<2, NEAREST, PADDED>(avx, first, run, t_max, search),
        }
    }

    /// The blocks of the run, two at a time where `avx` is given and the run has both.
    #[inline(always)]
    fn search_run_along<const KZ: usize, const NEAREST: bool, const PADDED: bool>(
        &self,
        avx: Option<Avx>,
        first: *const Block,
        run: Range<usize>,
        t_max: &mut f64,
        search: &mut Search,
    ) -> bool {
        debug_assert!(run.start < LANES && (!PADDED || run.start == 0));
        let skip = run.start % LANES;
        let mut from = !0u32 << skip;
        let mut base = run.start - skip;
        while base < run.end {
            let pair = avx.is_some() && run.end - base > LANES;
            let width = if pair { 2 * LANES } else { LANES };
            let lanes = if PADDED {
                (1 << width) - 1
            } else {
                from & ((1 << (run.end - base).min(width)) - 1)
            };
            from = !0;
            // SAFETY: the structure's runs are of stored blocks, one after another, and a
            // pair is taken only where the run reaches into the second block.
            let block = unsafe { first.add(base / LANES) };
            if !unsafe { self.test_blocks::<KZ, NEAREST>(avx, block, pair, lanes, t_max, search) } {
                return false;
            }
            base += width;
        }
        true
    }

    /// One test: of the lanes set in `lanes` of the block at `block`, and of the next block
    /// too where `pair` (with `avx`). Keeps a hit in `search`, and lowers `t_max` to it if
    /// `NEAREST`, else returns false.
    ///
    /// # Safety
    /// `block`, and for a pair the block after it, must be stored blocks.
    #[inline(always)]
    unsafe fn test_blocks<const KZ: usize, const NEAREST: bool>(
        &self,
        avx: Option<Avx>,
        block: *const Block,
        pair: bool,
        lanes: u32,
        t_max: &mut f64,
        search: &mut Search,
    ) -> bool {
        let Search {
            ray,
            sheared,
            hit,
            blocks,
            ..
        } = search;
        let r = sheared.get_or_insert_with(|| ShearedRay::along::<KZ>(ray));
        #[cfg(not(target_arch = "x86_64"))]
        let _ = pair; // Pairs are an AVX test.
        let found = match avx {
            #[cfg(target_arch = "x86_64")]
            Some(avx) if pair => {
                // SAFETY: for a pair the caller vouches for both blocks.
                let pair = unsafe { &*(block as *const [Block; 2]) };
                self.intersect_lanes_along::<KZ, NEAREST, F8>(
                    avx, r, ray, pair, *blocks, lanes, *t_max,
                )
            }
            _ => {
                // SAFETY: the caller vouches for the block.
                let block = unsafe { &*block };
                self.intersect_lanes_along::<KZ, NEAREST, F4>(
                    (),
                    r,
                    ray,
                    block,
                    *blocks,
                    lanes,
                    *t_max,
                )
            }
        };
        if let Some(h) = found {
            *hit = Some(h);
            if !NEAREST {
                return false;
            }
            *t_max = h.t;
        }
        true
    }

    /// The watertight test on the triangles held in `blocks`, one lane of `V` each, against
    /// the lanes set in `lanes`: the nearest hit if `NEAREST`, else the first found. A hit
    /// names its part by the block's place from `places_from` (see [`BLOCK_UNITS`]).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn intersect_lanes_along<const KZ: usize, const NEAREST: bool, V: BlockLanes>(
        &self,
        isa: V::Isa,
        r: &ShearedRay,
        ray: &Ray,
        blocks: &V::Blocks,
        places_from: *const u8,
        lanes: u32,
        t_max: f64,
    ) -> Option<HitRecord> {
        let (kx, ky) = ((KZ + 1) % 3, (KZ + 2) % 3);
        // Worked out only for a hit: the block's place times its lanes.
        let first_part =
            || (blocks as *const V::Blocks as usize - places_from as usize) / (EMBED_UNIT / LANES);
        let splat = |v: f32| V::splat(isa, v);
        let origin = [splat(r.origin[0]), splat(r.origin[1]), splat(r.origin[2])];
        let shear = [splat(r.shear[0]), splat(r.shear[1]), splat(r.shear[2])];
        let (a, b, c) = (
            sheared::<V>(isa, blocks, 0, [kx, ky, KZ], origin, shear),
            sheared::<V>(isa, blocks, 1, [kx, ky, KZ], origin, shear),
            sheared::<V>(isa, blocks, 2, [kx, ky, KZ], origin, shear),
        );
        let [e0, e1, e2] = edge_functions(a, b, c);
        let zero = splat(0.0);
        // All three of one sign: the least not below zero, or the greatest not above. A
        // padding lane's NaNs pass neither comparison.
        let least = e0.min(e1).min(e2);
        let greatest = e0.max(e1).max(e2);
        let mut inside = (zero.le(least) | greatest.le(zero)) & lanes;
        if inside == 0 {
            return None;
        }
        // An edge function exactly zero in f32 may be a rounding artefact: settle in f64.
        // Inside, the three are of one sign, so one is zero only where the least or the
        // greatest is.
        let on_edge = (least.eq(zero) | greatest.eq(zero)) & inside;
        inside &= !on_edge;
        let det = e0.add(e1).add(e2);
        let sz = shear[2];
        let (az, bz, cz) = (a[2].mul(sz), b[2].mul(sz), c[2].mul(sz));
        let t_scaled = e0.mul(az).add(e1.mul(bz)).add(e2.mul(cz));
        let t = t_scaled.div(det);
        let limit = splat(round_up_distance(t_max));
        inside &= zero.lt(t) & t.lt(limit) & !det.eq(zero);
        let mut best: Option<HitRecord> = None;
        if inside != 0 {
            // Is t conservatively positive? pbrt-v4's bound (§6.8.4) takes a division and
            // some forty operations; a cheaper one settles nearly every hit first.
            let extent = [
                max_abs(a[0], b[0], c[0]),
                max_abs(a[1], b[1], c[1]),
                max_abs(az, bz, cz),
            ];
            let settled = clear_of_origin_cheaply(isa, extent, t_scaled);
            if inside & !settled != 0 {
                let e = [e0, e1, e2];
                inside &= settled | beyond_error_bound(isa, extent, e, det, t);
            }
            let (t, e1, e2, det) = (t.to_array(), e1.to_array(), e2.to_array(), det.to_array());
            while inside != 0 {
                let lane = inside.trailing_zeros() as usize;
                inside &= inside - 1;
                if best.is_none_or(|h| (t[lane] as f64) < h.t) {
                    best = Some(HitRecord {
                        t: t[lane] as f64,
                        u: (e1[lane] / det[lane]) as f64,
                        v: (e2[lane] / det[lane]) as f64,
                        part: part_of(first_part(), lane),
                    });
                }
                if !NEAREST {
                    // Any hit will do: the first lane's, and no edge case settled in f64.
                    return best;
                }
            }
        }
        if on_edge != 0 {
            best = settle_on_edge::<V>(ray, blocks, first_part(), on_edge, best, t_max);
        }
        best
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

/// The nearest of `best` and the hits in f64 on the lanes set in `on_edge` of `blocks`,
/// whose parts start at `first_part`, in (0, t_max): the lanes whose f32 edge function
/// came out exactly zero. Rare, and apart so that the common path of the block test saves
/// fewer registers.
#[cold]
#[inline(never)]
fn settle_on_edge<V: BlockLanes>(
    ray: &Ray,
    blocks: &V::Blocks,
    first_part: usize,
    mut on_edge: u32,
    mut best: Option<HitRecord>,
    t_max: f64,
) -> Option<HitRecord> {
    while on_edge != 0 {
        let lane = on_edge.trailing_zeros() as usize;
        on_edge &= on_edge - 1;
        let limit = best.map_or(t_max, |h| h.t);
        // Read from the block in hand: looking the part up would weigh on every call.
        let corners = V::corners_of_lane(blocks, lane).map(widened);
        if let Some((t, b1, b2)) = intersect_triangle(ray, limit, corners) {
            best = Some(HitRecord {
                t,
                u: b1,
                v: b2,
                part: part_of(first_part, lane),
            });
        }
    }
    best
}

/// The edge functions of the watertight test, of the sheared corners `a`, `b`, `c` (x, y):
/// for each edge, twice the signed area of the triangle it makes with the ray's axis.
#[inline(always)]
fn edge_functions<V: Lanes>(a: [V; 3], b: [V; 3], c: [V; 3]) -> [V; 3] {
    [
        b[0].mul(c[1]).sub(b[1].mul(c[0])),
        c[0].mul(a[1]).sub(c[1].mul(a[0])),
        a[0].mul(b[1]).sub(a[1].mul(b[0])),
    ]
}

/// The largest magnitude of three, lane by lane.
#[inline(always)]
fn max_abs<V: Lanes>(p: V, q: V, s: V) -> V {
    p.abs().max(q.abs()).max(s.abs())
}

/// The lanes whose hit distance is surely above pbrt-v4's conservative bound δt (§6.8.4),
/// found without its division. `extent` holds the largest |coordinate| of the sheared
/// corners on x, y and z (X, Y, Z), `t_scaled` the distance times the determinant.
///
/// With m = max(X, Y), the triangle's reach across the ray: the edge functions are at most
/// 2m², δe ≤ (2γ₂ + 4γ₅)m² + 4γ₅Zm, and δt·|det| = 3Z(2γ₃·max|e| + δe) ≤ γ₅Zm(21.6m + 12Z)
/// < 34γ₅·Z·m·max(m, Z); t·|det| = |t_scaled|. Against that, 48γ₅ leaves room for f32's
/// roundings. A bound in M³, M the largest coordinate of all, missed hits on a small
/// triangle far away (M ≈ t there, m ≪ t): 43 % of the bunny's camera-ray hits took the
/// division. This one leaves only hits near the origin, and slivers seen edge on.
#[inline(always)]
fn clear_of_origin_cheaply<V: Lanes>(isa: V::Isa, extent: [V; 3], t_scaled: V) -> u32 {
    let [x, y, z] = extent;
    let across = x.max(y);
    let bound = V::splat(isa, 48.0 * gamma_f32(5))
        .mul(across.max(z))
        .mul(z)
        .mul(across);
    // With m and Z from 2⁻³⁰ up, no product above falls below f32's normal range, where its
    // rounding would no longer be relative; a bound that overflows is infinite and settles
    // nothing.
    const SMALLEST: f32 = 1.0 / (1u32 << 30) as f32;
    let normal = V::splat(isa, SMALLEST).le(across.min(z));
    bound.lt(t_scaled.abs()) & normal
}

/// The lanes whose distance `t` is above pbrt-v4's conservative bound δt (§6.8.4), in f32 as
/// pbrt computes it; `extent` as for [`clear_of_origin_cheaply`], `e` the edge functions.
#[inline(always)]
fn beyond_error_bound<V: Lanes>(isa: V::Isa, extent: [V; 3], e: [V; 3], det: V, t: V) -> u32 {
    let splat = |v: f32| V::splat(isa, v);
    let [max_x, max_y, max_z] = extent;
    let delta_z = max_z.mul(splat(gamma_f32(3)));
    let delta_x = max_x.add(max_z).mul(splat(gamma_f32(5)));
    let delta_y = max_y.add(max_z).mul(splat(gamma_f32(5)));
    let delta_e = max_x
        .mul(max_y)
        .mul(splat(gamma_f32(2)))
        .add(delta_y.mul(max_x))
        .add(delta_x.mul(max_y))
        .mul(splat(2.0));
    let max_e = max_abs(e[0], e[1], e[2]);
    let delta_t = max_e
        .mul(max_z)
        .mul(splat(gamma_f32(3)))
        .add(delta_e.mul(max_z))
        .add(delta_z.mul(max_e))
        .mul(splat(3.0))
        .div(det.abs());
    delta_t.lt(t)
}

/// The BVH's runs for `visit`: nearest first if `NEAREST`, else in any order, walked as
/// suits `coherence` rays.
#[inline(always)]
fn traverse_bvh<const NEAREST: bool>(
    bvh: &crate::accel::Bvh,
    ray: &Ray,
    t_max: f64,
    items: impl LeafPlaces,
    coherence: Coherence,
    visit: impl FnMut(Range<usize>, &mut f64) -> bool,
) {
    if NEAREST {
        bvh.traverse_runs(ray, t_max, items, visit);
    } else {
        bvh.traverse_runs_any_order(ray, t_max, items, coherence, visit);
    }
}

/// The part of `lane` of a test whose first block's parts start at `first_part`: lanes
/// from the fifth on are in the second block, [`BLOCK_UNITS`] further on.
#[inline(always)]
fn part_of(first_part: usize, lane: usize) -> u32 {
    (first_part + lane + lane / LANES * (BLOCK_UNITS - 1) * LANES) as u32
}

/// Lanes that load corners from blocks: four lanes from one, eight from two in a row.
trait BlockLanes: Lanes {
    type Blocks;
    /// Coordinate `axis` of corner `k` of every lane's triangle.
    fn corners(isa: Self::Isa, blocks: &Self::Blocks, k: usize, axis: usize) -> Self;
    /// The corners of one lane's triangle.
    fn corners_of_lane(blocks: &Self::Blocks, lane: usize) -> Corners;
}

impl BlockLanes for F4 {
    type Blocks = Block;
    #[inline(always)]
    fn corners(_: (), block: &Block, k: usize, axis: usize) -> F4 {
        F4::load(&block.corners[k][axis])
    }
    fn corners_of_lane(block: &Block, lane: usize) -> Corners {
        block.corners(lane)
    }
}

#[cfg(target_arch = "x86_64")]
impl BlockLanes for F8 {
    type Blocks = [Block; 2];
    #[inline(always)]
    fn corners(avx: Avx, blocks: &[Block; 2], k: usize, axis: usize) -> F8 {
        F8::join(
            avx,
            &blocks[0].corners[k][axis],
            &blocks[1].corners[k][axis],
        )
    }
    fn corners_of_lane(blocks: &[Block; 2], lane: usize) -> Corners {
        blocks[lane / LANES % 2].corners(lane % LANES)
    }
}

/// Corner `k` of each lane's triangle relative to the ray origin, permuted by `axes` and
/// sheared so that the ray is the +z axis.
#[inline(always)]
fn sheared<V: BlockLanes>(
    isa: V::Isa,
    blocks: &V::Blocks,
    k: usize,
    axes: [usize; 3],
    origin: [V; 3],
    shear: [V; 3],
) -> [V; 3] {
    let x = V::corners(isa, blocks, k, axes[0]).sub(origin[0]);
    let y = V::corners(isa, blocks, k, axes[1]).sub(origin[1]);
    let z = V::corners(isa, blocks, k, axes[2]).sub(origin[2]);
    [x.add(shear[0].mul(z)), y.add(shear[1].mul(z)), z]
}

/// A ray's search through a mesh's blocks: the ray, its sheared form once a leaf is
/// reached, and the hit so far.
struct Search<'r> {
    ray: &'r Ray,
    sheared: Option<ShearedRay>,
    hit: Option<HitRecord>,
    /// Where the CPU has AVX: blocks are tested two at a time.
    avx: Option<Avx>,
    /// Where the blocks' places are counted from ([`TriangleMesh::block_bytes`]).
    blocks: *const u8,
}

impl Search<'_> {
    /// The axis the ray runs along most: the sheared ray's z. Found at the first leaf: most
    /// rays that miss never reach one.
    #[inline(always)]
    fn axis(&self) -> usize {
        match &self.sheared {
            Some(r) => r.kz,
            None => self.ray.direction.max_abs_axis(),
        }
    }
}

/// A ray prepared for the watertight test: axes permuted so the direction's largest
/// component is z, and the shear that turns the ray into the +z axis (all in f32).
struct ShearedRay {
    /// The axis that becomes z; x and y are the next two in turn.
    kz: usize,
    origin: [f32; 3],
    shear: [f32; 3],
}

impl ShearedRay {
    /// For a ray whose direction's largest component is along `KZ`: the permutation is a
    /// constant of the code, the ray's numbers read without an index.
    #[inline(always)]
    fn along<const KZ: usize>(ray: &Ray) -> ShearedRay {
        debug_assert_eq!(KZ, ray.direction.max_abs_axis());
        let (kx, ky) = ((KZ + 1) % 3, (KZ + 2) % 3);
        let (o, d) = (ray.origin, ray.direction);
        let o = [o.x as f32, o.y as f32, o.z as f32];
        let d = [d.x as f32, d.y as f32, d.z as f32];
        // The three quotients in one division.
        let [sx, sy, sz, _] = F4::from_array([-d[kx], -d[ky], 1.0, 1.0])
            .div(F4::splat(d[KZ]))
            .to_array();
        ShearedRay {
            kz: KZ,
            origin: [o[kx], o[ky], o[KZ]],
            shear: [sx, sy, sz],
        }
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

    /// A bumpy square of `n` × `n` quads, two triangles each, its coordinates exact in f32.
    fn sheet(n: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let positions = (0..=n)
            .flat_map(|j| (0..=n).map(move |i| (i, j)))
            .map(|(i, j)| Vec3::new(i as f64, j as f64, ((i * 7 + j * 3) % 5) as f64 * 0.125))
            .collect();
        let v = |i: u32, j: u32| j * (n + 1) + i;
        let triangles = (0..n)
            .flat_map(|j| (0..n).map(move |i| (i, j)))
            .flat_map(|(i, j)| {
                [
                    [v(i, j), v(i + 1, j), v(i + 1, j + 1)],
                    [v(i, j), v(i + 1, j + 1), v(i, j + 1)],
                ]
            })
            .collect();
        (positions, triangles)
    }

    #[test]
    fn every_layout_keeps_the_triangles_and_their_numbering() {
        let (positions, triangles) = sheet(13);
        let normals = vec![Vec3::Z; positions.len()];
        let kept =
            TriangleMesh::new(positions.clone(), triangles.clone(), normals, vec![]).unwrap();
        let bare = TriangleMesh::new(positions.clone(), triangles.clone(), vec![], vec![]).unwrap();
        let corners = |t: &[u32; 3]| t.map(|i| positions[i as usize]);
        for kind in [
            AccelKind::Bvh,
            AccelKind::Grid,
            AccelKind::Octree,
            AccelKind::None,
        ] {
            // Back and forth between blocks and the indexed layout.
            let kept = kept
                .with_accel(kind)
                .with_accel(AccelKind::Octree)
                .with_accel(kind);
            assert_eq!(
                kept.indexed(),
                (positions.clone(), triangles.clone()),
                "{kind}"
            );
            let bare = bare.with_accel(kind);
            let (vertices, tris) = bare.indexed();
            assert_eq!(
                vertices.len(),
                positions.len(),
                "{kind}: shared corners merged"
            );
            for (t, u) in triangles.iter().zip(&tris) {
                assert_eq!(corners(t), u.map(|i| vertices[i as usize]), "{kind}");
            }
            for mesh in [&kept, &bare] {
                assert_eq!(mesh.triangles().count(), triangles.len(), "{kind}");
                for (part, tri) in mesh.triangles() {
                    let source = mesh.source_triangle(part) as usize;
                    assert_eq!(tri, corners(&triangles[source]), "{kind}");
                }
            }
            let (part, _) = kept.triangles().nth(5).unwrap();
            let source = kept.source_triangle(part) as usize;
            assert_eq!(kept.vertex_indices(part), Some(triangles[source]), "{kind}");
            assert_eq!(bare.vertex_indices(part), None, "{kind}");
        }
    }

    #[test]
    fn leaves_the_build_cannot_split_by_position_still_take_one_test() {
        // Twelve triangles about one centroid, each tilted about x by its own angle: no
        // split by position separates them, yet every leaf must fit the one test of
        // `search_leaf_avx`; rays off the centroid meet them at different distances.
        let count = 12;
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for k in 0..count {
            let angle = 0.1 * k as f64 - 0.55;
            let (sin, cos) = angle.sin_cos();
            let tilted = |x: f64, y: f64| Vec3::new(x, y * cos, y * sin);
            let first = positions.len() as u32;
            positions.extend([tilted(-1.0, -1.0), tilted(2.0, -1.0), tilted(-1.0, 2.0)]);
            triangles.push([first, first + 1, first + 2]);
        }
        let mesh = TriangleMesh::new(positions, triangles, vec![], vec![]).unwrap();
        let Accel::Bvh(bvh) = &mesh.accel else {
            panic!("the BVH is the default")
        };
        assert!(bvh.is_embedded());
        let leaves = bvh.embedded_leaves();
        assert!(leaves.len() > 1 && leaves.iter().all(|&(_, n)| n <= 2 * LANES));
        let brute = mesh.with_accel(AccelKind::None);
        for i in 0..40 {
            // Never through the line all twelve share (y = z = 0), where they tie.
            let y = -0.87 + 0.05 * i as f64;
            let ray = Ray::new(Vec3::new(0.1, y, -5.0), Vec3::new(0.01, 0.02, 1.0));
            let (hit, expected) = (mesh.intersect(&ray, 1e9), brute.intersect(&ray, 1e9));
            let hit_source = hit.map(|h| (mesh.source_triangle(h.part), h.t));
            let expected_source = expected.map(|h| (brute.source_triangle(h.part), h.t));
            assert_eq!(hit_source, expected_source, "y = {y}");
            assert_eq!(
                mesh.intersect_any(&ray, 1e9).is_some(),
                hit.is_some(),
                "y = {y}"
            );
        }
    }

    #[test]
    fn blocks_tested_in_pairs_give_the_hits_of_blocks_tested_alone() {
        // Bit for bit, whatever the CPU: eight lanes compute what four do. Rays from above
        // at random (seed 11), and rays straight down through vertices, where the edge
        // functions are zero and the f64 test decides. Without AVX both sides test alone.
        let (positions, triangles) = sheet(24);
        let mesh = TriangleMesh::new(positions, triangles, vec![], vec![]).unwrap();
        let mut rng = crate::sampling::Rng::new(11, 0);
        let mut rays: Vec<Ray> = (0..3000)
            .map(|_| {
                let mut u = || rng.uniform();
                let origin = Vec3::new(u() * 30.0 - 3.0, u() * 30.0 - 3.0, 0.3 + u() * 4.0);
                let target = Vec3::new(u() * 24.0, u() * 24.0, 0.0);
                Ray::new(origin, target - origin)
            })
            .collect();
        rays.extend((0..25).map(|i| Ray::new(Vec3::new(i as f64, 7.0, 3.0), -Vec3::Z)));
        for kind in [AccelKind::Bvh, AccelKind::Grid, AccelKind::Octree] {
            let mesh = mesh.with_accel(kind);
            let mut hits = 0;
            for ray in &rays {
                let incoherent = Coherence::Incoherent;
                let alone = mesh.search::<true>(ray, f64::INFINITY, None, incoherent);
                let paired = mesh.search::<true>(ray, f64::INFINITY, Avx::detect(), incoherent);
                assert_eq!(paired, alone, "{kind}: {ray:?}");
                for coherence in [Coherence::Incoherent, Coherence::Coherent] {
                    let any_alone = mesh.search::<false>(ray, f64::INFINITY, None, coherence);
                    let any_paired =
                        mesh.search::<false>(ray, f64::INFINITY, Avx::detect(), coherence);
                    assert_eq!(any_paired.is_some(), alone.is_some(), "{kind}: {ray:?}");
                    assert_eq!(any_alone.is_some(), alone.is_some(), "{kind}: {ray:?}");
                }
                hits += alone.is_some() as usize;
            }
            assert!(hits > 2000, "{kind}: {hits} hits");
        }
    }

    #[test]
    fn a_bvh_with_its_blocks_apart_finds_the_hits_of_one_with_them_among_its_nodes() {
        // What a mesh too large to embed (some 40 million triangles) gets, here by a limit of
        // no bytes. Rays from above at random (seed 12).
        let (positions, triangles) = sheet(24);
        let normals = vec![Vec3::Z; positions.len()];
        let among = TriangleMesh::new(positions, triangles.clone(), normals, vec![]).unwrap();
        let apart = among.rebuilt(AccelKind::Bvh, 0);
        assert!(matches!(&among.accel, Accel::Bvh(b) if b.is_embedded()));
        assert!(matches!(&apart.accel, Accel::Bvh(b) if !b.is_embedded()));
        assert_eq!(apart.indexed(), among.indexed());
        for (part, _) in apart.triangles() {
            let source = apart.source_triangle(part) as usize;
            assert_eq!(apart.vertex_indices(part), Some(triangles[source]));
        }
        let mut rng = crate::sampling::Rng::new(12, 0);
        let mut hits = 0;
        for _ in 0..3000 {
            let mut u = || rng.uniform();
            let origin = Vec3::new(u() * 30.0 - 3.0, u() * 30.0 - 3.0, 0.3 + u() * 4.0);
            let ray = Ray::new(origin, Vec3::new(u() * 24.0, u() * 24.0, 0.0) - origin);
            let found = |mesh: &TriangleMesh| {
                let hit = mesh.intersect(&ray, f64::INFINITY);
                let any = mesh.intersect_any(&ray, f64::INFINITY).is_some();
                (
                    hit.map(|h| (h.t, h.u, h.v, mesh.source_triangle(h.part))),
                    any,
                )
            };
            assert_eq!(found(&apart), found(&among), "{ray:?}");
            hits += found(&among).1 as usize;
        }
        assert!(hits > 2000, "{hits} hits");
    }

    #[test]
    fn a_ray_leaving_a_triangle_misses_it_and_a_far_one_hits_it() {
        // Random triangles of every size (seed 5) whose centroid is a point exactly in f32,
        // corners too: a ray from the centroid, either way, has a distance of pure rounding
        // noise, which only pbrt's bound rejects (the cheap bound must leave it to that). A
        // ray from afar to the same point is settled by the cheap bound, at the distance
        // the f64 test finds.
        let mut rng = crate::sampling::Rng::new(5, 0);
        // Multiples of 1/16 under 1024, offsets of quarters times 2^-2..2^6: all sums fit in
        // f32's 24 bits.
        let mut multiples = |of: f64, below: f64| {
            let mut m = || ((rng.uniform() - 0.5) * 2.0 * below / of).round() * of;
            Vec3::new(m(), m(), m())
        };
        let exact = |p: Vec3| Vec3::new(p.x as f32 as f64, p.y as f32 as f64, p.z as f32 as f64);
        let mut far_hits = 0;
        for _ in 0..2000 {
            let centre = multiples(1.0 / 16.0, 1024.0);
            let scale = 2f64.powi(multiples(1.0, 4.5).x as i32 + 2);
            let (a, b) = (multiples(0.25, 2.0) * scale, multiples(0.25, 2.0) * scale);
            let away = multiples(1.0 / 1024.0, 0.5);
            if a.cross(b).length() < 1e-3 * scale * scale {
                continue;
            }
            let tri = [centre + a, centre + b, centre - a - b];
            assert_eq!(tri.map(exact), tri);
            let mesh = TriangleMesh::new(tri.to_vec(), vec![[0, 1, 2]], vec![], vec![]).unwrap();
            for d in [away, -away] {
                let leaving = Ray::new(centre, d);
                assert_eq!(
                    mesh.intersect(&leaving, f64::INFINITY),
                    None,
                    "{tri:?} {d:?}"
                );
                assert_eq!(mesh.intersect_any(&leaving, f64::INFINITY), None, "{tri:?}");
            }
            let from = exact(centre + away * (scale * 10.0));
            let arriving = Ray::new(from, centre - from);
            // Not grazing, where a distance is ill-conditioned.
            let cos = a.cross(b).normalized().dot(arriving.direction.normalized());
            if cos.abs() < 0.2 {
                continue;
            }
            if let Some((t, _, _)) = intersect_triangle(&arriving, f64::INFINITY, tri) {
                let hit = mesh.intersect(&arriving, f64::INFINITY).expect("a far hit");
                assert!((hit.t - t).abs() <= 1e-5 * t, "{} against {t}", hit.t);
                assert!(mesh.intersect_any(&arriving, f64::INFINITY).is_some());
                far_hits += 1;
            }
        }
        assert!(far_hits > 1000, "{far_hits} far hits");
    }

    #[test]
    fn the_cheap_bound_on_t_implies_pbrts_and_settles_far_small_triangles() {
        // Random sheared triangles (seed 11), four at a time, at distances 10⁻³..10³ and
        // across the ray 10⁻⁶..10 times as wide, tilted: wherever the cheap test settles a
        // lane with t > 0, pbrt's bound δt < t holds too, as the leaf test computes it. And
        // of the triangles at least 10⁻³ as wide as they are far, seen within 60° of head on
        // and not slivers, it settles all but 0.1 % (a bound in M³, M the largest coordinate
        // of all, settled 81 % of them).
        let mut rng = crate::sampling::Rng::new(11, 0);
        let mut uniform = move || rng.uniform() as f32;
        let (mut head_on, mut head_on_settled, mut settled_lanes) = (0, 0, 0);
        for _ in 0..20_000 {
            let mut corners = [[[0.0f32; 4]; 3]; 3]; // corner, axis, lane
            let mut head_on_lanes = 0u32;
            for lane in 0..4 {
                let distance = 10f32.powf(uniform() * 6.0 - 3.0);
                let ratio = 10f32.powf(uniform() * 7.0 - 6.0);
                let width = distance * ratio;
                let tilt = [uniform() * 2.0 - 1.0, uniform() * 2.0 - 1.0];
                for corner in &mut corners {
                    let x = (uniform() * 2.0 - 1.0) * width;
                    let y = (uniform() * 2.0 - 1.0) * width;
                    corner[0][lane] = x;
                    corner[1][lane] = y;
                    corner[2][lane] = distance + tilt[0] * x + tilt[1] * y;
                }
                // Within 60° of head on: |tilt| < √3.
                if ratio > 1e-3 && tilt[0] * tilt[0] + tilt[1] * tilt[1] < 3.0 {
                    head_on_lanes |= 1 << lane;
                }
            }
            let [a, b, c] = corners.map(|corner| corner.map(F4::from_array));
            let [e0, e1, e2] = edge_functions(a, b, c);
            let det = e0.add(e1).add(e2);
            let t_scaled = e0.mul(a[2]).add(e1.mul(b[2])).add(e2.mul(c[2]));
            let t = t_scaled.div(det);
            let extent = [0, 1, 2].map(|axis| max_abs(a[axis], b[axis], c[axis]));
            let zero = F4::splat(0.0);
            let positive = zero.lt(t) & !det.eq(zero);
            let settled = clear_of_origin_cheaply((), extent, t_scaled) & positive;
            let beyond = beyond_error_bound((), extent, [e0, e1, e2], det, t);
            assert_eq!(settled & !beyond, 0, "{corners:?}");
            settled_lanes += settled.count_ones();
            // Not a sliver: the projected area at least a tenth of the extent squared.
            let across = extent[0].max(extent[1]);
            let sliver = det.abs().lt(across.mul(across).mul(F4::splat(0.1)));
            let counted = head_on_lanes & positive & !sliver;
            head_on += counted.count_ones();
            head_on_settled += (counted & settled).count_ones();
        }
        assert!(settled_lanes > 20_000, "{settled_lanes} lanes settled");
        assert!(head_on > 5_000, "{head_on}");
        assert!(
            head_on_settled as f64 >= 0.999 * head_on as f64,
            "{head_on_settled} of {head_on} settled"
        );
    }

    #[test]
    fn large_triangles_kept_out_of_cells_are_still_hit() {
        // A small sheet above a ground of two triangles forty times as wide: the grid and
        // the octree test the ground on every ray, from the first run of their slots.
        let (mut positions, mut triangles) = sheet(8);
        let n = positions.len() as u32;
        positions.extend([
            Vec3::new(-160.0, -160.0, -4.0),
            Vec3::new(160.0, -160.0, -4.0),
            Vec3::new(160.0, 160.0, -4.0),
            Vec3::new(-160.0, 160.0, -4.0),
        ]);
        triangles.extend([[n, n + 1, n + 2], [n, n + 2, n + 3]]);
        let mesh = TriangleMesh::new(positions, triangles, vec![], vec![]).unwrap();
        let oracle = mesh.with_accel(AccelKind::None);
        for kind in [AccelKind::Bvh, AccelKind::Grid, AccelKind::Octree] {
            let m = mesh.with_accel(kind);
            let mut ground = 0;
            for i in 0..400 {
                let (x, y) = ((i % 20) as f64 * 1.7 - 12.0, (i / 20) as f64 * 1.7 - 12.0);
                let ray = Ray::new(Vec3::new(x, y, 10.0), Vec3::new(0.01, 0.02, -1.0));
                let name = |m: &TriangleMesh, h: Option<HitRecord>| {
                    h.map(|h| (m.source_triangle(h.part), h.t))
                };
                let want = name(&oracle, oracle.intersect(&ray, f64::INFINITY));
                assert_eq!(
                    name(&m, m.intersect(&ray, f64::INFINITY)),
                    want,
                    "{kind}: {i}"
                );
                assert_eq!(
                    m.intersect_any(&ray, f64::INFINITY).is_some(),
                    want.is_some()
                );
                ground += usize::from(want.is_some_and(|(source, _)| source >= 128));
            }
            assert!(ground > 200, "{kind}: {ground} rays reach the ground");
        }
    }

    #[test]
    fn a_bvh_mesh_takes_at_most_64_bytes_a_triangle() {
        // The budget of the acceleration issue, vertices, indices and nodes included.
        let (positions, triangles) = sheet(100);
        let mesh = TriangleMesh::new(positions, triangles, vec![], vec![]).unwrap();
        let per_triangle = mesh.memory_bytes() as f64 / mesh.triangle_count() as f64;
        assert!(per_triangle <= 64.0, "{per_triangle} bytes a triangle");
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
