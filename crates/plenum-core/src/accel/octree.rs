//! An adaptive octree: a cell holding more than a few items is split at its centre into
//! eight, to a depth limit. Traversal is the parametric algorithm of Revelles, Ureña and
//! Lastra (2000): from the distances at which the ray crosses a cell's three mid-planes it
//! knows, without testing boxes, which children it passes through and in what order, so the
//! cells are visited front to back. Items filed in several cells are mailboxed.

use super::mailbox::{new_owner, Mailbox};
use crate::math::{Bounds3, Ray, Vec3};
use std::mem::MaybeUninit;

const LEAF_ITEMS: usize = 8;
const MAX_DEPTH: usize = 16;
/// A ray passes through at most four of a cell's children.
const STACK: usize = 3 * MAX_DEPTH + 2;

#[derive(Clone, Debug)]
struct OctNode {
    /// Index of the first of eight consecutive children; 0 for a leaf.
    first_child: u32,
    start: u32,
    count: u32,
}

#[derive(Clone, Debug)]
pub struct Octree {
    bounds: Bounds3,
    nodes: Vec<OctNode>,
    items: Vec<u32>,
    item_count: usize,
    owner: u64,
}

/// Child `octant`'s box: bit 0, 1, 2 set for the upper half in x, y, z.
fn child_box(lo: Vec3, hi: Vec3, octant: usize) -> (Vec3, Vec3) {
    let mid = (lo + hi) * 0.5;
    let pick = |a: usize, upper: f64, lower: f64| if octant >> a & 1 == 1 { upper } else { lower };
    (
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
    pub fn build(item_bounds: &[Bounds3]) -> Octree {
        let bounded: Vec<u32> = (0..item_bounds.len() as u32)
            .filter(|&i| !item_bounds[i as usize].is_empty())
            .collect();
        let bounds = bounded.iter().fold(Bounds3::default(), |b, &i| {
            b.union(&item_bounds[i as usize])
        });
        let mut tree = Octree {
            bounds,
            nodes: vec![OctNode {
                first_child: 0,
                start: 0,
                count: 0,
            }],
            items: Vec::new(),
            item_count: item_bounds.len(),
            owner: new_owner(),
        };
        if bounded.is_empty() {
            return tree;
        }
        // Items are filed by slightly grown boxes so rounding never drops one from a cell.
        let margin = bounds.diagonal().max_component() * 1e-9;
        let filed: Vec<Bounds3> = item_bounds.iter().map(|b| b.expanded(margin)).collect();
        tree.bounds = bounds.expanded(margin);
        tree.build_node(0, tree.bounds.min, tree.bounds.max, bounded, 0, &filed);
        tree
    }

    fn build_node(
        &mut self,
        node: usize,
        lo: Vec3,
        hi: Vec3,
        items: Vec<u32>,
        depth: usize,
        filed: &[Bounds3],
    ) {
        let make_leaf = |tree: &mut Octree, items: &[u32]| {
            tree.nodes[node] = OctNode {
                first_child: 0,
                start: tree.items.len() as u32,
                count: items.len() as u32,
            };
            tree.items.extend_from_slice(items);
        };
        if items.len() <= LEAF_ITEMS || depth >= MAX_DEPTH {
            return make_leaf(self, &items);
        }
        let mid = (lo + hi) * 0.5;
        let mut children: [Vec<u32>; 8] = Default::default();
        for &i in &items {
            let b = &filed[i as usize];
            for (octant, list) in children.iter_mut().enumerate() {
                let inside = (0..3).all(|a| {
                    if octant >> a & 1 == 1 {
                        b.max[a] >= mid[a]
                    } else {
                        b.min[a] <= mid[a]
                    }
                });
                if inside {
                    list.push(i);
                }
            }
        }
        // Items that mostly straddle the centre: splitting would only copy them.
        let copies: usize = children.iter().map(Vec::len).sum();
        if copies > 2 * items.len() || children.iter().all(|c| c.len() == items.len()) {
            return make_leaf(self, &items);
        }
        let first = self.nodes.len();
        self.nodes[node].first_child = first as u32;
        for _ in 0..8 {
            self.nodes.push(OctNode {
                first_child: 0,
                start: 0,
                count: 0,
            });
        }
        drop(items);
        for (octant, list) in children.into_iter().enumerate() {
            let (clo, chi) = child_box(lo, hi, octant);
            self.build_node(first + octant, clo, chi, list, depth + 1, filed);
        }
    }

    pub fn bounds(&self) -> Bounds3 {
        self.bounds
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<OctNode>() + self.items.len() * 4
    }

    /// Visits the leaves the ray crosses front to back, handing `visit` their untested items
    /// (see [`super::Accel::traverse`]).
    pub fn traverse(&self, ray: &Ray, t_max: f64, mut visit: impl FnMut(&[u32], &mut f64) -> bool) {
        if self.items.is_empty() {
            return;
        }
        let Some((t_enter, t_exit)) = self.bounds.intersect_interval(ray, t_max) else {
            return;
        };
        let mut t_max = t_max;
        // A zero direction component becomes a tiny one of the same sign: its plane is then
        // crossed at ±huge distances, never inside a cell, which is the right answer.
        let dir = ray.direction;
        let inv = [0, 1, 2].map(|a| {
            let d = if dir[a].abs() < 1e-300 {
                1e-300f64.copysign(dir[a])
            } else {
                dir[a]
            };
            1.0 / d
        });
        let mailbox = Mailbox::start(self.owner, self.item_count);
        // Uninitialised: only entries below `top`, all written first, are read.
        let mut stack = [MaybeUninit::<(u32, Vec3, Vec3, f64, f64)>::uninit(); STACK];
        stack[0].write((0, self.bounds.min, self.bounds.max, t_enter, t_exit));
        let mut top = 1;
        while top > 0 {
            top -= 1;
            // SAFETY: entries below `top` were written when pushed.
            let (index, lo, hi, ta, tb) = unsafe { stack[top].assume_init() };
            if ta > t_max {
                continue;
            }
            let node = &self.nodes[index as usize];
            if node.first_child == 0 {
                let start = node.start as usize;
                let items = &self.items[start..start + node.count as usize];
                if !mailbox.visit_untested(items, &mut t_max, &mut visit) {
                    return;
                }
                continue;
            }
            let mid = (lo + hi) * 0.5;
            let tm = [0, 1, 2].map(|a| (mid[a] - ray.origin[a]) * inv[a]);
            // The child the ray is in at ta: on the upper side of a mid-plane it has already
            // crossed going up, or not yet crossed going down.
            let mut octant = 0;
            for a in 0..3 {
                let upper = if inv[a] > 0.0 {
                    tm[a] <= ta
                } else {
                    tm[a] > ta
                };
                octant |= (upper as usize) << a;
            }
            // The mid-planes crossed inside the cell, in order along the ray.
            let mut crossings = [(0.0f64, 0usize); 3];
            let mut n = 0;
            for (a, &t) in tm.iter().enumerate() {
                if t > ta && t < tb {
                    crossings[n] = (t, a);
                    n += 1;
                }
            }
            // At most three: sorted by exchanges, without a call into the general sort.
            for i in 1..n {
                let mut j = i;
                while j > 0 && crossings[j].0 < crossings[j - 1].0 {
                    crossings.swap(j, j - 1);
                    j -= 1;
                }
            }
            // Children along the ray: push them farthest first so the nearest pops next.
            let mut sequence = [(0usize, 0.0f64, 0.0f64); 4];
            let mut t = ta;
            for (k, &(tc, axis)) in crossings[..n].iter().enumerate() {
                sequence[k] = (octant, t, tc);
                octant ^= 1 << axis;
                t = tc;
            }
            sequence[n] = (octant, t, tb);
            for &(oct, t0, t1) in sequence[..=n].iter().rev() {
                let child = &self.nodes[(node.first_child + oct as u32) as usize];
                if child.first_child == 0 && child.count == 0 {
                    // An empty leaf: nothing to visit there.
                    continue;
                }
                let (clo, chi) = child_box(lo, hi, oct);
                stack[top].write((node.first_child + oct as u32, clo, chi, t0, t1));
                top += 1;
            }
        }
    }
}
