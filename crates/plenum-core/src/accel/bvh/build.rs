//! The binary tree, built top down by the binned surface-area heuristic (Wald 2007) over all
//! three axes, in parallel across large subtrees.

use super::collapse::Binary;
use super::{Aabb, LeafSize, MAX_DEPTH};

const BINS: usize = 16;
/// Subtrees with more items than this are built in parallel.
const PARALLEL_ITEMS: usize = 4096;

#[derive(Clone, Copy)]
pub(super) struct Item {
    pub(super) lo: [f32; 3],
    pub(super) hi: [f32; 3],
    pub(super) index: u32,
}

impl Item {
    /// Twice the centroid: all that binning needs.
    pub(super) fn center2(&self, axis: usize) -> f32 {
        self.lo[axis] + self.hi[axis]
    }
}

pub(super) struct Builder {
    pub(super) leaf: LeafSize,
}

impl Builder {
    /// Builds the binary tree over `items`, which start at `offset` in the final item
    /// order, split down to runs of one block and planned for the collapse (see [`Binary`]).
    pub(super) fn build(&self, items: &mut [Item], offset: usize, depth: usize) -> Binary {
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
    pub(super) fn split(&self, items: &mut [Item], depth: usize) -> Option<usize> {
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
