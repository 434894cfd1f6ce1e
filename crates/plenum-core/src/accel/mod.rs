//! Acceleration structures, selectable so their speed-ups can be compared: an eight-wide BVH
//! (the default), a uniform grid, an octree, and none (brute force). The same structures
//! serve both levels of a scene: the primitives of the scene, and the triangles inside each
//! mesh.
//!
//! Every structure answers one query, [`Accel::traverse`]: it hands the caller runs of item
//! indices whose boxes the ray crosses, roughly nearest first, and the caller tests them,
//! shrinking the search distance as it finds hits. Closest-hit, any-hit and all-hits queries
//! are all written with it.

mod brute;
mod bvh;
pub mod cost;
mod grid;
mod mailbox;
mod octree;
pub(crate) mod pages;
pub(crate) mod ray_f32;
pub(crate) mod simd;

pub use brute::BruteForce;
pub use bvh::{
    AmongNodes, Bvh, Coherence, LeafItems, LeafPlaces, SahCost, EMBED_LIMIT, EMBED_UNIT,
};
pub use cost::Cost;
pub use grid::Grid;
pub use octree::Octree;

use crate::math::{Bounds3, Ray};

/// Plain data (`Copy`: numbers, arrays and structs of them) read as the bytes it is, for
/// laying blocks out among a BVH's nodes and finding them there.
pub(crate) fn bytes_of<T: Copy>(items: &[T]) -> &[u8] {
    // SAFETY: the bytes of `items`, borrowed as long as they are.
    unsafe { std::slice::from_raw_parts(items.as_ptr() as *const u8, std::mem::size_of_val(items)) }
}

/// An item whose box has more than this share of the scene box's surface area is large.
const LARGE_SHARE: f64 = 0.25;
/// Most large items a spatial subdivision keeps out of its cells.
const MAX_LARGE: usize = 16;

/// For the grid and the octree: the items with a box, split into those to file in cells and
/// a few as large as the scene (a ground polygon under a small model, the walls of a room),
/// which every ray tests instead. Filed, they would stretch the cells over empty space and
/// leave the model few of them ("the teapot in a stadium"), and be tested in every cell the
/// ray crosses anyway. Many large items stay filed: testing them all per ray would be brute
/// force.
fn split_off_large(item_bounds: &[Bounds3]) -> LargeSplit {
    let union = |items: &[u32]| {
        items.iter().fold(Bounds3::default(), |b, &i| {
            b.union(&item_bounds[i as usize])
        })
    };
    let bounded: Vec<u32> = (0..item_bounds.len() as u32)
        .filter(|&i| !item_bounds[i as usize].is_empty())
        .collect();
    let bounds = union(&bounded);
    let threshold = LARGE_SHARE * bounds.surface_area();
    let (large, filed): (Vec<u32>, Vec<u32>) = bounded
        .iter()
        .partition(|&&i| item_bounds[i as usize].surface_area() > threshold);
    if large.len() <= MAX_LARGE && !filed.is_empty() {
        LargeSplit {
            region: union(&filed),
            bounds,
            filed,
            large,
        }
    } else {
        LargeSplit {
            region: bounds,
            bounds,
            filed: bounded,
            large: Vec::new(),
        }
    }
}

/// Items parted by [`split_off_large`].
struct LargeSplit {
    /// Those to file in cells.
    filed: Vec<u32>,
    /// Those every ray tests.
    large: Vec<u32>,
    /// The bounds of the filed items: the region the cells divide.
    region: Bounds3,
    /// The bounds of all the items.
    bounds: Bounds3,
}

/// Which acceleration structure to build.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum AccelKind {
    #[default]
    Bvh,
    Grid,
    Octree,
    /// Brute force with bounding spheres.
    None,
}

impl AccelKind {
    pub const ALL: [AccelKind; 4] = [
        AccelKind::Bvh,
        AccelKind::Grid,
        AccelKind::Octree,
        AccelKind::None,
    ];

    pub fn name(self) -> &'static str {
        match self {
            AccelKind::Bvh => "bvh",
            AccelKind::Grid => "grid",
            AccelKind::Octree => "octree",
            AccelKind::None => "none",
        }
    }
}

impl std::fmt::Display for AccelKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for AccelKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        AccelKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| format!("unknown accelerator `{s}`: expected bvh, grid, octree or none"))
    }
}

/// How the caller tests a leaf's items: at most `max_leaf` per BVH leaf, `block` at a time
/// (four triangles share one SIMD test). A leaf costs the BVH's build `leaf_cost`, and
/// `block_cost` more for each block past its first, in units of a node visit.
#[derive(Clone, Copy, Debug)]
pub struct LeafSize {
    pub max_leaf: usize,
    pub block: usize,
    pub leaf_cost: f32,
    pub block_cost: f32,
}

impl LeafSize {
    /// Items tested one by one (scene primitives), each test as costly as a node visit.
    pub const SINGLE: LeafSize = LeafSize {
        max_leaf: 4,
        block: 1,
        leaf_cost: 1.0,
        block_cost: 1.0,
    };

    /// The blocks that `n` items fill.
    pub fn blocks(&self, n: usize) -> usize {
        n.div_ceil(self.block)
    }

    /// What testing a leaf of `n` items costs, in node visits.
    pub fn cost(&self, n: usize) -> f32 {
        self.leaf_cost + self.block_cost * (self.blocks(n) as f32 - 1.0)
    }
}

/// For the structures that file items in cells (the grid and the octree), a finer test
/// than an item's box: whether item `i` may reach into a cell's box. It must never say no
/// where the item does reach in (a triangle's exact test against the box, say); a cell
/// kept for an item that misses it costs only a test.
pub type Reaches<'a> = &'a (dyn Fn(u32, &Bounds3) -> bool + Sync);

#[derive(Clone, Debug)]
pub enum Accel {
    Bvh(Bvh),
    Grid(Grid),
    Octree(Octree),
    None(BruteForce),
}

impl Default for Accel {
    fn default() -> Self {
        Accel::Bvh(Bvh::default())
    }
}

impl Accel {
    /// Builds a `kind` structure over items given by their bounds (empty boxes are never
    /// returned by traversal).
    pub fn build(kind: AccelKind, item_bounds: &[Bounds3], leaf: LeafSize) -> Accel {
        Accel::build_with(kind, item_bounds, leaf, None)
    }

    /// [`Accel::build`], with the grid and the octree filing an item only in the cells
    /// that `reaches` says it may reach into, not in every cell its box meets.
    pub fn build_with(
        kind: AccelKind,
        item_bounds: &[Bounds3],
        leaf: LeafSize,
        reaches: Option<Reaches>,
    ) -> Accel {
        match kind {
            AccelKind::Bvh => Accel::Bvh(Bvh::build(item_bounds, leaf)),
            AccelKind::Grid => Accel::Grid(Grid::build(item_bounds, leaf.block, reaches)),
            AccelKind::Octree => Accel::Octree(Octree::build(item_bounds, leaf.block, reaches)),
            AccelKind::None => Accel::None(BruteForce::build(item_bounds)),
        }
    }

    pub fn kind(&self) -> AccelKind {
        match self {
            Accel::Bvh(_) => AccelKind::Bvh,
            Accel::Grid(_) => AccelKind::Grid,
            Accel::Octree(_) => AccelKind::Octree,
            Accel::None(_) => AccelKind::None,
        }
    }

    /// Bounds of all items.
    pub fn bounds(&self) -> Bounds3 {
        match self {
            Accel::Bvh(a) => a.bounds(),
            Accel::Grid(a) => a.bounds(),
            Accel::Octree(a) => a.bounds(),
            Accel::None(a) => a.bounds(),
        }
    }

    /// Whether a grid or an octree had to bound the references its cells hold (items that
    /// overlap many cells), at some cost in speed.
    pub fn capped(&self) -> bool {
        match self {
            Accel::Grid(a) => a.capped(),
            Accel::Octree(a) => a.capped(),
            Accel::Bvh(_) | Accel::None(_) => false,
        }
    }

    /// Bytes the structure itself occupies (nodes, cells and item lists).
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Accel>()
            + match self {
                Accel::Bvh(a) => a.memory_bytes(),
                Accel::Grid(a) => a.memory_bytes(),
                Accel::Octree(a) => a.memory_bytes(),
                Accel::None(a) => a.memory_bytes(),
            }
    }

    /// Hands `visit(items, t_max)` runs of items whose bounds the ray may meet in
    /// (0, t_max), roughly nearest first. `visit` tests them, may lower `t_max` (to the
    /// nearest hit so far) to prune what lies beyond, and returns false to stop. No item is
    /// handed over twice for one ray.
    #[inline]
    pub fn traverse(&self, ray: &Ray, t_max: f64, visit: impl FnMut(&[u32], &mut f64) -> bool) {
        match self {
            Accel::Bvh(a) => a.traverse(ray, t_max, visit),
            Accel::Grid(a) => a.traverse(ray, t_max, visit),
            Accel::Octree(a) => a.traverse(ray, t_max, visit),
            Accel::None(a) => a.traverse(ray, t_max, visit),
        }
    }

    /// [`Accel::traverse`] for a caller to whom an item handed over twice costs little and
    /// changes nothing, such as a nearest- or any-hit query over triangles: the grid and the
    /// octree then skip mailboxing, which costs more than the repeated tests it saves.
    #[inline]
    pub fn traverse_repeating(
        &self,
        ray: &Ray,
        t_max: f64,
        visit: impl FnMut(&[u32], &mut f64) -> bool,
    ) {
        match self {
            Accel::Bvh(a) => a.traverse(ray, t_max, visit),
            Accel::Grid(a) => a.traverse_repeating(ray, t_max, visit),
            Accel::Octree(a) => a.traverse_repeating(ray, t_max, visit),
            Accel::None(a) => a.traverse(ray, t_max, visit),
        }
    }
}

/// What pads a run of items to whole blocks in the lists the structures hand a caller that
/// stores its items in blocks (`take_padded_order`, `take_padded_runs`).
pub const PAD: u32 = u32::MAX;

/// Appends `items` to `list`, then [`PAD`] entries up to a whole number of `block`s.
fn append_padded(list: &mut Vec<u32>, items: &[u32], block: usize) {
    list.extend_from_slice(items);
    list.resize(list.len().next_multiple_of(block), PAD);
}

/// The axis of the smallest of three times, and that time (the grid's and the octree's next
/// wall). Written as selects, not branches: which wall comes next is a coin toss the CPU
/// cannot predict.
#[inline(always)]
fn nearest(t: [f64; 3]) -> (usize, f64) {
    use std::hint::select_unpredictable as select;
    let y_first = t[1] < t[0];
    let (axis, time) = select(y_first, (1, t[1]), (0, t[0]));
    select(t[2] < time, (2, t[2]), (axis, time))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    fn cube(center: Vec3, half: f64) -> Bounds3 {
        Bounds3::new(center - Vec3::ONE * half, center + Vec3::ONE * half)
    }

    #[test]
    fn cells_filed_by_the_finer_test_hold_fewer_items_and_keep_those_reached() {
        use crate::sampling::Rng;
        // Small triangles spread through the unit cube make the cells small; slivers along
        // its diagonal have boxes that cover many cells the slivers themselves miss.
        let mut rng = Rng::new(11, 0);
        let mut triangles: Vec<[Vec3; 3]> = (0..400)
            .map(|_| {
                let c = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
                [c, c + Vec3::X * 0.02, c + Vec3::Y * 0.02]
            })
            .collect();
        for k in 0..10 {
            let shift = Vec3::new(0.0, 0.0, k as f64 * 0.05);
            let (a, b) = (Vec3::ZERO + shift, Vec3::ONE * 0.7 + shift);
            triangles.push([a, b, b + Vec3::new(0.01, -0.01, 0.0)]);
        }
        let bounds: Vec<Bounds3> = triangles.iter().map(|t| Bounds3::from_points(*t)).collect();
        let reaches = |i: u32, cell: &Bounds3| cell.meets_triangle(triangles[i as usize]);
        for kind in [AccelKind::Grid, AccelKind::Octree] {
            let by_box = Accel::build(kind, &bounds, LeafSize::SINGLE);
            let finer = Accel::build_with(kind, &bounds, LeafSize::SINGLE, Some(&reaches));
            let (coarse, fine) = (by_box.memory_bytes(), finer.memory_bytes());
            assert!(fine < coarse, "{kind:?}: {fine} bytes against {coarse}");
            // A ray through a point of a triangle is handed that triangle.
            for (i, t) in triangles.iter().enumerate() {
                for (u, v) in [(0.2, 0.2), (0.6, 0.3), (0.05, 0.9)] {
                    let p = t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v * (1.0 - u);
                    let d = Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, 1.0);
                    let ray = Ray::new(p - d * 3.0, d);
                    let mut handed = false;
                    finer.traverse(&ray, f64::INFINITY, |items, _| {
                        handed |= items.contains(&(i as u32));
                        true
                    });
                    assert!(handed, "{kind:?}: triangle {i} not handed at {p:?}");
                }
            }
        }
    }

    #[test]
    fn overlapping_items_keep_grids_and_octrees_within_a_few_times_the_bvh() {
        // 6000 copies of one triangle's box made the grid file each in 20 000 cells
        // (3.6 GB with a mesh's blocks); boxes flat across the octree's middle plane fell in
        // both halves at every level. Both now stop at their reference budget, and say so.
        let triangle = Bounds3::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0));
        let coincident = vec![triangle; 6000];
        // Slivers as long as every cell they are in fall in both halves at every level.
        let sliver = Bounds3::new(Vec3::new(0.0, 0.3, 0.3), Vec3::new(1.0, 0.301, 0.3));
        let slivers = vec![sliver; 1000];
        for (items, kind) in [
            (&coincident, AccelKind::Grid),
            (&slivers, AccelKind::Octree),
        ] {
            let accel = Accel::build(kind, items, LeafSize::SINGLE);
            let bvh = Accel::build(AccelKind::Bvh, items, LeafSize::SINGLE).memory_bytes();
            let bytes = accel.memory_bytes();
            assert!(accel.capped(), "{kind:?}");
            assert!(bytes < 8 * bvh, "{kind:?}: {bytes} bytes, the BVH {bvh}");
            // Still every item is found.
            let ray = Ray::new(Vec3::new(0.5, 0.3005, 5.0), -Vec3::Z);
            let mut handed = 0;
            accel.traverse(&ray, f64::INFINITY, |run, _| {
                handed += run.len();
                true
            });
            assert!(handed >= items.len() - 2, "{kind:?}: {handed} handed");
        }
        // An ordinary flat mesh is not capped: the octree's root is thickened across it.
        let floor: Vec<Bounds3> = (0..20_000)
            .map(|i| {
                let c = Vec3::new((i % 141) as f64 / 141.0, (i / 141) as f64 / 141.0, 0.0);
                Bounds3::new(c, c + Vec3::new(0.007, 0.007, 0.0))
            })
            .collect();
        let octree = Accel::build(AccelKind::Octree, &floor, LeafSize::SINGLE);
        assert!(!octree.capped());
        let grid = Accel::build(AccelKind::Grid, &floor, LeafSize::SINGLE);
        assert!(!grid.capped());
    }

    /// Each walk counts the nodes it visits on its thread: brute force a bounding sphere per
    /// item, whatever the ray; a BVH one node for a ray that misses the root's children; a
    /// grid and an octree none for a ray that misses their region. A ray down a row of 64
    /// cubes that stops at the first hit costs the structures a few visits, brute force 64.
    #[test]
    fn walks_count_the_nodes_they_visit() {
        let cubes: Vec<Bounds3> = (0..64)
            .map(|i| cube(Vec3::new(i as f64 * 3.0, 0.0, 0.0), 1.0))
            .collect();
        let along = Ray::new(Vec3::new(-5.0, 0.0, 0.0), Vec3::X);
        let beside = Ray::new(Vec3::new(-5.0, 1000.0, 0.0), Vec3::X);
        for kind in AccelKind::ALL {
            let accel = Accel::build(kind, &cubes, LeafSize::SINGLE);
            let visits = |ray: &Ray| {
                let ((), spent) = cost::spent(|| {
                    accel.traverse(ray, f64::INFINITY, |items, t_max| {
                        // The first cube's near face is the nearest hit.
                        if items.contains(&0) {
                            *t_max = 4.0;
                        }
                        true
                    })
                });
                assert_eq!(spent.tests, 0, "{kind:?}: the callers count the tests");
                spent.nodes
            };
            let (hit, missed) = (visits(&along), visits(&beside));
            match kind {
                AccelKind::None => assert_eq!((hit, missed), (64, 64)),
                AccelKind::Bvh => assert_eq!(missed, 1),
                _ => assert_eq!(missed, 0, "{kind:?}"),
            }
            if kind != AccelKind::None {
                assert!((1..=12).contains(&hit), "{kind:?}: {hit} visits");
            }
        }
    }

    #[test]
    fn nearest_names_an_axis_of_the_smallest_time() {
        let values = [0.0, 1.0, 2.0, f64::INFINITY];
        for &x in &values {
            for &y in &values {
                for &z in &values {
                    let t = [x, y, z];
                    let min = x.min(y).min(z);
                    let (axis, time) = nearest(t);
                    assert_eq!(t[axis], min, "{t:?}");
                    assert_eq!(time, min, "{t:?}");
                }
            }
        }
    }

    #[test]
    fn a_ground_under_a_model_is_split_off_and_many_large_items_are_not() {
        let ground = Bounds3::new(Vec3::new(-12.0, 0.0, -12.0), Vec3::new(12.0, 0.0, 12.0));
        let mut items: Vec<Bounds3> = (0..20)
            .map(|i| cube(Vec3::new(i as f64 * 0.1, 1.0, 0.0), 0.05))
            .collect();
        items.push(ground);
        items.push(Bounds3::default());
        let LargeSplit { filed, large, .. } = split_off_large(&items);
        assert_eq!(large, vec![20]);
        assert_eq!(filed, (0..20).collect::<Vec<u32>>());
        // Nothing but large items: they stay filed.
        let LargeSplit { filed, large, .. } = split_off_large(&[ground, ground]);
        assert_eq!((filed, large), (vec![0, 1], vec![]));
        // More large items than are worth testing on every ray.
        let walls = vec![ground; MAX_LARGE + 1];
        let LargeSplit { filed, large, .. } =
            split_off_large(&[walls, vec![cube(Vec3::ZERO, 0.1)]].concat());
        assert_eq!((filed.len(), large.len()), (MAX_LARGE + 2, 0));
    }
}
