//! An eight-wide bounding-volume hierarchy: a binary binned surface-area-heuristic build
//! (Wald 2007) over all three axes, parallel across subtrees, collapsed into nodes of up to
//! eight children at the least SAH cost (Ylitie, Karras and Laine 2017); compact f32 nodes
//! tested eight boxes at a time with AVX where the CPU has it (detected at run time) and as
//! two four-box SSE tests otherwise; ordered front-to-back traversal with a fixed-size
//! stack (no allocation per ray).
//!
//! The BVH knows only boxes. Its leaves are runs of item indices handed to the caller's
//! closure, so one structure serves the triangles of a mesh (tested four at once) and the
//! primitives of a scene alike. A caller may instead store its items in the leaf order
//! (as pbrt does with its primitives): leaves are then runs of consecutive items, with no
//! index to read per item, which is how meshes use it.
//!
//! Boxes are rounded outward to f32, and the slab test is made conservative the way pbrt-v4
//! (§6.8.2) does it: the far distance is enlarged by the relative error of its computation,
//! and the ray origin is rounded up or down per plane so that the f32 origin never moves a
//! box out of the ray's way.

use super::pages::LargeArray;
#[cfg(target_arch = "x86_64")]
use super::ray_f32::BoxRayAvx;
use super::ray_f32::{round_down, round_up, round_up_distance, BoxRay};
use super::simd::F4;
use super::{append_padded, bytes_of, LeafSize};
use crate::math::{Bounds3, Ray};
use std::mem::MaybeUninit;
use std::ops::Range;

const BINS: usize = 16;
/// Children per node.
const WIDTH: usize = 8;
/// Depth (in binary splits) past which runs are halved instead of split by cost.
const MAX_DEPTH: usize = 64;
/// A node pushes at most seven children. Each wide node is at least one binary split below
/// its parent; splits are binned down to MAX_DEPTH levels, then at most 31 levels more, as
/// every level halves the items.
const STACK: usize = 7 * (MAX_DEPTH + 32);
/// Subtrees with more items than this are built in parallel.
const PARALLEL_ITEMS: usize = 4096;

/// A child reference. An interior node: its byte offset in the nodes (a multiple of 64, so
/// that the traversal adds it to the base without a shift). A leaf: `LEAF_FLAG` set, its
/// run's first position above `START_SHIFT` and its count less one below the flag. After
/// [`Bvh::embed_blocks`] a leaf's start counts [`EMBED_UNIT`]s, so that its reference is its
/// first block's byte offset plus at most 15, on the same cache line: a prefetch reads
/// either kind from the base plus the reference, without decoding it.
const LEAF_FLAG: u32 = 8;
const START_SHIFT: u32 = 4;
const NODE_BYTES: u32 = std::mem::size_of::<Node>() as u32;
/// Longest run a leaf can hold: its count less one takes the bits below the flag.
const MAX_LEAF_ITEMS: usize = LEAF_FLAG as usize;
/// Never read: `used` leaves the slot out.
const EMPTY: u32 = LEAF_FLAG;
/// The unit in which [`Bvh::embed_blocks`] gives a leaf's place: blocks are a whole number
/// of them, so every block starts on one.
pub const EMBED_UNIT: usize = 1 << START_SHIFT;
/// The most bytes [`Bvh::embed_blocks`] lays out, within what references reach (4 GiB).
pub const EMBED_LIMIT: usize = 1 << 31;

/// The reference of a leaf holding the run of `count` items from `start`.
fn leaf_reference(start: usize, count: usize) -> u32 {
    assert!(
        (1..=MAX_LEAF_ITEMS).contains(&count),
        "a BVH leaf of {count} items"
    );
    assert!(
        start < 1 << (32 - START_SHIFT),
        "too many items for a BVH leaf reference"
    );
    ((start as u32) << START_SHIFT) | LEAF_FLAG | (count as u32 - 1)
}

#[inline(always)]
fn is_leaf(reference: u32) -> bool {
    reference & LEAF_FLAG != 0
}

/// A leaf reference's run: its start and its count.
#[inline(always)]
fn leaf_run(reference: u32) -> (usize, usize) {
    let count = (reference & (LEAF_FLAG - 1)) as usize + 1;
    ((reference >> START_SHIFT) as usize, count)
}

/// Eight child boxes as six planes of eight lanes: min x, y, z then max x, y, z. Four cache
/// lines exactly.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node {
    planes: [[f32; WIDTH]; 6],
    children: [u32; WIDTH],
    /// Bit i set where child slot i is used.
    used: u32,
}

impl Node {
    /// The slots in use.
    fn slots(&self) -> impl Iterator<Item = usize> + '_ {
        (0..WIDTH).filter(|&s| self.used & (1 << s) != 0)
    }

    /// The box of the child in `slot`.
    fn child_box(&self, slot: usize) -> Aabb {
        Aabb {
            lo: [0, 1, 2].map(|a| self.planes[a][slot]),
            hi: [0, 1, 2].map(|a| self.planes[3 + a][slot]),
        }
    }
}

#[derive(Clone, Debug, Default)]
pub struct Bvh {
    /// On huge pages where there are many (see [`super::pages`]). After
    /// [`Bvh::embed_blocks`], the leaves' blocks lie among them.
    nodes: LargeArray<Node>,
    embedded: bool,
    /// Item indices, grouped by leaf.
    order: Vec<u32>,
    bounds: Bounds3,
}

#[derive(Clone, Copy)]
struct Item {
    lo: [f32; 3],
    hi: [f32; 3],
    index: u32,
}

impl Item {
    /// Twice the centroid: all that binning needs.
    fn center2(&self, axis: usize) -> f32 {
        self.lo[axis] + self.hi[axis]
    }
}

#[derive(Clone, Copy)]
struct Aabb {
    lo: [f32; 3],
    hi: [f32; 3],
}

impl Aabb {
    const EMPTY: Aabb = Aabb {
        lo: [f32::INFINITY; 3],
        hi: [f32::NEG_INFINITY; 3],
    };

    fn grow(&mut self, lo: &[f32; 3], hi: &[f32; 3]) {
        for a in 0..3 {
            self.lo[a] = self.lo[a].min(lo[a]);
            self.hi[a] = self.hi[a].max(hi[a]);
        }
    }

    fn half_area(&self) -> f32 {
        let d = [0, 1, 2].map(|a| (self.hi[a] - self.lo[a]).max(0.0));
        d[0] * d[1] + d[1] * d[2] + d[2] * d[0]
    }

    fn of(items: &[Item]) -> Aabb {
        let mut b = Aabb::EMPTY;
        for it in items {
            b.grow(&it.lo, &it.hi);
        }
        b
    }
}

enum BuildNode {
    Leaf {
        bounds: Aabb,
        start: u32,
        count: u32,
    },
    Inner {
        bounds: Aabb,
        children: Vec<BuildNode>,
    },
}

impl BuildNode {
    fn bounds(&self) -> &Aabb {
        match self {
            BuildNode::Leaf { bounds, .. } | BuildNode::Inner { bounds, .. } => bounds,
        }
    }
}

impl Bvh {
    /// Builds over items given by their bounds, for a caller that tests leaves as `leaf`
    /// says; the leaves refer to items by position. Empty boxes are left out.
    pub fn build(item_bounds: &[Bounds3], leaf: LeafSize) -> Bvh {
        let max_leaf = leaf.max_leaf.clamp(1, MAX_LEAF_ITEMS);
        let leaf = LeafSize {
            max_leaf,
            block: leaf.block.clamp(1, max_leaf),
            ..leaf
        };
        let mut items: Vec<Item> = item_bounds
            .iter()
            .enumerate()
            .filter(|(_, b)| !b.is_empty())
            .map(|(i, b)| Item {
                lo: [0, 1, 2].map(|a| round_down(b.min[a])),
                hi: [0, 1, 2].map(|a| round_up(b.max[a])),
                index: i as u32,
            })
            .collect();
        let bounds = item_bounds
            .iter()
            .fold(Bounds3::default(), |b, i| b.union(i));
        if items.is_empty() {
            return Bvh {
                bounds,
                ..Bvh::default()
            };
        }
        let root = Builder { leaf }.build(&mut items, 0, 0).into_wide();
        let mut nodes = Vec::with_capacity(items.len() / 2 + 1);
        match root {
            leaf @ BuildNode::Leaf { .. } => {
                flatten_children(&mut nodes, &[leaf]);
            }
            BuildNode::Inner { children, .. } => {
                flatten_children(&mut nodes, &children);
            }
        }
        Bvh {
            nodes: nodes.into(),
            embedded: false,
            order: items.iter().map(|it| it.index).collect(),
            bounds,
        }
    }

    pub fn bounds(&self) -> Bounds3 {
        self.bounds
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node>() + self.order.len() * 4
    }

    /// Asks for a child the traversal will visit later, so it arrives while others are
    /// tested: five cache lines from its start, a node's four and the first of the blocks
    /// stored after it, or a leaf's first five (a mesh's two blocks of four triangles, 320
    /// bytes, where the leaf follows its node directly). Without branches (see
    /// [`LeafPlaces::fetch_address`]): whether a child is a leaf is a coin toss to the branch
    /// predictor.
    #[inline(always)]
    fn prefetch(&self, child: u32, items: impl LeafPlaces) {
        #[cfg(target_arch = "x86_64")]
        {
            let p = items.fetch_address(self.nodes.as_ptr() as *const u8, child) as *const i8;
            // SAFETY: prefetching is only a hint; it never faults, so the address needs no
            // bounds check.
            unsafe {
                use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
                for line in 0..5 {
                    _mm_prefetch(p.wrapping_add(64 * line), _MM_HINT_T0);
                }
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = (child, items);
    }

    /// Front-to-back traversal. `visit(items, t_max)` is called with the items of each leaf
    /// whose box the ray crosses in (0, t_max); it may shrink `t_max` to prune farther boxes,
    /// and returns false to stop.
    #[inline]
    pub fn traverse(&self, ray: &Ray, t_max: f64, mut visit: impl FnMut(&[u32], &mut f64) -> bool) {
        let items = LeafItems::<{ std::mem::size_of::<u32>() }>::at(&self.order);
        self.traverse_runs(ray, t_max, items, |run, t_max| {
            visit(&self.order[run], t_max)
        });
    }

    /// Hands the caller the items in leaf order, each leaf padded with [`super::PAD`] entries to a
    /// whole number of `block`s, and leaves the BVH without them: for a caller that stores
    /// its items in this order, so that leaves name runs of them directly
    /// ([`Bvh::traverse_runs`]), no index is read per item, and every leaf starts a block.
    /// Items the BVH left out (empty boxes) are not in it. [`Bvh::traverse`] must not be used
    /// afterwards.
    pub fn take_padded_order(&mut self, block: usize) -> Vec<u32> {
        let order = std::mem::take(&mut self.order);
        let mut leaves: Vec<(u32, usize, usize)> = Vec::new(); // (reference, node, slot)
        for (n, node) in self.nodes.iter().enumerate() {
            for (slot, &child) in node.children.iter().enumerate() {
                if node.used & (1 << slot) != 0 && is_leaf(child) {
                    leaves.push((child, n, slot));
                }
            }
        }
        leaves.sort_unstable_by_key(|&(child, _, _)| leaf_run(child).0);
        let mut padded = Vec::with_capacity(order.len() + leaves.len() * (block - 1));
        for (child, n, slot) in leaves {
            let (start, count) = leaf_run(child);
            self.nodes[n].children[slot] = leaf_reference(padded.len(), count);
            append_padded(&mut padded, &order[start..start + count], block);
        }
        padded
    }

    /// Moves the caller's blocks into the nodes' array, each node followed by the blocks of
    /// its leaf children: a leaf's items then lie beside the node that names it, and the
    /// memory system, having fetched a node's lines, is already on its way to theirs (the
    /// level-8 icosphere's incoherent rays 12 % faster for the closest hit, measured in one
    /// process). `blocks` hold the items of [`Bvh::take_padded_order`], `lanes` to a block.
    /// A leaf's run then starts at its first block's place in [`Bvh::embedded`], counted in
    /// [`EMBED_UNIT`]s, and still counts items; [`Bvh::embedded_leaves`] lists the runs.
    /// Returns false, leaving the BVH as it was, where the whole would exceed `limit` bytes
    /// or [`EMBED_LIMIT`], what references can reach, or there are no nodes.
    pub fn embed_blocks<B: Copy>(&mut self, blocks: &[B], lanes: usize, limit: usize) -> bool {
        let block_bytes = std::mem::size_of::<B>();
        assert!(block_bytes.is_multiple_of(EMBED_UNIT) && std::mem::align_of::<B>() <= 64);
        if self.nodes.is_empty() {
            return false;
        }
        let layout = BlockLayout {
            blocks: bytes_of(blocks),
            block_bytes,
            lanes,
        };
        // Counted first, then written where it was counted.
        let mut counted = Arena {
            bytes: &mut [],
            len: 0,
        };
        self.embed_node(0, &layout, &mut counted);
        if counted.len > limit.min(EMBED_LIMIT) {
            return false;
        }
        let mut nodes = vec![self.nodes[0]; counted.len.div_ceil(NODE_BYTES as usize)];
        // SAFETY: nodes are plain data; any bytes written over them are as plain.
        let bytes = unsafe {
            std::slice::from_raw_parts_mut(
                nodes.as_mut_ptr() as *mut u8,
                std::mem::size_of_val(&*nodes),
            )
        };
        self.embed_node(0, &layout, &mut Arena { bytes, len: 0 });
        self.nodes = nodes.into();
        self.embedded = true;
        true
    }

    /// The leaves' blocks lie among the nodes ([`Bvh::embed_blocks`]).
    pub fn is_embedded(&self) -> bool {
        self.embedded
    }

    /// Lays out node `index` in `arena` with the blocks of its leaf children, then its
    /// interior children's subtrees; returns its new reference.
    fn embed_node(&self, index: usize, layout: &BlockLayout, arena: &mut Arena) -> u32 {
        // Past EMBED_LIMIT only while counting: the references made then are dropped.
        let at = arena.take(std::mem::align_of::<Node>(), NODE_BYTES as usize);
        let original = self.nodes[index];
        let mut node = original;
        let used = |slot: usize| original.used & (1 << slot) != 0;
        let leaf = |slot: usize| is_leaf(original.children[slot]);
        for slot in (0..WIDTH).filter(|&s| used(s) && leaf(s)) {
            let (start, count) = leaf_run(original.children[slot]);
            let first = start / layout.lanes * layout.block_bytes;
            let end = first + count.div_ceil(layout.lanes) * layout.block_bytes;
            let place = arena.take(EMBED_UNIT, end - first);
            arena.put(place, &layout.blocks[first..end]);
            node.children[slot] = leaf_reference(place / EMBED_UNIT, count);
        }
        for slot in (0..WIDTH).filter(|&s| used(s) && !leaf(s)) {
            let child = original.children[slot] / NODE_BYTES;
            node.children[slot] = self.embed_node(child as usize, layout, arena);
        }
        arena.put(at, bytes_of(std::slice::from_ref(&node)));
        at as u32
    }

    /// The nodes and, after [`Bvh::embed_blocks`], the blocks among them, as bytes.
    pub fn embedded(&self) -> &[u8] {
        bytes_of(&self.nodes)
    }

    /// The node whose reference is `offset` (see [`LEAF_FLAG`]).
    #[inline(always)]
    fn node_at(&self, offset: usize) -> &Node {
        debug_assert!(offset.is_multiple_of(std::mem::align_of::<Node>()));
        debug_assert!(offset + NODE_BYTES as usize <= self.embedded().len());
        // SAFETY: interior references are byte offsets of nodes, written by
        // `flatten_children` or `embed_node`.
        unsafe {
            &*(self.nodes.as_ptr() as *const u8)
                .add(offset)
                .cast::<Node>()
        }
    }

    /// The tree's surface-area-heuristic cost, as Embree's statistics give it: for nodes,
    /// the sum of their boxes' areas; for leaves, of their boxes' areas times the blocks of
    /// `block` items each holds; both relative to the root's box. A ray crossing the root
    /// visits, on average (uniformly distributed rays), that many nodes and tests that many
    /// blocks: what a better tree lowers.
    pub fn sah_cost(&self, block: usize) -> SahCost {
        let mut cost = SahCost::default();
        if self.nodes.is_empty() {
            return cost;
        }
        let root = self.node_at(0);
        let mut whole = Aabb::EMPTY;
        for b in root.slots().map(|s| root.child_box(s)) {
            whole.grow(&b.lo, &b.hi);
        }
        let root_area = whole.half_area();
        // (reference, its box's half area)
        let mut pending = vec![(0u32, root_area)];
        while let Some((reference, area)) = pending.pop() {
            let node = self.node_at(reference as usize);
            cost.nodes += (area / root_area) as f64;
            for s in node.slots() {
                let (child, child_area) = (node.children[s], node.child_box(s).half_area());
                if is_leaf(child) {
                    let blocks = leaf_run(child).1.div_ceil(block.max(1));
                    cost.leaves += (child_area / root_area) as f64 * blocks as f64;
                } else {
                    pending.push((child, child_area));
                }
            }
        }
        cost
    }

    /// After [`Bvh::embed_blocks`], every leaf's run: its first block's place in
    /// [`Bvh::embedded`] in [`EMBED_UNIT`]s, and how many items it holds.
    pub fn embedded_leaves(&self) -> Vec<(usize, usize)> {
        assert!(self.embedded, "the BVH holds no blocks");
        let mut leaves = Vec::new();
        let mut pending = if self.nodes.is_empty() {
            vec![]
        } else {
            vec![0u32]
        };
        while let Some(reference) = pending.pop() {
            let node = self.node_at(reference as usize);
            for slot in node.slots() {
                let child = node.children[slot];
                if is_leaf(child) {
                    leaves.push(leaf_run(child));
                } else {
                    pending.push(child);
                }
            }
        }
        leaves
    }

    /// [`Bvh::traverse`] handing each leaf as its run of positions in the leaf order.
    /// `items` says where the runs' items lie, so that a leaf's items can be fetched ahead
    /// of their test.
    #[inline]
    pub fn traverse_runs<L: LeafPlaces>(
        &self,
        ray: &Ray,
        t_max: f64,
        items: L,
        visit: impl FnMut(Range<usize>, &mut f64) -> bool,
    ) {
        self.traverse_dispatch::<true, false, L>(ray, t_max, items, visit);
    }

    /// [`Bvh::traverse_runs`] for a caller that stops at any hit, such as a shadow ray: the
    /// leaves come in no particular order, which spares sorting the children of each node,
    /// and `visit` must not lower `t_max` (it stops instead), which spares comparing each
    /// waiting child's distance with it. `coherence` chooses how the next child is taken
    /// (see [`Coherence`]); the leaves visited are the same.
    #[inline]
    pub fn traverse_runs_any_order<L: LeafPlaces>(
        &self,
        ray: &Ray,
        t_max: f64,
        items: L,
        coherence: Coherence,
        visit: impl FnMut(Range<usize>, &mut f64) -> bool,
    ) {
        match coherence {
            Coherence::Incoherent => {
                self.traverse_dispatch::<false, false, L>(ray, t_max, items, visit)
            }
            Coherence::Coherent => {
                self.traverse_dispatch::<false, true, L>(ray, t_max, items, visit)
            }
        }
    }

    #[inline(always)]
    fn traverse_dispatch<const NEAREST_FIRST: bool, const BY_BRANCH: bool, L: LeafPlaces>(
        &self,
        ray: &Ray,
        t_max: f64,
        items: L,
        visit: impl FnMut(Range<usize>, &mut f64) -> bool,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx") && std::is_x86_feature_detected!("fma") {
            // SAFETY: the CPU has AVX and FMA.
            return unsafe {
                self.traverse_avx::<NEAREST_FIRST, BY_BRANCH, L>(ray, t_max, items, visit)
            };
        }
        let r = BoxRay::new(ray);
        self.traverse_with::<NEAREST_FIRST, BY_BRANCH, L>(t_max, items, visit, |planes, far| {
            r.test8(planes, F4::splat(far))
        });
    }

    /// The traversal with eight boxes tested per AVX instruction.
    ///
    /// # Safety
    /// The CPU must support AVX and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,fma")]
    unsafe fn traverse_avx<const NEAREST_FIRST: bool, const BY_BRANCH: bool, L: LeafPlaces>(
        &self,
        ray: &Ray,
        t_max: f64,
        items: L,
        visit: impl FnMut(Range<usize>, &mut f64) -> bool,
    ) {
        // SAFETY: this function runs only where the CPU has AVX and FMA.
        let wide = unsafe { BoxRayAvx::new(ray) };
        self.traverse_with::<NEAREST_FIRST, BY_BRANCH, L>(
            t_max,
            items,
            visit,
            |planes, far| unsafe { wide.test8(planes, far) },
        );
    }

    /// The traversal, with `test(planes, far)` giving a node's eight entry distances and
    /// the mask of the children the ray crosses before `far`. `BY_BRANCH` (any order only):
    /// the first hit child is taken through [`child_by_branch`].
    #[inline(always)]
    fn traverse_with<const NEAREST_FIRST: bool, const BY_BRANCH: bool, L: LeafPlaces>(
        &self,
        t_max: f64,
        items: L,
        mut visit: impl FnMut(Range<usize>, &mut f64) -> bool,
        test: impl Fn(&[[f32; WIDTH]; 6], f32) -> ([f32; WIDTH], u32),
    ) {
        let mut t_max = t_max;
        let mut far = round_up_distance(t_max);
        // Uninitialised: only entries below `top`, all written first, are read.
        let mut stack = [MaybeUninit::<u64>::uninit(); STACK];
        let mut top = 0usize;
        // A reference widened once where it is read: kept as u32, it is widened again
        // before every use as an offset.
        let mut current = 0usize;
        loop {
            if is_leaf(current as u32) {
                let (start, count) = leaf_run(current as u32);
                let before = t_max;
                if !visit(start..start + count, &mut t_max) {
                    return;
                }
                // In any order, `visit` stops instead of lowering `t_max`; most leaves
                // leave it as it was.
                if NEAREST_FIRST && t_max != before {
                    far = round_up_distance(t_max);
                }
            } else {
                let node = self.node_at(current);
                let (near, hits) = test(&node.planes, far);
                // Eight lanes: indices below stay under eight.
                let mut hits = hits & node.used & 0xFF;
                if hits != 0 {
                    let first = hits.trailing_zeros() as usize & 7;
                    hits &= hits - 1;
                    // Asked for whether a leaf (whose blocks the test reads after a call) or
                    // a node (read next anyway): which one it is, is a coin toss to the
                    // branch predictor.
                    self.prefetch(node.children[first], items);
                    let next = if BY_BRANCH {
                        child_by_branch(&node.children, first)
                    } else {
                        node.children[first]
                    };
                    if hits == 0 {
                        current = next as usize;
                        continue;
                    }
                    if !NEAREST_FIRST {
                        // Any order will do (as for shadow rays): no distances kept, since
                        // `t_max` never falls below one of a child already found to cross.
                        current = next as usize;
                        while hits != 0 {
                            let i = hits.trailing_zeros() as usize & 7;
                            hits &= hits - 1;
                            self.prefetch(node.children[i], items);
                            debug_assert!(top < STACK);
                            // SAFETY: `top` stays below STACK (see there).
                            unsafe {
                                stack
                                    .get_unchecked_mut(top)
                                    .write(waiting(node.children[i], 0.0))
                            };
                            top += 1;
                        }
                        continue;
                    }
                    // The nearest hit child is visited next, chosen by a branch: where it is
                    // predicted, the child's load need not wait for the distances. The
                    // others wait on the stack, nearest on top, put in place without
                    // branches: how far an entry sinks is a coin toss on incoherent rays.
                    let mut best = waiting(node.children[first], near[first]);
                    let base = top;
                    while hits != 0 {
                        let i = hits.trailing_zeros() as usize & 7;
                        hits &= hits - 1;
                        let mut farther = waiting(node.children[i], near[i]);
                        self.prefetch(node.children[i], items);
                        if farther < best {
                            std::mem::swap(&mut farther, &mut best);
                        }
                        // Insert keeping [base, top) sorted by decreasing distance: the new
                        // entry sinks past every nearer one, each step a minimum and a
                        // maximum.
                        debug_assert!(top < STACK);
                        // SAFETY: `top` stays below STACK (see there); entries in [base, top)
                        // were written above.
                        unsafe {
                            stack.get_unchecked_mut(top).write(farther);
                            for j in (base + 1..=top).rev() {
                                let below = stack.get_unchecked(j - 1).assume_init();
                                let above = stack.get_unchecked(j).assume_init();
                                stack.get_unchecked_mut(j - 1).write(below.max(above));
                                stack.get_unchecked_mut(j).write(below.min(above));
                            }
                        }
                        top += 1;
                    }
                    current = best as u32 as usize;
                    continue;
                }
            }
            // Pop the nearest waiting child still in reach.
            let limit = far;
            loop {
                if top == 0 {
                    return;
                }
                top -= 1;
                // SAFETY: entries below `top` were written when pushed.
                let next = unsafe { stack.get_unchecked(top).assume_init() };
                if !NEAREST_FIRST || f32::from_bits((next >> 32) as u32) <= limit {
                    current = next as u32 as usize;
                    break;
                }
            }
        }
    }
}

/// How the rays a thread traces one after another relate, a hint for the any-hit walk
/// ([`Bvh::traverse_runs_any_order`]), as Embree's coherent and incoherent context flags
/// are: it changes the time, never the hits.
///
/// The walk's next node is a node's first hit child. Read at a slot worked out from the
/// box test, its load waits for the test, node after node. Read through a branch on the
/// slot, it starts as soon as the branch is predicted, and neighbouring rays take the same
/// children, so the predictor learns them; on rays unlike each other the branch is a coin
/// toss, and a mispredicted one costs more than the wait. On the 2-core Zen 3 of
/// docs/acceleration.md, any hit by branch ran 5–7 % faster on the bunny's and the dragon's
/// camera rays and 3–8 % slower on their incoherent rays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Coherence {
    /// Each ray unlike the one before, as a path tracer's bounces or rays sampled at random:
    /// the next child is read at the slot the test gives.
    #[default]
    Incoherent,
    /// Rays that follow their neighbours, as camera rays through neighbouring pixels or
    /// shadow rays from neighbouring points to one light: the next child is read through a
    /// branch on its slot.
    Coherent,
}

/// Child `slot` of `children`, read at an address a branch on `slot` picks (a jump table)
/// rather than one computed from it: where the branch is predicted, the load need not wait
/// for the box test that chose the slot.
#[inline(always)]
fn child_by_branch(children: &[u32; WIDTH], slot: usize) -> u32 {
    macro_rules! read {
        ($k:literal) => {{
            // An empty statement, different in each arm, so that LLVM cannot fold the arms
            // back into one load at a computed address.
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the statement is a comment; it reads and writes nothing.
            unsafe {
                std::arch::asm!(
                    concat!("/* slot ", $k, " */"),
                    options(nomem, nostack, preserves_flags)
                )
            };
            children[$k]
        }};
    }
    match slot {
        0 => read!(0),
        1 => read!(1),
        2 => read!(2),
        3 => read!(3),
        4 => read!(4),
        5 => read!(5),
        6 => read!(6),
        _ => read!(7),
    }
}

/// A BVH's expected cost per ray crossing its root ([`Bvh::sah_cost`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SahCost {
    /// Nodes visited.
    pub nodes: f64,
    /// Leaf blocks tested.
    pub leaves: f64,
}

/// A child waiting on the traversal stack: its entry distance, never negative, in the high
/// half and its reference in the low half. Non-negative floats order as their bits, so the
/// nearer of two entries is the smaller number.
#[inline(always)]
fn waiting(child: u32, near: f32) -> u64 {
    (u64::from(near.to_bits()) << 32) | u64::from(child)
}

/// The caller's blocks for [`Bvh::embed_blocks`], as bytes: `lanes` items to a block.
struct BlockLayout<'a> {
    blocks: &'a [u8],
    block_bytes: usize,
    lanes: usize,
}

/// Bytes being laid out: only counted where `bytes` is empty, else written too.
struct Arena<'a> {
    bytes: &'a mut [u8],
    len: usize,
}

impl Arena<'_> {
    /// Room for `n` bytes from the next multiple of `align`: where they start.
    fn take(&mut self, align: usize, n: usize) -> usize {
        let at = self.len.next_multiple_of(align);
        self.len = at + n;
        at
    }

    fn put(&mut self, at: usize, data: &[u8]) {
        if !self.bytes.is_empty() {
            self.bytes[at..at + data.len()].copy_from_slice(data);
        }
    }
}

/// Where the items a leaf's run indexes lie, for prefetching: from the start of `items`,
/// `STRIDE` bytes per unit of a run's start (an item, or an [`EMBED_UNIT`] of embedded
/// blocks; a constant, so that the traversal multiplies by an immediate and keeps no
/// register for it).
#[derive(Clone, Copy)]
pub struct LeafItems<const STRIDE: usize> {
    base: *const u8,
}

impl<const STRIDE: usize> LeafItems<STRIDE> {
    /// Items laid out from the start of `items`, such as a mesh's blocks of four triangles
    /// (a block's size over four).
    pub fn at<T>(items: &[T]) -> LeafItems<STRIDE> {
        LeafItems {
            base: items.as_ptr() as *const u8,
        }
    }
}

/// The blocks [`Bvh::embed_blocks`] laid out among the nodes, [`EMBED_UNIT`]s from the
/// start of the nodes' array: found from the nodes' address, which the traversal holds
/// anyway, so that theirs takes no register of its own.
#[derive(Clone, Copy)]
pub struct AmongNodes;

/// Where a leaf's items lie, for prefetching: [`LeafItems`] or [`AmongNodes`].
pub trait LeafPlaces: Copy {
    /// Where child `reference` of a BVH whose nodes are at `nodes` starts, or an address
    /// on the same cache line: its node, or its leaf's items.
    fn fetch_address(self, nodes: *const u8, reference: u32) -> *const u8;
}

impl<const STRIDE: usize> LeafPlaces for LeafItems<STRIDE> {
    #[inline(always)]
    fn fetch_address(self, nodes: *const u8, reference: u32) -> *const u8 {
        let node = nodes.wrapping_add(reference as usize);
        let leaf = self.base.wrapping_add(leaf_run(reference).0 * STRIDE);
        std::hint::select_unpredictable(is_leaf(reference), leaf, node)
    }
}

impl LeafPlaces for AmongNodes {
    /// The reference itself: see [`LEAF_FLAG`].
    #[inline(always)]
    fn fetch_address(self, nodes: *const u8, reference: u32) -> *const u8 {
        nodes.wrapping_add(reference as usize)
    }
}

/// Appends a node holding `children` (at most eight), then their subtrees depth-first,
/// and returns its reference.
fn flatten_children(nodes: &mut Vec<Node>, children: &[BuildNode]) -> u32 {
    let index = nodes.len();
    assert!(
        index < (u32::MAX / NODE_BYTES) as usize,
        "too many nodes for a BVH node reference"
    );
    let mut node = Node {
        planes: [
            [f32::INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
        ],
        children: [EMPTY; WIDTH],
        used: (1 << children.len()) - 1,
    };
    for (slot, child) in children.iter().enumerate() {
        let b = child.bounds();
        for a in 0..3 {
            node.planes[a][slot] = b.lo[a];
            node.planes[3 + a][slot] = b.hi[a];
        }
    }
    nodes.push(node);
    for (slot, child) in children.iter().enumerate() {
        let reference = match child {
            BuildNode::Leaf { start, count, .. } => {
                leaf_reference(*start as usize, *count as usize)
            }
            BuildNode::Inner { children, .. } => flatten_children(nodes, children),
        };
        nodes[index].children[slot] = reference;
    }
    index as u32 * NODE_BYTES
}

struct Builder {
    leaf: LeafSize,
}

impl Builder {
    /// Builds the binary tree over `items`, which start at `offset` in the final item
    /// order, split down to runs of one block and planned for the collapse (see [`Binary`]).
    fn build(&self, items: &mut [Item], offset: usize, depth: usize) -> Binary {
        let bounds = Aabb::of(items);
        let n = items.len();
        let children = self.split(items, depth).map(|mid| {
            let (first, second) = items.split_at_mut(mid);
            let (first, second) = if n > PARALLEL_ITEMS {
                rayon::join(
                    || self.build(first, offset, depth + 1),
                    || self.build(second, offset + mid, depth + 1),
                )
            } else {
                (
                    self.build(first, offset, depth + 1),
                    self.build(second, offset + mid, depth + 1),
                )
            };
            Box::new([first, second])
        });
        Binary::planned(bounds, offset, n, children, &self.leaf)
    }

    /// Partitions `items` by the cheapest binned SAH split over the three axes and returns
    /// the size of the first part; `None` for a run of one block. Splitting a block's items
    /// further lowered the SAH cost by 0.4 % and cost a longer build and 6–8 % more bytes
    /// (smaller leaves, more padding), at the same speed.
    fn split(&self, items: &mut [Item], depth: usize) -> Option<usize> {
        let n = items.len();
        if n <= self.leaf.block {
            return None;
        }
        if depth + 2 >= MAX_DEPTH {
            // Halve the run: every level below then at least halves, which bounds the depth
            // (and the traversal stack) whatever the boxes.
            return Some(n / 2);
        }
        let mut centers = Aabb::EMPTY;
        for it in items.iter() {
            let c = [it.center2(0), it.center2(1), it.center2(2)];
            centers.grow(&c, &c);
        }
        let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, last bin on the left)
        for axis in 0..3 {
            let (lo, hi) = (centers.lo[axis], centers.hi[axis]);
            if hi <= lo {
                continue;
            }
            let scale = BINS as f32 / (hi - lo);
            let mut bins = [Aabb::EMPTY; BINS];
            let mut counts = [0usize; BINS];
            for it in items.iter() {
                let b = (((it.center2(axis) - lo) * scale) as usize).min(BINS - 1);
                bins[b].grow(&it.lo, &it.hi);
                counts[b] += 1;
            }
            let mut right_cost = [0.0f32; BINS];
            let (mut acc, mut count) = (Aabb::EMPTY, 0);
            for i in (1..BINS).rev() {
                acc.grow(&bins[i].lo, &bins[i].hi);
                count += counts[i];
                right_cost[i] = acc.half_area() * self.leaf.blocks(count) as f32;
            }
            let (mut acc, mut count) = (Aabb::EMPTY, 0);
            for i in 0..BINS - 1 {
                acc.grow(&bins[i].lo, &bins[i].hi);
                count += counts[i];
                let cost = acc.half_area() * self.leaf.blocks(count) as f32 + right_cost[i + 1];
                if count > 0 && count < n && best.is_none_or(|b| cost < b.0) {
                    best = Some((cost, axis, i));
                }
            }
        }
        let Some((_, axis, last)) = best else {
            // Every centroid coincides: halve the run.
            return Some(n / 2);
        };
        let (lo, hi) = (centers.lo[axis], centers.hi[axis]);
        let scale = BINS as f32 / (hi - lo);
        Some(partition(items, |it| {
            ((((it.center2(axis) - lo) * scale) as usize).min(BINS - 1)) <= last
        }))
    }
}

/// A node of the binary tree, planned for its collapse into eight-wide nodes by the
/// optimal collapse of Ylitie, Karras and Laine (2017): bottom up, each node keeps the
/// least SAH cost of its subtree spread over at most j slots of a wide node, for j up to
/// eight; top down, the root then takes the cheapest plan and each node's slots are shared
/// out as planned. Costs are in units of a node visit times its box's half area; a leaf
/// costs as [`LeafSize`] says.
struct Binary {
    bounds: Aabb,
    start: u32,
    count: u32,
    children: Option<Box<[Binary; 2]>>,
    /// `cost[j - 1]`: the subtree's least cost in at most `j` slots.
    cost: [f32; WIDTH],
    /// `split[j - 1]`: how many of those `j` slots the first child's subtree takes in the
    /// cheapest plan, or 0 where the subtree takes one slot.
    split: [u8; WIDTH],
    /// In one slot: a leaf, or else a node whose eight slots the children share as
    /// `node_split` says.
    leaf: bool,
    node_split: u8,
}

impl Binary {
    fn planned(
        bounds: Aabb,
        start: usize,
        count: usize,
        children: Option<Box<[Binary; 2]>>,
        leaf: &LeafSize,
    ) -> Binary {
        let area = bounds.half_area();
        let leaf_cost = if count <= leaf.max_leaf {
            area * leaf.cost(count)
        } else {
            f32::INFINITY
        };
        let mut plan = Binary {
            bounds,
            start: start as u32,
            count: count as u32,
            children: None,
            cost: [leaf_cost; WIDTH],
            split: [0; WIDTH],
            leaf: true,
            node_split: 0,
        };
        let Some(children) = children else {
            return plan;
        };
        let [first, second] = &*children;
        // The least cost in j slots, at least one for each child, and the first one's share
        // (one slot where no cost is finite: boxes too large for f32 areas).
        let mut shared = [(f32::INFINITY, 1u8); WIDTH];
        for j in 2..=WIDTH {
            for k in 1..j {
                let cost = first.cost[k - 1] + second.cost[j - k - 1];
                if cost < shared[j - 1].0 {
                    shared[j - 1] = (cost, k as u8);
                }
            }
        }
        let node_cost = area + shared[WIDTH - 1].0;
        plan.leaf = count <= leaf.max_leaf && leaf_cost <= node_cost;
        plan.node_split = shared[WIDTH - 1].1;
        let one_slot = if plan.leaf { leaf_cost } else { node_cost };
        for j in 1..=WIDTH {
            (plan.cost[j - 1], plan.split[j - 1]) = if j > 1 && shared[j - 1].0 < one_slot {
                shared[j - 1]
            } else {
                (one_slot, 0)
            };
        }
        plan.children = Some(children);
        plan
    }

    /// The subtree in one slot, as planned: a leaf, or a node.
    fn into_wide(self) -> BuildNode {
        match self.children {
            Some(children) if !self.leaf => {
                let mut slots = Vec::with_capacity(WIDTH);
                let [first, second] = *children;
                let k = self.node_split as usize;
                first.into_slots(k, &mut slots);
                second.into_slots(WIDTH - k, &mut slots);
                BuildNode::Inner {
                    bounds: self.bounds,
                    children: slots,
                }
            }
            _ => BuildNode::Leaf {
                bounds: self.bounds,
                start: self.start,
                count: self.count,
            },
        }
    }

    /// Appends the subtree as planned for at most `slots` slots.
    fn into_slots(self, slots: usize, out: &mut Vec<BuildNode>) {
        let k = self.split[slots - 1] as usize;
        if k == 0 {
            out.push(self.into_wide());
            return;
        }
        let [first, second] = *self
            .children
            .expect("slots are shared only between children");
        first.into_slots(k, out);
        second.into_slots(slots - k, out);
    }
}

/// Moves the items satisfying `pred` to the front; returns how many there are.
fn partition<T>(items: &mut [T], pred: impl Fn(&T) -> bool) -> usize {
    let mut first = 0;
    for i in 0..items.len() {
        if pred(&items[i]) {
            items.swap(first, i);
            first += 1;
        }
    }
    first
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Leaves of at most `max_leaf` items, `block` to a test, each test costing a node visit.
    fn sizes(max_leaf: usize, block: usize) -> LeafSize {
        LeafSize {
            max_leaf,
            block,
            leaf_cost: 1.0,
            block_cost: 1.0,
        }
    }

    /// The cost of a wide subtree, worked out from the tree itself.
    fn wide_cost(node: &BuildNode, leaf: &LeafSize) -> f32 {
        match node {
            BuildNode::Leaf { bounds, count, .. } => {
                bounds.half_area() * leaf.cost(*count as usize)
            }
            BuildNode::Inner { bounds, children } => {
                bounds.half_area() + children.iter().map(|c| wide_cost(c, leaf)).sum::<f32>()
            }
        }
    }

    /// Every collapse of a binary subtree into wide slots, as (cost, slots), by exhaustive
    /// enumeration: a leaf where it may be one; each collapse of the first child beside each
    /// of the second's; and a node over the cheapest of those that fit in its slots.
    fn every_collapse(node: &Binary, leaf: &LeafSize) -> Vec<(f32, usize)> {
        let area = node.bounds.half_area();
        let mut all = Vec::new();
        if node.count as usize <= leaf.max_leaf {
            all.push((area * leaf.cost(node.count as usize), 1));
        }
        if let Some(children) = &node.children {
            let second = every_collapse(&children[1], leaf);
            let mut fitting = f32::INFINITY;
            for (a, m) in every_collapse(&children[0], leaf) {
                for &(b, n) in &second {
                    if m + n <= WIDTH {
                        all.push((a + b, m + n));
                        fitting = fitting.min(a + b);
                    }
                }
            }
            all.push((area + fitting, 1));
        }
        all
    }

    /// `n` boxes at random (a fixed linear congruential sequence from `seed`) in the unit
    /// cube, of sizes from 0.01 to 0.3.
    fn random_boxes(n: usize, seed: u64) -> Vec<Bounds3> {
        use crate::math::Vec3;
        let mut state = seed;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f64 / (1u64 << 24) as f64
        };
        (0..n)
            .map(|_| {
                let c = Vec3::new(next(), next(), next());
                let size = Vec3::new(next(), next(), next()) * 0.29 + Vec3::ONE * 0.01;
                Bounds3::new(c, c + size)
            })
            .collect()
    }

    fn items_of(boxes: &[Bounds3]) -> Vec<Item> {
        boxes
            .iter()
            .enumerate()
            .map(|(i, b)| Item {
                lo: [0, 1, 2].map(|a| b.min[a] as f32),
                hi: [0, 1, 2].map(|a| b.max[a] as f32),
                index: i as u32,
            })
            .collect()
    }

    /// Boxes along a noisy curve, so leaves of every size occur.
    fn curve_boxes() -> Vec<Bounds3> {
        use crate::math::Vec3;
        (0..1000)
            .map(|i| {
                let x = i as f64 * 0.01;
                let c = Vec3::new(x, (7.0 * x).sin(), ((i * 37) % 11) as f64 * 0.05);
                Bounds3::new(c, c + Vec3::ONE * 0.02)
            })
            .collect()
    }

    #[test]
    fn the_sah_cost_counts_nodes_and_leaf_blocks_by_area() {
        use crate::math::Vec3;
        // Two unit cubes nine apart: the root's box is 10 × 1 × 1 (half area 21), each
        // cube's 3. Tested one at a time, the pair is worth splitting: one node (the root,
        // crossed by every ray) and two leaves of one block, each crossed by 3/21 of rays.
        let cube = |x: f64| Bounds3::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 1.0, 1.0));
        let bvh = Bvh::build(&[cube(0.0), cube(9.0)], sizes(8, 1));
        let cost = bvh.sah_cost(1);
        assert!((cost.nodes - 1.0).abs() < 1e-6, "{cost:?}");
        assert!((cost.leaves - 6.0 / 21.0).abs() < 1e-6, "{cost:?}");
        // Tested four at a time, one leaf of one block holds both: splitting saves nothing.
        let bvh = Bvh::build(&[cube(0.0), cube(9.0)], sizes(8, 4));
        assert_eq!(
            bvh.sah_cost(4),
            SahCost {
                nodes: 1.0,
                leaves: 1.0
            }
        );
        assert_eq!(Bvh::build(&[], sizes(8, 4)).sah_cost(4), SahCost::default());
    }

    #[test]
    fn children_are_visited_nearest_first() {
        use crate::math::Vec3;
        // A row of 300 unit boxes in x, spread out in y and z so that eight-wide nodes hold
        // boxes side by side: a ray down the row must meet every box crossing it in order,
        // whichever way it runs, and any order must still meet them all.
        let boxes: Vec<Bounds3> = (0..300)
            .map(|i| {
                let c = Vec3::new(i as f64 * 1.5, (i % 5) as f64 * 0.1, (i % 3) as f64 * 0.1);
                Bounds3::new(c, c + Vec3::ONE)
            })
            .collect();
        let bvh = Bvh::build(&boxes, sizes(1, 1));
        for (origin, direction) in [(-5.0, 1.0), (500.0, -1.0)] {
            let ray = Ray::new(
                Vec3::new(origin, 0.55, 0.55),
                Vec3::new(direction, 0.0, 0.0),
            );
            let mut met = Vec::new();
            bvh.traverse(&ray, f64::INFINITY, |items, _| {
                met.extend_from_slice(items);
                true
            });
            let mut expected: Vec<u32> = (0..300).collect();
            if direction < 0.0 {
                expected.reverse();
            }
            assert_eq!(met, expected, "direction {direction}");
            // Either coherence hint: the same boxes in the same order.
            let items = LeafItems::<{ std::mem::size_of::<u32>() }>::at(&bvh.order);
            let any_order = |coherence| {
                let mut met = Vec::new();
                bvh.traverse_runs_any_order(&ray, f64::INFINITY, items, coherence, |run, _| {
                    met.extend(bvh.order[run].iter().copied());
                    true
                });
                met
            };
            let mut any = any_order(Coherence::Incoherent);
            assert_eq!(any_order(Coherence::Coherent), any, "direction {direction}");
            any.sort();
            assert_eq!(any, (0..300).collect::<Vec<u32>>(), "direction {direction}");
        }
    }

    #[test]
    fn padded_order_starts_every_leaf_on_a_block() {
        let boxes = curve_boxes();
        let mut bvh = Bvh::build(&boxes, sizes(8, 4));
        let order = bvh.take_padded_order(4);
        assert_eq!(order.len() % 4, 0);
        let mut seen = vec![0; boxes.len()];
        let mut covered = vec![false; order.len()];
        for node in bvh.nodes.iter() {
            for (slot, &child) in node.children.iter().enumerate() {
                if node.used & (1 << slot) == 0 || !is_leaf(child) {
                    continue;
                }
                let (start, count) = leaf_run(child);
                assert_eq!(start % 4, 0, "a leaf starts inside a block");
                for (k, &item) in order[start..start + count.next_multiple_of(4)]
                    .iter()
                    .enumerate()
                {
                    covered[start + k] = true;
                    if k < count {
                        seen[item as usize] += 1;
                    } else {
                        assert_eq!(item, crate::accel::PAD);
                    }
                }
            }
        }
        assert!(
            seen.iter().all(|&n| n == 1),
            "every item in exactly one leaf"
        );
        assert!(covered.iter().all(|&c| c), "no slot outside a leaf");
    }

    #[test]
    fn leaf_references_keep_their_run_apart_from_node_references() {
        for count in 1..=MAX_LEAF_ITEMS {
            for start in [0, 1, 5, 4096, (1 << (32 - START_SHIFT)) - 1] {
                let reference = leaf_reference(start, count);
                assert!(is_leaf(reference));
                assert_eq!(leaf_run(reference), (start, count));
            }
        }
        // Nodes start on cache lines: their offsets never carry the flag.
        for index in [0, 1, 7, 1 << 20] {
            assert!(!is_leaf(index * NODE_BYTES));
        }
        assert!(std::panic::catch_unwind(|| leaf_reference(0, MAX_LEAF_ITEMS + 1)).is_err());
        assert!(std::panic::catch_unwind(|| leaf_reference(1 << 28, 1)).is_err());
    }

    #[test]
    fn embedded_blocks_follow_their_node_and_are_visited_as_before() {
        use crate::math::Vec3;
        let boxes = curve_boxes();
        let mut bvh = Bvh::build(&boxes, sizes(8, 4));
        let order = bvh.take_padded_order(4);
        // Blocks of four item numbers: 16 bytes, one unit.
        let blocks: Vec<[u32; 4]> = order.chunks(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
        let before = bvh.clone();
        let mut small = bvh.clone();
        assert!(!small.embed_blocks(&blocks, 4, 1024), "over the limit");
        assert!(!small.is_embedded());
        assert!(bvh.embed_blocks(&blocks, 4, EMBED_LIMIT));
        let bytes = bvh.embedded();
        let items_at = |place: usize, count: usize| -> Vec<u32> {
            let run = &bytes[place * EMBED_UNIT..][..count.next_multiple_of(4) * 4];
            run.chunks(4)
                .map(|b| u32::from_ne_bytes(b.try_into().unwrap()))
                .collect()
        };
        // Each node's leaf children, in slot order, right after it.
        let mut seen = vec![0; boxes.len()];
        let mut pending = vec![0usize];
        while let Some(at) = pending.pop() {
            let node: Node = unsafe { std::ptr::read(bytes[at..].as_ptr() as *const Node) };
            let mut next = at + NODE_BYTES as usize;
            for slot in node.slots() {
                let child = node.children[slot];
                if !is_leaf(child) {
                    pending.push(child as usize);
                    continue;
                }
                let (place, count) = leaf_run(child);
                assert_eq!(
                    place * EMBED_UNIT,
                    next,
                    "a leaf's blocks away from its node"
                );
                // Read as a byte offset from the base (on a cache line's start), the
                // reference names the line the leaf's first block starts on.
                assert_eq!(
                    AmongNodes.fetch_address(std::ptr::null(), child) as usize / 64,
                    place * EMBED_UNIT / 64
                );
                next += count.div_ceil(4) * EMBED_UNIT;
                let items = items_at(place, count);
                items[..count].iter().for_each(|&i| seen[i as usize] += 1);
                assert!(items[count..].iter().all(|&i| i == crate::accel::PAD));
            }
        }
        assert!(
            seen.iter().all(|&n| n == 1),
            "every item in exactly one leaf"
        );
        assert_eq!(
            bvh.embedded_leaves()
                .iter()
                .map(|&(_, count)| count)
                .sum::<usize>(),
            boxes.len()
        );
        // The same leaves, in the same order, for rays in every direction (seed-free:
        // directions on a spiral).
        let mut visited = 0;
        for k in 0..200 {
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / 200.0;
            let phi = k as f64 * 2.399963;
            let r = (1.0 - z * z).sqrt();
            let direction = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            let ray = Ray::new(Vec3::new(5.0, 0.0, 0.25), direction);
            let mut old = Vec::new();
            let mut new = Vec::new();
            before.traverse_runs(&ray, f64::INFINITY, LeafItems::<4>::at(&order), |run, _| {
                old.extend_from_slice(&order[run]);
                true
            });
            bvh.traverse_runs(
                &ray,
                f64::INFINITY,
                LeafItems::<EMBED_UNIT>::at(bytes),
                |run, _| {
                    new.extend(items_at(run.start, run.len()).into_iter().take(run.len()));
                    true
                },
            );
            assert_eq!(old, new, "ray {k}");
            visited += old.len();
        }
        assert!(visited > 100, "the rays reach leaves ({visited} items)");
    }

    #[test]
    fn the_collapse_is_the_cheapest_there_is() {
        // Against every collapse, enumerated, of small random sets, for each number of slots
        // up to eight; leaves of up to 8 items in blocks of 4 (as a mesh's) and up to 4
        // items one by one (as a scene's).
        let mesh = LeafSize {
            leaf_cost: 1.25,
            block_cost: 0.25,
            ..sizes(8, 4)
        };
        for (seed, n) in [(1, 3), (2, 7), (3, 10), (4, 12), (5, 12)] {
            for leaf in [mesh, sizes(4, 1)] {
                let mut items = items_of(&random_boxes(n, seed));
                let root = Builder { leaf }.build(&mut items, 0, 0);
                let all = every_collapse(&root, &leaf);
                for j in 1..=WIDTH {
                    let least = all
                        .iter()
                        .filter(|&&(_, slots)| slots <= j)
                        .map(|&(cost, _)| cost)
                        .fold(f32::INFINITY, f32::min);
                    let planned = root.cost[j - 1];
                    assert!(
                        (planned - least).abs() <= 1e-5 * least,
                        "seed {seed}, {j} slots: planned {planned}, least {least}"
                    );
                }
            }
        }
    }

    #[test]
    fn boxes_too_large_for_f32_areas_still_make_a_tree() {
        use crate::math::Vec3;
        // Areas overflow to infinity (and 0 · ∞ to NaN): every plan costs the same, and the
        // tree must still hold each item once, in leaves it can name.
        let boxes: Vec<Bounds3> = (0..100)
            .map(|i| {
                let c = Vec3::new(i as f64 * 1e36, 0.0, 0.0);
                Bounds3::new(c - Vec3::ONE * 1e38, c + Vec3::ONE * 1e38)
            })
            .collect();
        let bvh = Bvh::build(&boxes, sizes(4, 1));
        let ray = Ray::new(Vec3::new(0.0, 0.0, -3e38), Vec3::new(0.0, 0.0, 1.0));
        let mut seen = Vec::new();
        bvh.traverse(&ray, f64::INFINITY, |items, _| {
            seen.extend_from_slice(items);
            true
        });
        seen.sort();
        assert_eq!(seen, (0..100).collect::<Vec<u32>>());
    }

    #[test]
    fn the_wide_tree_is_the_plan() {
        // The tree made costs what its plan said, holds every item once, in leaves of at
        // most `max_leaf` and nodes of at most eight.
        fn check(node: &BuildNode, max_leaf: usize, items: &mut Vec<u32>) {
            match node {
                BuildNode::Leaf { start, count, .. } => {
                    assert!((1..=max_leaf as u32).contains(count));
                    items.extend(*start..start + count);
                }
                BuildNode::Inner { children, .. } => {
                    assert!((1..=WIDTH).contains(&children.len()));
                    for c in children {
                        check(c, max_leaf, items);
                    }
                }
            }
        }
        let leaf = LeafSize {
            leaf_cost: 1.25,
            block_cost: 0.25,
            ..sizes(8, 4)
        };
        for boxes in [curve_boxes(), random_boxes(5000, 9)] {
            let mut items = items_of(&boxes);
            let root = Builder { leaf }.build(&mut items, 0, 0);
            let planned = root.cost[0];
            let wide = root.into_wide();
            let cost = wide_cost(&wide, &leaf);
            assert!(
                (cost - planned).abs() <= 1e-4 * planned,
                "{cost} against {planned}"
            );
            let mut seen = Vec::new();
            check(&wide, 8, &mut seen);
            seen.sort();
            assert_eq!(seen, (0..boxes.len() as u32).collect::<Vec<_>>());
        }
    }
}
