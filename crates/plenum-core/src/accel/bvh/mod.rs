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
//!
//! Its parts: `build` (the binary binned-SAH build), `collapse` (the binary tree planned and
//! collapsed into eight-wide nodes, then flattened), `layout` (the leaves' items reordered
//! for the caller, and their blocks laid out among the nodes), `traverse` (the walks of a
//! ray); this module holds the node format they share.

mod build;
mod collapse;
mod layout;
#[cfg(test)]
mod tests;
mod traverse;

pub use traverse::{AmongNodes, Coherence, LeafItems, LeafPlaces};

use super::pages::LargeArray;
use super::ray_f32::{round_down, round_up};
use super::LeafSize;
use crate::math::Bounds3;
use build::{Builder, Item};
use collapse::{flatten_children, BuildNode};

/// Children per node.
const WIDTH: usize = 8;
/// Depth (in binary splits) past which runs are halved instead of split by cost.
const MAX_DEPTH: usize = 64;

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
}

/// A BVH's expected cost per ray crossing its root ([`Bvh::sah_cost`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SahCost {
    /// Nodes visited.
    pub nodes: f64,
    /// Leaf blocks tested.
    pub leaves: f64,
}
