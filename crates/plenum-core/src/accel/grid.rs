//! A uniform grid (Fujimoto et al. 1986) traversed by the 3-D DDA of Amanatides and Woo
//! (1987), with mailboxing so an item filed in several cells is tested once per ray.
//! The resolution follows the usual heuristic: cells of equal size along each axis,
//! about λ·N of them in all (∛(λN/V) per unit length).
//!
//! Most of a ray's cells are empty, and stepping through them one by one is most of the
//! cost. So the grid also keeps which blocks of 4 × 4 × 4 cells (macro cells) hold anything,
//! and a ray crosses an empty block in one jump to its far wall. Every step stays within
//! the cells the ray touches up to rounding, which the margin items are filed with covers.

use super::mailbox::{new_owner, Mailbox};
use super::pages::LargeArray;
use super::{append_padded, nearest, split_off_large, LargeSplit, Reaches};
use crate::math::{Bounds3, Ray, Vec3};
use std::ops::Range;

/// Cells per item, for items tested one by one (a scene's primitives).
const LAMBDA: f64 = 1.5;
/// Cells per item, for items tested four at a time (a mesh's triangles, in blocks), whose
/// tests cost less per item: 5–11 % faster than [`LAMBDA`] on the dragon's rays.
const LAMBDA_BLOCKS: f64 = 0.75;
const MAX_RESOLUTION: usize = 512;
/// Most cell references per filed item (counted by boxes, before the finer test, which
/// halves them on a flat mesh: 8.7 by box at its λN resolution), plus [`SPARE_REFERENCES`]. Items that overlap (6000 copies of one triangle) would otherwise
/// each be filed in thousands of cells: 3.6 GB. Where the resolution would need more, it is
/// coarsened until they fit, and the grid says so ([`Grid::capped`]).
const REFERENCES_PER_ITEM: usize = 16;
const SPARE_REFERENCES: usize = 1 << 12;
/// Cells per macro cell along each axis (a power of two).
const MACRO: usize = 4;

#[derive(Clone, Debug)]
pub struct Grid {
    /// The cells' region: the bounds of the items in them.
    region: Bounds3,
    /// The bounds of all the items, large ones included.
    bounds: Bounds3,
    /// Items as large as the scene, tested by every ray (see [`split_off_large`]).
    large: Vec<u32>,
    /// After [`Grid::take_padded_runs`], the large items' run: the first `large_run` slots.
    large_run: usize,
    resolution: [usize; 3],
    cell_size: Vec3,
    /// 1 / cell_size, or 0 along a flat axis: cells are found by a product, not a quotient.
    inv_cell_size: Vec3,
    /// Items of cell c are `items[starts[c]..starts[c + 1]]`; on huge pages where there are
    /// many cells (see [`super::pages`]).
    starts: LargeArray<u32>,
    items: Vec<u32>,
    /// Per macro cell: some cell of it holds an item.
    macro_full: Vec<bool>,
    macro_resolution: [usize; 3],
    item_count: usize,
    /// The resolution was coarsened to keep within [`REFERENCES_PER_ITEM`].
    capped: bool,
    owner: u64,
}

impl Grid {
    /// A grid over items given by their bounds, for a caller that tests `block` items at a
    /// time; with `reaches`, an item is filed only in the cells it may reach into.
    pub fn build(item_bounds: &[Bounds3], block: usize, reaches: Option<Reaches>) -> Grid {
        let lambda = if block > 1 { LAMBDA_BLOCKS } else { LAMBDA };
        let LargeSplit {
            filed: bounded,
            large,
            region,
            bounds,
        } = split_off_large(item_bounds);
        let mut grid = Grid {
            region,
            bounds,
            large,
            large_run: 0,
            resolution: [1; 3],
            cell_size: Vec3::ONE,
            inv_cell_size: Vec3::ONE,
            starts: vec![0, 0].into(),
            items: Vec::new(),
            macro_full: vec![true],
            macro_resolution: [1; 3],
            item_count: item_bounds.len(),
            capped: false,
            owner: new_owner(),
        };
        if bounded.is_empty() {
            return grid;
        }
        let extent = region.diagonal();
        let longest = extent.max_component();
        // Flat or point-like scenes: give every axis some thickness so the volume is positive.
        let floor = (longest * 1e-3).max(f64::MIN_POSITIVE);
        let thick = Vec3::new(
            extent.x.max(floor),
            extent.y.max(floor),
            extent.z.max(floor),
        );
        let per_unit = (lambda * bounded.len() as f64 / (thick.x * thick.y * thick.z)).cbrt();
        for a in 0..3 {
            let cells = (extent[a] * per_unit).round() as usize;
            grid.resolution[a] = cells.clamp(1, MAX_RESOLUTION);
        }
        // Items are filed by their boxes grown a little, so that rounding in the cell
        // arithmetic can never leave an item out of a cell the ray meets it in.
        let margin = longest * 1e-9;
        let filed = |i: u32| item_bounds[i as usize].expanded(margin);
        let budget = REFERENCES_PER_ITEM * bounded.len() + SPARE_REFERENCES;
        loop {
            grid.set_cell_size(extent);
            let references: usize = bounded.iter().map(|&i| grid.cells_met(&filed(i))).sum();
            if references <= budget || grid.resolution == [1; 3] {
                break;
            }
            grid.capped = true;
            grid.resolution = grid.resolution.map(|r| r.div_ceil(2));
        }
        let cell_count = grid.resolution.iter().product::<usize>();
        // Two passes: count each cell's items, then file them (compressed rows).
        // Asked of a cell grown as the item's box is, and by a little of its size more,
        // so that the finer test's own rounding never leaves an item out either.
        let pad = margin + 1e-6 * grid.cell_size.max_component();
        // Each item's cells, by its box and then by `reaches` (an item whose box lies in
        // one cell reaches into it); listed once, filed twice.
        let cells_of = |i: u32| {
            let b = filed(i);
            let finer = reaches.filter(|_| !grid.one_cell(&b));
            let mut cells = Vec::new();
            grid.for_cells(&b, |c, cell| {
                if finer.is_none_or(|reaches| reaches(i, &grid.cell_bounds(cell).expanded(pad))) {
                    cells.push(c)
                }
            });
            cells
        };
        let item_cells: Vec<Vec<usize>> = {
            use rayon::prelude::*;
            bounded.par_iter().map(|&i| cells_of(i)).collect()
        };
        let mut counts = vec![0u32; cell_count + 1];
        for &c in item_cells.iter().flatten() {
            counts[c] += 1;
        }
        let mut total = 0u32;
        for c in counts.iter_mut() {
            let n = *c;
            *c = total;
            total += n;
        }
        let mut fill = counts.clone();
        let mut items = vec![0u32; total as usize];
        for (&i, cells) in bounded.iter().zip(&item_cells) {
            for &c in cells {
                items[fill[c] as usize] = i;
                fill[c] += 1;
            }
        }
        grid.macro_resolution = grid.resolution.map(|r| r.div_ceil(MACRO));
        let [mx, my, mz] = grid.macro_resolution;
        grid.macro_full = vec![false; mx * my * mz];
        let [nx, ny, _] = grid.resolution;
        for c in 0..cell_count {
            if counts[c + 1] > counts[c] {
                let (x, y, z) = (c % nx, (c / nx) % ny, c / (nx * ny));
                grid.macro_full[((z / MACRO) * my + y / MACRO) * mx + x / MACRO] = true;
            }
        }
        grid.starts = counts.into();
        grid.items = items;
        grid
    }

    pub fn bounds(&self) -> Bounds3 {
        self.bounds
    }

    pub fn resolution(&self) -> [usize; 3] {
        self.resolution
    }

    pub fn memory_bytes(&self) -> usize {
        (self.starts.len() + self.items.len() + self.large.len()) * 4 + self.macro_full.len()
    }

    /// Whether the resolution had to be coarsened to bound the cells' references (items
    /// that overlap many cells each): rays then test more items per cell.
    pub fn capped(&self) -> bool {
        self.capped
    }

    /// Cell sizes and their inverses for the current resolution over a region of `extent`.
    fn set_cell_size(&mut self, extent: Vec3) {
        let r = self.resolution.map(|r| r as f64);
        self.cell_size = Vec3::new(extent.x / r[0], extent.y / r[1], extent.z / r[2]);
        let inverse = |size: f64| if size > 0.0 { 1.0 / size } else { 0.0 };
        self.inv_cell_size = Vec3::new(
            inverse(self.cell_size.x),
            inverse(self.cell_size.y),
            inverse(self.cell_size.z),
        );
    }

    /// How many cells the box `b` meets.
    fn cells_met(&self, b: &Bounds3) -> usize {
        (0..3)
            .map(|a| self.cell_of(b.max[a], a) - self.cell_of(b.min[a], a) + 1)
            .product()
    }

    /// The cell of a point along one axis, clamped to the grid.
    /// Along a flat axis the inverse cell size is 0, which puts every point in its one cell.
    #[inline(always)]
    fn cell_of(&self, x: f64, axis: usize) -> usize {
        // Truncation is floor here (c ≥ 0), without a call into libm; a signed conversion
        // is one instruction, and the clamp keeps it in range.
        let c = (x - self.region.min[axis]) * self.inv_cell_size[axis];
        (c.min(MAX_RESOLUTION as f64) as i64).clamp(0, self.resolution[axis] as i64 - 1) as usize
    }

    /// Hands `f` each cell the box `b` meets: its index and its coordinates.
    fn for_cells(&self, b: &Bounds3, mut f: impl FnMut(usize, [usize; 3])) {
        let lo = [0, 1, 2].map(|a| self.cell_of(b.min[a], a));
        let hi = [0, 1, 2].map(|a| self.cell_of(b.max[a], a));
        let [nx, ny, _] = self.resolution;
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    f((z * ny + y) * nx + x, [x, y, z]);
                }
            }
        }
    }

    /// Whether the box `b` lies in one cell.
    fn one_cell(&self, b: &Bounds3) -> bool {
        (0..3).all(|a| self.cell_of(b.min[a], a) == self.cell_of(b.max[a], a))
    }

    /// The box of the cell at `cell`.
    fn cell_bounds(&self, cell: [usize; 3]) -> Bounds3 {
        let corner = |c: [usize; 3]| {
            Vec3::new(
                self.region.min.x + c[0] as f64 * self.cell_size.x,
                self.region.min.y + c[1] as f64 * self.cell_size.y,
                self.region.min.z + c[2] as f64 * self.cell_size.z,
            )
        };
        Bounds3::new(corner(cell), corner(cell.map(|c| c + 1)))
    }

    /// Visits the cells the ray crosses in order, handing `visit` the untested items of each
    /// (see [`super::Accel::traverse`]).
    ///
    /// Two walks in step: one over macro cells, which crosses an empty one in a single step,
    /// and one over the cells of each macro cell that holds anything.
    pub fn traverse(&self, ray: &Ray, t_max: f64, mut visit: impl FnMut(&[u32], &mut f64) -> bool) {
        let mut t_max = t_max;
        // First, so that a hit on them (the ground, say) prunes the walk.
        if !self.large.is_empty() && !visit(&self.large, &mut t_max) {
            return;
        }
        let mut mailbox = None;
        self.walk(ray, t_max, |first, end, t_max| {
            mailbox
                .get_or_insert_with(|| Mailbox::start(self.owner, self.item_count))
                .visit_untested(self.run(first, end), t_max, &mut visit)
        });
    }

    /// [`Grid::traverse`] without mailboxing: an item in several cells may be handed over
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
        self.walk(ray, t_max, |first, end, t_max| {
            visit(self.run(first, end), t_max)
        });
    }

    /// Hands the caller the items of the large run and of every cell, each padded with
    /// [`super::PAD`] entries to a whole number of `block`s and starting a block, in place of the
    /// grid's own lists: for a caller that stores its items so, as a mesh stores its
    /// triangles in blocks. Only [`Grid::traverse_runs`] may be used afterwards.
    pub fn take_padded_runs(&mut self, block: usize) -> Vec<u32> {
        let mut padded = Vec::with_capacity(self.items.len() * 2);
        append_padded(&mut padded, &self.large, block);
        self.large_run = padded.len();
        let mut starts = Vec::with_capacity(self.starts.len());
        for c in 0..self.starts.len() - 1 {
            starts.push(padded.len() as u32);
            let items = &self.items[self.starts[c] as usize..self.starts[c + 1] as usize];
            append_padded(&mut padded, items, block);
        }
        starts.push(padded.len() as u32);
        self.large = Vec::new();
        self.starts = starts.into();
        self.items = Vec::new();
        padded
    }

    /// [`Grid::traverse_repeating`] after [`Grid::take_padded_runs`], handing each run as
    /// its range of positions in the padded list (pads included).
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
        self.walk(ray, t_max, |first, end, t_max| visit(first..end, t_max));
    }

    /// Cell items `first..end`.
    #[inline(always)]
    fn run(&self, first: usize, end: usize) -> &[u32] {
        debug_assert!(first <= end && end <= self.items.len());
        // SAFETY: `starts` holds ascending offsets into `items`.
        unsafe { self.items.get_unchecked(first..end) }
    }

    /// Walks the cells the ray crosses in order, handing `hand(first, end, t_max)` the run
    /// `first..end` of the items of each one that holds any, until it returns false.
    #[inline(always)]
    fn walk(&self, ray: &Ray, t_max: f64, mut hand: impl FnMut(usize, usize, &mut f64) -> bool) {
        let mut t_max = t_max;
        // Nothing filed in any cell.
        if self.starts.last() == Some(&0) {
            return;
        }
        // The only divisions per ray.
        let d = ray.direction;
        let inv_dir = Vec3::new(1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
        // Many rays miss the region: before the walk's set-up.
        let Some((t_enter, t_exit)) = self.region.intersect(ray, inv_dir, t_max) else {
            return;
        };
        let walk = Walk::new(self, ray, inv_dir);
        let mut visits = super::cost::Visits::start();
        let mut limit = t_max.min(t_exit);
        // The cell walk starts only in a macro cell that holds anything (most rays enter
        // the region through empty ones).
        let p = ray.at(t_enter);
        let mut block = [0; 3];
        for a in 0..3 {
            block[a] = self.cell_of(p[a], a) / MACRO;
        }
        let mut block_next = walk.walls(self, block, MACRO);
        let mut m = self.macro_index(block);
        let (mut cell, mut next, mut stop) = ([0; 3], [0.0; 3], [0; 3]);
        // The cell walk is under way inside the current macro cell; when not, the ray
        // entered this macro cell at `t_block`, through a wall across `entered_along` (or
        // none, 3, where it starts).
        let mut walking = false;
        let (mut t_block, mut entered_along) = (t_enter, 3);
        loop {
            if self.macro_full[m] {
                if !walking {
                    cell = self.entry_cell(ray.at(t_block), block, entered_along, &walk);
                    next = walk.walls(self, cell, 1);
                    for a in 0..3 {
                        stop[a] = self.stop(block[a], a, &walk);
                    }
                    walking = true;
                }
                let mut c = self.index(cell);
                // Walk the cells until the ray leaves the macro cell along axis `a`.
                let a = loop {
                    visits.nodes += 1;
                    debug_assert!(c + 1 < self.starts.len());
                    // SAFETY: `c` indexes the cell `cell`, inside the grid (checked after
                    // each step), and `starts` has one more entry than there are cells.
                    let (first, end) = unsafe {
                        (
                            *self.starts.get_unchecked(c) as usize,
                            *self.starts.get_unchecked(c + 1) as usize,
                        )
                    };
                    if first < end {
                        if !hand(first, end, &mut t_max) {
                            return;
                        }
                        limit = t_max.min(t_exit);
                    }
                    let (a, t) = nearest(next);
                    if t > limit {
                        return;
                    }
                    // One step across the nearest wall. Each axis has its own arm, with
                    // its own state held in registers: which arm is taken is a coin toss,
                    // but selects over all three axes, or state indexed by the axis (kept
                    // in memory), run more instructions and are slower.
                    let mut advance = |i: usize| {
                        cell[i] = cell[i].wrapping_add_signed(walk.step[i]);
                        next[i] += walk.delta[i];
                        c = c.wrapping_add_signed(walk.stride[i]);
                        cell[i] == stop[i]
                    };
                    let left = match a {
                        0 => advance(0),
                        1 => advance(1),
                        _ => advance(2),
                    };
                    if left {
                        break a;
                    }
                };
                // The cell walk carries on in the neighbouring macro cell, if the grid
                // goes on (below zero wraps to beyond it).
                if cell[a] >= self.resolution[a] {
                    return;
                }
                block[a] = block[a].wrapping_add_signed(walk.step[a]);
                block_next[a] += walk.macro_delta[a];
                stop[a] = self.stop(block[a], a, &walk);
                m = m.wrapping_add_signed(walk.macro_stride[a]);
            } else {
                visits.nodes += 1;
                let (a, t) = nearest(block_next);
                if t > limit {
                    return;
                }
                // As in the cell walk, an arm per axis.
                let mut advance = |i: usize| {
                    block[i] = block[i].wrapping_add_signed(walk.step[i]);
                    block_next[i] += walk.macro_delta[i];
                    m = m.wrapping_add_signed(walk.macro_stride[i]);
                    block[i] >= self.macro_resolution[i]
                };
                let outside = match a {
                    0 => advance(0),
                    1 => advance(1),
                    _ => advance(2),
                };
                if outside {
                    return;
                }
                (t_block, entered_along) = (t, a);
                walking = false;
            }
        }
    }

    /// The first cell along axis `a` past macro cell `block` the way the ray steps: in the
    /// next macro cell, or just outside the grid (`usize::MAX` below it).
    fn stop(&self, block: usize, a: usize, walk: &Walk) -> usize {
        if walk.step[a] > 0 {
            ((block + 1) * MACRO).min(self.resolution[a])
        } else {
            (block * MACRO).wrapping_sub(1)
        }
    }

    /// The cell of macro cell `block` where a ray that entered it at `p` across a wall
    /// along axis `entered` (or started in it, `entered` 3) starts: on that axis the first
    /// row it meets, on the others where `p` lies, kept within the macro cell against
    /// rounding.
    #[inline(always)]
    fn entry_cell(&self, p: Vec3, block: [usize; 3], entered: usize, walk: &Walk) -> [usize; 3] {
        let mut cell = [0; 3];
        for a in 0..3 {
            let low = block[a] * MACRO;
            let high = (low + MACRO).min(self.resolution[a]) - 1;
            cell[a] = if a != entered {
                self.cell_of(p[a], a).clamp(low, high)
            } else if walk.step[a] > 0 {
                low
            } else {
                high
            };
        }
        cell
    }

    fn index(&self, cell: [usize; 3]) -> usize {
        let [nx, ny, _] = self.resolution;
        (cell[2] * ny + cell[1]) * nx + cell[0]
    }

    fn macro_index(&self, block: [usize; 3]) -> usize {
        let [mx, my, _] = self.macro_resolution;
        (block[2] * my + block[1]) * mx + block[0]
    }
}

/// A ray's constants for walking the grid.
struct Walk {
    origin: Vec3,
    inv_dir: Vec3,
    /// −1, 0 or +1 cell per step along each axis.
    step: [isize; 3],
    /// The change of the cell index per step along each axis, and of the macro cell index.
    stride: [isize; 3],
    macro_stride: [isize; 3],
    /// The time between walls along each axis, of cells and of macro cells.
    delta: [f64; 3],
    macro_delta: [f64; 3],
}

impl Walk {
    #[inline(always)]
    fn new(grid: &Grid, ray: &Ray, inv_dir: Vec3) -> Walk {
        let [nx, ny, _] = grid.resolution;
        let [mx, my, _] = grid.macro_resolution;
        let strides = [1, nx as isize, (nx * ny) as isize];
        let macro_strides = [1, mx as isize, (mx * my) as isize];
        let mut walk = Walk {
            origin: ray.origin,
            inv_dir,
            step: [0; 3],
            stride: [0; 3],
            macro_stride: [0; 3],
            delta: [f64::INFINITY; 3],
            macro_delta: [f64::INFINITY; 3],
        };
        // Plain loops: an array's `map` here is left as a call.
        for a in 0..3 {
            let d = ray.direction[a];
            let step = (d > 0.0) as isize - (d < 0.0) as isize;
            walk.step[a] = step;
            walk.stride[a] = step * strides[a];
            walk.macro_stride[a] = step * macro_strides[a];
            if step != 0 {
                walk.delta[a] = (grid.cell_size[a] * inv_dir[a]).abs();
                walk.macro_delta[a] = walk.delta[a] * MACRO as f64;
            }
        }
        walk
    }

    /// When the ray crosses wall `wall` (the low wall of that cell) along axis `a`.
    fn time_at(&self, grid: &Grid, a: usize, wall: usize) -> f64 {
        // Through i64: an unsigned conversion to f64 takes several instructions.
        let x = grid.region.min[a] + wall as i64 as f64 * grid.cell_size[a];
        (x - self.origin[a]) * self.inv_dir[a]
    }

    /// When the ray leaves `cell`, in cells `size` wide (1, or MACRO for macro cells),
    /// through each axis's wall ahead (never along an axis it does not move along).
    fn walls(&self, grid: &Grid, cell: [usize; 3], size: usize) -> [f64; 3] {
        let mut t = [f64::INFINITY; 3];
        for a in 0..3 {
            if self.step[a] != 0 {
                let ahead = if self.step[a] > 0 {
                    cell[a] + 1
                } else {
                    cell[a]
                };
                t[a] = self.time_at(grid, a, ahead * size);
            }
        }
        t
    }
}
