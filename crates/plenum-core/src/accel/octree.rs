//! An adaptive octree: a cell holding more than a few items is split at its centre into
//! eight, to a depth limit. Traversal is the parametric algorithm of Revelles, Ureña and
//! Lastra (2000): a cell carries the distances at which the ray crosses its six planes; the
//! mid-planes' are their averages, and from them the traversal knows, without testing
//! boxes, which children the ray passes through and in what order, so the cells are
//! visited front to back. Items filed in several cells are mailboxed.
//!
//! A leaf also keeps the box its items fill within its cell, and a ray that misses that
//! box passes the leaf untested: leaves at the surface of a model are mostly empty space,
//! which rays that pass the model close by cross (a tenth faster on the dragon's rays).

use super::mailbox::{new_owner, Mailbox};
use super::{append_padded, nearest, split_off_large, LargeSplit, Reaches};
use crate::math::{gamma, Bounds3, Ray, Vec3};
use std::mem::MaybeUninit;
use std::ops::Range;

const MAX_DEPTH: usize = 16;
/// Most leaf references per filed item, plus [`SPARE_REFERENCES`]: past it, cells are not
/// split further and the octree says so ([`Octree::capped`]). Without it, items that each
/// fall in several children at every level (thin slivers as long as their cells) multiplied
/// their references at every level down to the depth limit.
const REFERENCES_PER_ITEM: usize = 8;
/// The root cell's shortest side is at least 1 / THINNEST of its longest.
const THINNEST: f64 = 8.0;
const SPARE_REFERENCES: usize = 1 << 12;

/// When a cell is split: it holds more than `leaf_items`, and splitting saves more than
/// `split_cost` item tests (the cost of visiting the children).
#[derive(Clone, Copy)]
struct Splitting {
    leaf_items: usize,
    split_cost: usize,
}

/// What a build files items by: their boxes grown by `margin`, the finer test where there
/// is one, and when to split a cell.
struct Filing<'a> {
    boxes: &'a [Bounds3],
    margin: f64,
    reaches: Option<Reaches<'a>>,
    splitting: Splitting,
    /// The most references the item lists of all cells may hold at once.
    budget: usize,
}

impl Filing<'_> {
    /// A cell grown as the grid grows its cells (see there), by the items' margin and a
    /// little of its size more: what the finer test is asked of, and what bounds a leaf's
    /// box.
    fn grown(&self, cell: &Bounds3) -> Bounds3 {
        cell.expanded(self.margin + 1e-6 * cell.diagonal().max_component())
    }
}

/// For items tested one by one (a scene's primitives).
const ONE_BY_ONE: Splitting = Splitting {
    leaf_items: 8,
    split_cost: 8,
};

/// For items tested four or eight at a time (a mesh's triangles, in blocks), whose tests
/// cost less per item: 10–18 % faster than [`ONE_BY_ONE`] on the bunny's, the dragon's and
/// the icosphere's rays; with blocks tested in pairs, 24 and 32 beat 16 and 20 by up to
/// 27 % on the bunny's incoherent rays, a third less memory (docs/acceleration.md).
const IN_BLOCKS: Splitting = Splitting {
    leaf_items: 24,
    split_cost: 32,
};

/// A cell: a leaf with a run of items, or a parent of eight cells.
#[derive(Clone, Copy, Debug)]
struct OctNode {
    /// A leaf's first item in `items`; a parent's block of children in `blocks`.
    first: u32,
    /// A leaf's item count with the LEAF bit. A parent's children that hold anything, bit
    /// k for child k, so traversal skips empty ones without reading them.
    info: u32,
}

const LEAF: u32 = 1 << 31;

/// Eight siblings in one cache line, so a cell's children come in with one miss.
#[derive(Clone, Debug)]
#[repr(C, align(64))]
struct Siblings([OctNode; 8]);

const EMPTY_BLOCK: Siblings = Siblings(
    [OctNode {
        first: 0,
        info: LEAF,
    }; 8],
);

#[derive(Clone, Debug)]
pub struct Octree {
    /// The root cell: the bounds of the items filed in cells.
    region: Bounds3,
    /// The bounds of all the items, large ones included.
    bounds: Bounds3,
    /// Items as large as the scene, tested by every ray (see [`split_off_large`]).
    large: Vec<u32>,
    /// After [`Octree::take_padded_runs`], the large items' run: the first `large_run` slots.
    large_run: usize,
    /// Cell `id` is `blocks[id / 8].0[id % 8]`; the root is cell 0, alone in its block.
    blocks: Vec<Siblings>,
    /// Per cell, for a leaf: the box its items fill within it, min then max, rounded out.
    leaf_boxes: Vec<[f32; 6]>,
    items: Vec<u32>,
    /// Some cell holds an item.
    has_items: bool,
    item_count: usize,
    /// While building: the references in the item lists of all cells, built or pending.
    references: usize,
    /// A cell was left unsplit because the references reached the budget.
    capped: bool,
    owner: u64,
}

/// The nearest f32 at or below `x`, and at or above.
fn round_down(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) > x {
        y.next_down()
    } else {
        y
    }
}

fn round_up(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) < x {
        y.next_up()
    } else {
        y
    }
}

/// Child `octant`'s box: bit 0, 1, 2 set for the upper half in x, y, z.
fn child_box(cell: &Bounds3, octant: usize) -> Bounds3 {
    let (lo, hi) = (cell.min, cell.max);
    let mid = (lo + hi) * 0.5;
    let pick = |a: usize, upper: f64, lower: f64| if octant >> a & 1 == 1 { upper } else { lower };
    Bounds3::new(
        Vec3::new(
            pick(0, mid.x, lo.x),
            pick(1, mid.y, lo.y),
            pick(2, mid.z, lo.z),
        ),
        Vec3::new(
            pick(0, hi.x, mid.x),
            pick(1, hi.y, mid.y),
            pick(2, hi.z, mid.z),
        ),
    )
}

impl Octree {
    /// An octree over items given by their bounds, for a caller that tests `block` items
    /// at a time; with `reaches`, an item is filed only in the cells it may reach into.
    pub fn build(item_bounds: &[Bounds3], block: usize, reaches: Option<Reaches>) -> Octree {
        let splitting = if block > 1 { IN_BLOCKS } else { ONE_BY_ONE };
        let LargeSplit {
            filed: bounded,
            large,
            region,
            bounds,
        } = split_off_large(item_bounds);
        let mut tree = Octree {
            region,
            bounds,
            large,
            large_run: 0,
            blocks: vec![EMPTY_BLOCK],
            leaf_boxes: vec![[0.0; 6]; 8],
            items: Vec::new(),
            has_items: false,
            item_count: item_bounds.len(),
            references: bounded.len(),
            capped: false,
            owner: new_owner(),
        };
        if bounded.is_empty() {
            return tree;
        }
        // Items are filed by slightly grown boxes so rounding never drops one from a cell.
        let margin = region.diagonal().max_component() * 1e-9;
        let filed: Vec<Bounds3> = item_bounds.iter().map(|b| b.expanded(margin)).collect();
        // A region far thinner along an axis than along its longest (a flat mesh) is
        // thickened there, from its lower side: cells as flat as the region put every item
        // of a flat mesh in both children across it, at every level (810 MB for 80 000
        // triangles). Not a cube for every region: that made the dragon 40 % slower.
        let least = region.diagonal().max_component() / THINNEST;
        let thick = |a: usize| region.max[a].max(region.min[a] + least);
        let region = Bounds3::new(region.min, Vec3::new(thick(0), thick(1), thick(2)));
        tree.region = region.expanded(margin);
        let filing = Filing {
            boxes: &filed,
            margin,
            reaches,
            splitting,
            budget: REFERENCES_PER_ITEM * bounded.len() + SPARE_REFERENCES,
        };
        tree.build_node(0, tree.region, bounded, tree.region, 0, &filing);
        tree.has_items = !tree.items.is_empty();
        tree
    }

    fn build_node(
        &mut self,
        node: usize,
        cell: Bounds3,
        items: Vec<u32>,
        fill: Bounds3,
        depth: usize,
        filing: &Filing,
    ) {
        let splitting = filing.splitting;
        let make_leaf = |tree: &mut Octree, items: &[u32]| {
            *tree.node_mut(node) = OctNode {
                first: tree.items.len() as u32,
                info: LEAF | items.len() as u32,
            };
            tree.items.extend_from_slice(items);
            let grown = filing.grown(&cell);
            let mut b = [0.0f32; 6];
            for a in 0..3 {
                b[a] = round_down(fill.min[a].max(grown.min[a]));
                b[a + 3] = round_up(fill.max[a].min(grown.max[a]));
            }
            tree.leaf_boxes[node] = b;
        };
        if items.len() <= splitting.leaf_items || depth >= MAX_DEPTH {
            return make_leaf(self, &items);
        }
        let mid = cell.centroid();
        let mut children: [Vec<u32>; 8] = Default::default();
        // The box each child's items fill (gathered here, where each box is read anyway).
        let mut fills = [Bounds3::default(); 8];
        for &i in &items {
            let b = &filing.boxes[i as usize];
            // Octants the box reaches into, and the axes along which it crosses the middle.
            let straddles = (0..3).any(|a| b.min[a] <= mid[a] && b.max[a] >= mid[a]);
            for (octant, list) in children.iter_mut().enumerate() {
                let inside = (0..3).all(|a| {
                    if octant >> a & 1 == 1 {
                        b.max[a] >= mid[a]
                    } else {
                        b.min[a] <= mid[a]
                    }
                });
                // Where the box lies in one octant, the item reaches into it.
                let kept = match filing.reaches {
                    Some(reaches) if inside && straddles => {
                        reaches(i, &filing.grown(&child_box(&cell, octant)))
                    }
                    _ => inside,
                };
                if kept {
                    list.push(i);
                    fills[octant] = fills[octant].union(b);
                }
            }
        }
        // A ray through the cell crosses each child with probability ¼ (their surface area
        // to the cell's), so after the split it tests about a quarter of the copies, and
        // pays for visiting the children. Items that mostly straddle the centre make the
        // split cost more than it saves.
        let copies: usize = children.iter().map(Vec::len).sum();
        if copies + 4 * splitting.split_cost >= 4 * items.len() {
            return make_leaf(self, &items);
        }
        if self.references + copies - items.len() > filing.budget {
            self.capped = true;
            return make_leaf(self, &items);
        }
        self.references += copies - items.len();
        let block = self.blocks.len();
        self.blocks.push(EMPTY_BLOCK);
        self.leaf_boxes.resize(self.blocks.len() * 8, [0.0; 6]);
        drop(items);
        let mut occupied = 0;
        for ((octant, list), fill) in children.into_iter().enumerate().zip(fills) {
            occupied |= u32::from(!list.is_empty()) << octant;
            let child = child_box(&cell, octant);
            self.build_node(block * 8 + octant, child, list, fill, depth + 1, filing);
        }
        *self.node_mut(node) = OctNode {
            first: block as u32,
            info: occupied,
        };
    }

    fn node(&self, id: usize) -> OctNode {
        self.blocks[id / 8].0[id % 8]
    }

    fn node_mut(&mut self, id: usize) -> &mut OctNode {
        &mut self.blocks[id / 8].0[id % 8]
    }

    pub fn bounds(&self) -> Bounds3 {
        self.bounds
    }

    /// Whether some cell was left unsplit to bound the references (items that fall in
    /// several children at every level): rays then test more items there.
    pub fn capped(&self) -> bool {
        self.capped
    }

    pub fn memory_bytes(&self) -> usize {
        self.blocks.len() * std::mem::size_of::<Siblings>()
            + self.leaf_boxes.len() * std::mem::size_of::<[f32; 6]>()
            + (self.items.len() + self.large.len()) * 4
    }

    /// Visits the leaves the ray crosses front to back, handing `visit` their untested items
    /// (see [`super::Accel::traverse`]).
    pub fn traverse(&self, ray: &Ray, t_max: f64, mut visit: impl FnMut(&[u32], &mut f64) -> bool) {
        let mut t_max = t_max;
        // First, so that a hit on them (the ground, say) prunes the descent.
        if !self.large.is_empty() && !visit(&self.large, &mut t_max) {
            return;
        }
        let mut mailbox = None;
        self.descend(ray, t_max, |run, t_max| {
            mailbox
                .get_or_insert_with(|| Mailbox::start(self.owner, self.item_count))
                .visit_untested(&self.items[run], t_max, &mut visit)
        });
    }

    /// [`Octree::traverse`] without mailboxing: an item in several cells may be handed over
    /// again, which costs less than the stamps where testing it again is cheap and harmless
    /// (a mesh's triangles, for the nearest or any hit).
    pub fn traverse_repeating(
        &self,
        ray: &Ray,
        t_max: f64,
        mut visit: impl FnMut(&[u32], &mut f64) -> bool,
    ) {
        let mut t_max = t_max;
        if !self.large.is_empty() && !visit(&self.large, &mut t_max) {
            return;
        }
        self.descend(ray, t_max, |run, t_max| visit(&self.items[run], t_max));
    }

    /// Hands the caller the items of the large run and of every leaf, each padded with
    /// [`super::PAD`] entries to a whole number of `block`s and starting a block, in place of the
    /// octree's own lists: for a caller that stores its items so, as a mesh stores its
    /// triangles in blocks. Only [`Octree::traverse_runs`] may be used afterwards.
    pub fn take_padded_runs(&mut self, block: usize) -> Vec<u32> {
        let mut padded = Vec::with_capacity(self.items.len() * 2);
        append_padded(&mut padded, &self.large, block);
        self.large_run = padded.len();
        for siblings in &mut self.blocks {
            for node in siblings.0.iter_mut().filter(|n| n.info & LEAF != 0) {
                let (first, count) = (node.first as usize, (node.info & !LEAF) as usize);
                node.first = padded.len() as u32;
                append_padded(&mut padded, &self.items[first..first + count], block);
            }
        }
        self.large = Vec::new();
        self.has_items = !padded.is_empty();
        self.items = Vec::new();
        padded
    }

    /// [`Octree::traverse_repeating`] after [`Octree::take_padded_runs`], handing each run
    /// as its range of positions in the padded list (pads left out).
    #[inline]
    pub fn traverse_runs(
        &self,
        ray: &Ray,
        t_max: f64,
        mut visit: impl FnMut(Range<usize>, &mut f64) -> bool,
    ) {
        let mut t_max = t_max;
        if self.large_run > 0 && !visit(0..self.large_run, &mut t_max) {
            return;
        }
        self.descend(ray, t_max, visit);
    }

    /// Visits the leaves the ray crosses front to back, handing `hand(run, t_max)` the
    /// range of each one's items in `items`, until it returns false.
    #[inline(always)]
    fn descend(&self, ray: &Ray, t_max: f64, mut hand: impl FnMut(Range<usize>, &mut f64) -> bool) {
        let mut t_max = t_max;
        // The root's own entry and exit test below stands for a test of the bounds.
        if !self.has_items {
            return;
        }
        // As Revelles et al. do, mirror the ray about the tree's centre along each axis it
        // runs down, so that it runs up every axis; octant bits in `flip` undo the mirroring.
        // A zero direction component becomes a tiny positive one: its planes are then
        // crossed at ±huge distances, never inside a cell, which is the right answer.
        let (lo, hi) = (self.region.min, self.region.max);
        let mut flip = 0;
        let mut t0 = [0.0; 3];
        let mut t1 = [0.0; 3];
        // For the leaves' boxes, which are not mirrored: where in a box's six numbers the
        // near and the far side lie along each axis, and 1 / d with d's own sign.
        let (mut near, mut far) = ([0, 1, 2], [3, 4, 5]);
        let mut inv_dir = [0.0; 3];
        for a in 0..3 {
            let (mut o, mut d) = (ray.origin[a], ray.direction[a]);
            let mirrored = d < 0.0;
            if mirrored {
                (o, d) = (lo[a] + hi[a] - o, -d);
                flip |= 1 << a;
                (near[a], far[a]) = (far[a], near[a]);
            }
            let inv = 1.0 / d.max(1e-200);
            inv_dir[a] = if mirrored { -inv } else { inv };
            t0[a] = (lo[a] - o) * inv;
            t1[a] = (hi[a] - o) * inv;
        }
        // Whether the ray, from `start` to `t_max`, misses the box leaf `id`'s items fill:
        // the slab test, with the far distance rounded up as the BVH's is.
        let leaf_missed = |id: usize, start: f64, t_max: f64| {
            // SAFETY: there is a box per cell.
            let b = unsafe { self.leaf_boxes.get_unchecked(id) };
            let (mut enter, mut exit) = (start, t_max);
            for a in 0..3 {
                let n = (f64::from(b[near[a]]) - ray.origin[a]) * inv_dir[a];
                let f = (f64::from(b[far[a]]) - ray.origin[a]) * inv_dir[a];
                enter = if n > enter { n } else { enter };
                exit = if f < exit { f } else { exit };
            }
            enter > exit * (1.0 + 2.0 * gamma(3))
        };
        // Plain comparisons: the distances are never NaN, so f64::max's NaN rules would only
        // cost instructions.
        let larger = |a: f64, b: f64| if a > b { a } else { b };
        let smaller = |a: f64, b: f64| if a < b { a } else { b };
        let enter = larger(larger(t0[0], t0[1]), t0[2]);
        let leave = smaller(smaller(t1[0], t1[1]), t1[2]);
        if enter > t_max || leave < 0.0 || enter > leave {
            return;
        }
        // The parents the ray is passing through, innermost on top. Only parents are
        // stacked, and a parent's next child is found from its planes when the ray leaves
        // the one before: a leaf costs no stack traffic, and a hit that lowers `t_max`
        // ends the walk through a parent's remaining children at once. (Working out a
        // parent's whole way through its children when it is entered, occupied ones only,
        // runs fewer instructions but was 10 % slower on the bunny's incoherent rays, and
        // 11–31 % slower without branches.)
        // Uninitialised: only entries below `top`, all written first, are read.
        let mut stack = [MaybeUninit::<Passage>::uninit(); MAX_DEPTH + 1];
        let mut top = 0;
        // The cell entered: its index, planes' distances, and where the ray enters it ahead
        // of its origin. Every cell entered is one the ray crosses before `t_max`.
        let (mut index, mut c0, mut c1, mut start) = (0u32, t0, t1, larger(enter, 0.0));
        let mut visits = super::cost::Visits::start();
        loop {
            visits.nodes += 1;
            let node = self.node(index as usize);
            if node.info & LEAF != 0 {
                let first = node.first as usize;
                if leaf_missed(index as usize, start, t_max) {
                    // Nothing here: on to the next cell.
                } else if !hand(first..first + (node.info & !LEAF) as usize, &mut t_max) {
                    return;
                }
                // Whatever is left is entered beyond this cell's exit.
                if t_max <= smaller(smaller(c1[0], c1[1]), c1[2]) {
                    return;
                }
            } else {
                // The children's line is read as soon as one of them is entered: ask for it
                // while the way through them is worked out.
                #[cfg(target_arch = "x86_64")]
                // SAFETY: prefetching is only a hint and never faults.
                unsafe {
                    use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
                    let children = self.blocks.as_ptr().wrapping_add(node.first as usize);
                    _mm_prefetch(children as *const i8, _MM_HINT_T0);
                }
                let mut mid = [0.0; 3];
                // The first child the ray is in: upper along each axis whose mid-plane it
                // crosses before it starts in this cell.
                let mut octant = 0;
                for a in 0..3 {
                    mid[a] = 0.5 * (c0[a] + c1[a]);
                    octant |= u32::from(mid[a] < start) << a;
                }
                // A parent at depth k is stacked above k others, and parents lie above
                // MAX_DEPTH.
                debug_assert!(top < MAX_DEPTH);
                // SAFETY: see above.
                unsafe {
                    stack.get_unchecked_mut(top).write(Passage {
                        children: node.first,
                        occupied: node.info,
                        octant,
                        t0: c0,
                        mid,
                        t1: c1,
                        enter: start,
                    })
                };
                top += 1;
            }
            // The next occupied child on the way, in the innermost parent not yet left.
            loop {
                if top == 0 {
                    return;
                }
                // SAFETY: entries below `top` were written when stacked.
                let p = unsafe { stack.get_unchecked_mut(top - 1).assume_init_mut() };
                // A hit since the child was found may have put it out of reach, and the
                // parent's later children with it.
                if p.enter > t_max {
                    top -= 1;
                    continue;
                }
                let octant = p.octant;
                let mut exit = [0.0; 3];
                for (a, e) in exit.iter_mut().enumerate() {
                    *e = if octant >> a & 1 == 1 {
                        p.t1[a]
                    } else {
                        p.mid[a]
                    };
                }
                let enter = p.enter;
                let occupied = p.occupied >> (octant ^ flip) & 1 != 0;
                // Next, the child across the nearest exit plane, unless that plane is the
                // parent's own or lies beyond `t_max`: then the parent is left (its entry,
                // written all the same, is dead). Without branches: which way it goes is a
                // coin toss to the branch predictor.
                let (a, t) = nearest(exit);
                p.octant = octant | 1 << a;
                p.enter = t;
                top -= (octant >> a & 1) as usize | usize::from(t > t_max);
                // An empty child costs only the step past it; an occupied one is entered,
                // its planes taken from the parent's (still there when just left).
                if occupied {
                    for (a, c) in c0.iter_mut().enumerate() {
                        *c = if octant >> a & 1 == 1 {
                            p.mid[a]
                        } else {
                            p.t0[a]
                        };
                    }
                    c1 = exit;
                    start = enter;
                    index = p.children * 8 + (octant ^ flip);
                    break;
                }
            }
        }
    }
}

/// A parent cell the ray is passing through: where its children lie and which hold
/// anything (bit k for child k), the distances to its planes (mirrored, see
/// [`Octree::descend`]), and the next child on the way with where the ray enters it.
#[derive(Clone, Copy)]
struct Passage {
    children: u32,
    occupied: u32,
    octant: u32,
    t0: [f64; 3],
    mid: [f64; 3],
    t1: [f64; 3],
    enter: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn depth(tree: &Octree, id: usize) -> usize {
        let node = tree.node(id);
        if node.info & LEAF != 0 {
            return 0;
        }
        (0..8)
            .map(|k| depth(tree, node.first as usize * 8 + k))
            .max()
            .unwrap_or(0)
            + 1
    }

    /// The items a ray is handed, in the order handed, with `t_max` left alone.
    fn handed(tree: &Octree, ray: &Ray, t_max: f64) -> Vec<u32> {
        let mut items = Vec::new();
        tree.traverse(ray, t_max, |run, _| {
            items.extend_from_slice(run);
            true
        });
        items
    }

    /// Forty tiny items at one point split the cells around it to the depth limit (each
    /// split copies them all into one child, and 40 items pay for a split), with a few
    /// items at the corners of a unit cube to spread the tree. Rays through the point from
    /// every side, along the axes and diagonally, from outside and from the point itself,
    /// are handed every one of them; a segment that ends before the point is handed none.
    #[test]
    fn a_cluster_splits_to_the_depth_limit_and_every_ray_through_it_finds_it() {
        let p = Vec3::new(0.3, 0.6, 0.45);
        let tiny = Bounds3::new(p - Vec3::splat(1e-7), p + Vec3::splat(1e-7));
        let mut boxes = vec![tiny; 40];
        for k in 0..8 {
            let c = Vec3::new((k & 1) as f64, (k >> 1 & 1) as f64, (k >> 2 & 1) as f64);
            boxes.push(Bounds3::new(c - Vec3::splat(0.01), c + Vec3::splat(0.01)));
        }
        let tree = Octree::build(&boxes, 1, None);
        assert_eq!(depth(&tree, 0), MAX_DEPTH);
        let mut directions = Vec::new();
        for sign in [-1.0, 1.0] {
            directions.push(Vec3::new(sign, 0.0, 0.0));
            directions.push(Vec3::new(0.0, sign, 0.0));
            directions.push(Vec3::new(0.0, 0.0, sign));
        }
        for k in 0..8 {
            let s = |bit: usize| if k >> bit & 1 == 1 { 1.0 } else { -1.0 };
            directions.push(Vec3::new(s(0) * 0.3, s(1) * 0.7, s(2)).normalized());
        }
        for d in directions {
            let from_outside = Ray::new(p - d * 3.0, d);
            for ray in [from_outside, Ray::new(p, d)] {
                let items = handed(&tree, &ray, f64::INFINITY);
                for i in 0..40 {
                    assert!(items.contains(&i), "{ray:?} missed item {i}");
                }
            }
            let short = handed(&tree, &from_outside, 2.9);
            assert!(short.iter().all(|&i| i >= 40), "{d:?}: {short:?}");
        }
    }

    /// Two items at each corner of a unit cube and four in a cluster at (0.3, 0.3, 0.3)
    /// split the root once; the lower octant's leaf holds the cluster and one corner's
    /// items, and the box they fill leaves most of its cell empty. A ray across that cell
    /// through the empty part is handed nothing; one through the cluster is handed it.
    #[test]
    fn a_ray_that_misses_the_box_a_leafs_items_fill_is_handed_none_of_them() {
        let small = |c: Vec3| Bounds3::new(c - Vec3::splat(0.01), c + Vec3::splat(0.01));
        let mut boxes = Vec::new();
        for k in 0..16 {
            let k = k / 2;
            boxes.push(small(Vec3::new(
                (k & 1) as f64,
                (k >> 1 & 1) as f64,
                (k >> 2 & 1) as f64,
            )));
        }
        boxes.extend([small(Vec3::splat(0.3)); 4]);
        let tree = Octree::build(&boxes, 1, None);
        assert_eq!(depth(&tree, 0), 1);
        let along_x = |y: f64, z: f64| Ray::new(Vec3::new(-1.0, y, z), Vec3::X);
        assert_eq!(
            handed(&tree, &along_x(0.45, 0.45), f64::INFINITY),
            Vec::<u32>::new()
        );
        let through = handed(&tree, &along_x(0.3, 0.3), f64::INFINITY);
        assert!((16..20).all(|i| through.contains(&i)), "{through:?}");
    }
}
