//! A bounding-volume hierarchy built with the binned surface-area heuristic (Wald 2007), laid
//! out depth-first so the first child follows its parent, and traversed front to back with a
//! fixed-size stack: no allocation per ray.
//!
//! The BVH knows only boxes; the caller's closure intersects the items in a leaf, so one
//! structure serves triangles of a mesh and primitives of a scene alike.

use crate::geometry::HitRecord;
use crate::math::{Bounds3, Ray, Vec3};

const BINS: usize = 12;
const MAX_LEAF: usize = 4;
/// Depth of the traversal stack; builds stop splitting before this depth.
const MAX_DEPTH: usize = 64;
/// Cost of a node visit relative to one item test.
const TRAVERSAL_COST: f64 = 0.5;

#[derive(Clone, Debug)]
struct Node {
    bounds: Bounds3,
    /// Leaf: index of the first item in `order`. Interior: index of the second child.
    offset: u32,
    /// Items in a leaf; 0 for interior nodes.
    count: u32,
    /// Split axis of an interior node, for ordering the children.
    axis: u8,
}

#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// Item indices, grouped by leaf.
    order: Vec<u32>,
}

struct Item {
    bounds: Bounds3,
    centroid: Vec3,
    index: u32,
}

impl Bvh {
    /// Builds over items given by their bounds; the leaves refer to items by position.
    pub fn build(item_bounds: &[Bounds3]) -> Bvh {
        let mut items: Vec<Item> = item_bounds
            .iter()
            .enumerate()
            .map(|(i, b)| Item {
                bounds: *b,
                centroid: b.centroid(),
                index: i as u32,
            })
            .collect();
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(2 * items.len().max(1)),
            order: Vec::with_capacity(items.len()),
        };
        if !items.is_empty() {
            bvh.build_node(&mut items, 0);
        }
        bvh
    }

    pub fn bounds(&self) -> Bounds3 {
        self.nodes
            .first()
            .map_or_else(Bounds3::default, |n| n.bounds)
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    fn build_node(&mut self, items: &mut [Item], depth: usize) -> usize {
        let bounds = items
            .iter()
            .fold(Bounds3::default(), |b, it| b.union(&it.bounds));
        let node = self.nodes.len();
        self.nodes.push(Node {
            bounds,
            offset: 0,
            count: 0,
            axis: 0,
        });
        match self.choose_split(items, &bounds, depth) {
            None => {
                self.nodes[node].offset = self.order.len() as u32;
                self.nodes[node].count = items.len() as u32;
                self.order.extend(items.iter().map(|it| it.index));
            }
            Some((axis, mid)) => {
                let (left, right) = items.split_at_mut(mid);
                self.build_node(left, depth + 1);
                let second = self.build_node(right, depth + 1);
                self.nodes[node].offset = second as u32;
                self.nodes[node].axis = axis as u8;
            }
        }
        node
    }

    /// Partitions `items` by the cheapest SAH split; `None` makes a leaf.
    fn choose_split(
        &self,
        items: &mut [Item],
        bounds: &Bounds3,
        depth: usize,
    ) -> Option<(usize, usize)> {
        let n = items.len();
        if n <= 1 || depth + 1 >= MAX_DEPTH {
            return None;
        }
        let centroids = items
            .iter()
            .fold(Bounds3::default(), |b, it| b.union_point(it.centroid));
        let axis = centroids.diagonal().max_abs_axis();
        let (lo, hi) = (centroids.min[axis], centroids.max[axis]);
        if hi <= lo {
            // All centroids coincide: no split separates them.
            return (n > MAX_LEAF).then_some((axis, n / 2));
        }
        let bin_of = |c: Vec3| (((c[axis] - lo) / (hi - lo) * BINS as f64) as usize).min(BINS - 1);
        let mut bin_bounds = [Bounds3::default(); BINS];
        let mut bin_counts = [0usize; BINS];
        for it in items.iter() {
            let b = bin_of(it.centroid);
            bin_bounds[b] = bin_bounds[b].union(&it.bounds);
            bin_counts[b] += 1;
        }
        // Sweep from the right to get the area and count of every suffix of bins.
        let mut right_area = [0.0; BINS];
        let mut right_count = [0usize; BINS];
        let (mut acc, mut count) = (Bounds3::default(), 0);
        for i in (1..BINS).rev() {
            acc = acc.union(&bin_bounds[i]);
            count += bin_counts[i];
            right_area[i] = acc.surface_area();
            right_count[i] = count;
        }
        let (mut best, mut best_cost) = (0, f64::INFINITY);
        let (mut acc, mut count) = (Bounds3::default(), 0);
        for i in 0..BINS - 1 {
            acc = acc.union(&bin_bounds[i]);
            count += bin_counts[i];
            let cost =
                count as f64 * acc.surface_area() + right_count[i + 1] as f64 * right_area[i + 1];
            if cost < best_cost {
                best_cost = cost;
                best = i;
            }
        }
        let split_cost = TRAVERSAL_COST + best_cost / bounds.surface_area().max(f64::MIN_POSITIVE);
        if n <= MAX_LEAF && split_cost >= n as f64 {
            return None;
        }
        let mid = partition(items, |it| bin_of(it.centroid) <= best);
        if mid == 0 || mid == n {
            return Some((axis, n / 2));
        }
        Some((axis, mid))
    }

    /// The nearest hit in (0, t_max): `hit_item(index, t_max)` tests one item against the ray
    /// and is called with a shrinking `t_max`. Returns the item index and its hit.
    pub fn intersect(
        &self,
        ray: &Ray,
        t_max: f64,
        mut hit_item: impl FnMut(u32, f64) -> Option<HitRecord>,
    ) -> Option<(u32, HitRecord)> {
        let mut best = None;
        self.traverse(ray, t_max, |item, t_max| {
            if let Some(hit) = hit_item(item, *t_max) {
                *t_max = hit.t;
                best = Some((item, hit));
            }
            true
        });
        best
    }

    /// Calls `visit(item)` for every item in a leaf whose box the ray crosses in (0, t_max),
    /// until `visit` returns false. For queries that want every hit, not the nearest one.
    pub fn for_each_candidate(&self, ray: &Ray, t_max: f64, mut visit: impl FnMut(u32) -> bool) {
        self.traverse(ray, t_max, |item, _| visit(item));
    }

    /// Front-to-back traversal with a fixed-size stack. `visit(item, t_max)` may shrink
    /// `t_max` to prune farther nodes, and returns false to stop.
    fn traverse(&self, ray: &Ray, mut t_max: f64, mut visit: impl FnMut(u32, &mut f64) -> bool) {
        if self.nodes.is_empty() {
            return;
        }
        let inv_dir = Vec3::new(
            1.0 / ray.direction.x,
            1.0 / ray.direction.y,
            1.0 / ray.direction.z,
        );
        let negative = [inv_dir.x < 0.0, inv_dir.y < 0.0, inv_dir.z < 0.0];
        let mut stack = [0u32; MAX_DEPTH];
        let mut top = 0;
        let mut current = 0usize;
        loop {
            let node = &self.nodes[current];
            if node.bounds.intersect(ray, inv_dir, t_max).is_some() {
                if node.count > 0 {
                    let start = node.offset as usize;
                    for &item in &self.order[start..start + node.count as usize] {
                        if !visit(item, &mut t_max) {
                            return;
                        }
                    }
                } else {
                    // Visit the child on the ray's near side first.
                    let (first, second) = if negative[node.axis as usize] {
                        (node.offset as usize, current + 1)
                    } else {
                        (current + 1, node.offset as usize)
                    };
                    stack[top] = second as u32;
                    top += 1;
                    current = first;
                    continue;
                }
            }
            if top == 0 {
                return;
            }
            top -= 1;
            current = stack[top] as usize;
        }
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
    use crate::geometry::Sphere;

    #[test]
    fn finds_the_same_nearest_hit_as_brute_force() {
        // A seeded cloud of spheres; compare with testing every sphere.
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let spheres: Vec<Sphere> = (0..500)
            .map(|_| {
                Sphere::new(
                    Vec3::new(next() * 20.0 - 10.0, next() * 20.0 - 10.0, next() * 20.0),
                    0.05 + next() * 0.5,
                )
            })
            .collect();
        let bvh = Bvh::build(&spheres.iter().map(|s| s.bounds()).collect::<Vec<_>>());
        for _ in 0..2000 {
            let origin = Vec3::new(next() * 4.0 - 2.0, next() * 4.0 - 2.0, -5.0);
            let dir = Vec3::new(next() - 0.5, next() - 0.5, 1.0);
            let ray = Ray::new(origin, dir);
            let fast = bvh.intersect(&ray, f64::INFINITY, |i, t| {
                spheres[i as usize].intersect(&ray, t)
            });
            let brute = spheres
                .iter()
                .enumerate()
                .filter_map(|(i, s)| s.intersect(&ray, f64::INFINITY).map(|h| (i as u32, h)))
                .min_by(|a, b| a.1.t.total_cmp(&b.1.t));
            assert_eq!(fast.map(|h| h.0), brute.map(|h| h.0));
        }
    }

    #[test]
    fn empty_bvh_misses() {
        let bvh = Bvh::build(&[]);
        assert!(bvh
            .intersect(&Ray::new(Vec3::ZERO, Vec3::Z), 1.0, |_, _| unreachable!())
            .is_none());
    }
}
