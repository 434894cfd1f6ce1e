//! A ray's search through a mesh: the structure hands over runs of blocks, and each block's
//! four triangles (eight, two blocks at a time, with AVX) are tested at once by the
//! watertight test in f32 lanes, the rare hit exactly on an edge settled in f64.

use super::watertight::{
    beyond_error_bound, clear_of_origin_cheaply, edge_functions, intersect_triangle, max_abs,
};
use super::{widened, Block, Corners, TriangleMesh, BLOCK_UNITS, LANES, LEAF};
use crate::accel::ray_f32::round_up_distance;
#[cfg(target_arch = "x86_64")]
use crate::accel::simd::F8;
use crate::accel::simd::{Avx, Lanes, F4};
use crate::accel::{
    bytes_of, cost, Accel, AmongNodes, Coherence, LeafItems, LeafPlaces, EMBED_UNIT,
};
use crate::geometry::HitRecord;
use crate::math::Ray;
use std::ops::Range;

impl TriangleMesh {
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
    pub(super) fn search<const NEAREST: bool>(
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
                // A mesh of one leaf: that leaf's test alone.
                if let Some((place, count)) = self.single_leaf {
                    let block = first(&search, &(place..place + count));
                    let mut t_max = t_max;
                    cost::tested(count);
                    #[cfg(target_arch = "x86_64")]
                    if let Some(avx) = avx {
                        // SAFETY: `avx` says the CPU has AVX.
                        unsafe {
                            self.search_leaf_avx::<NEAREST>(
                                avx,
                                block,
                                count,
                                &mut t_max,
                                &mut search,
                            )
                        };
                        return search.hit;
                    }
                    self.search_run_sse::<NEAREST, true>(block, 0..count, &mut t_max, &mut search);
                    return search.hit;
                }
                // The instruction set chosen once, not at every leaf.
                #[cfg(target_arch = "x86_64")]
                if let Some(avx) = avx {
                    let state = &mut search;
                    let visit_run = move |run: Range<usize>, t_max: &mut f64| {
                        let (block, count) = (first(state, &run), run.end - run.start);
                        cost::tested(count);
                        // SAFETY: `avx` says the CPU has AVX.
                        unsafe { self.search_leaf_avx::<NEAREST>(avx, block, count, t_max, state) }
                    };
                    traverse_bvh::<NEAREST>(bvh, ray, t_max, AmongNodes, coherence, visit_run);
                    return search.hit;
                }
                let visit_run = |run: Range<usize>, t_max: &mut f64| {
                    let (block, count) = (first(&search, &run), run.end - run.start);
                    cost::tested(count);
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
            cost::tested(run.len());
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
                cost::tested(items.len());
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
