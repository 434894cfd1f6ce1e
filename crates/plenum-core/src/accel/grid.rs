//! A uniform grid (Fujimoto et al. 1986) traversed by the 3-D DDA of Amanatides and Woo
//! (1987), with mailboxing so an item filed in several cells is tested once per ray.
//! The resolution follows the usual heuristic: cells of equal size along each axis,
//! about λ·N of them in all (∛(λN/V) per unit length).
//!
//! Most of a ray's cells are empty, and stepping through them one by one is most of the
//! cost. So the grid also keeps which blocks of 4 × 4 × 4 cells (macro cells) hold anything,
//! and a ray crosses an empty block in one jump to its far wall.

use super::mailbox::{new_owner, Mailbox};
use crate::math::{Bounds3, Ray, Vec3};

/// Cells per item.
const LAMBDA: f64 = 1.5;
const MAX_RESOLUTION: usize = 512;
/// Cells per macro cell along each axis (a power of two).
const MACRO: usize = 4;

#[derive(Clone, Debug)]
pub struct Grid {
    bounds: Bounds3,
    resolution: [usize; 3],
    cell_size: Vec3,
    /// Items of cell c are `items[starts[c]..starts[c + 1]]`.
    starts: Vec<u32>,
    items: Vec<u32>,
    /// Per macro cell: some cell of it holds an item.
    macro_full: Vec<bool>,
    macro_resolution: [usize; 3],
    item_count: usize,
    owner: u64,
}

impl Grid {
    pub fn build(item_bounds: &[Bounds3]) -> Grid {
        let bounded: Vec<usize> = (0..item_bounds.len())
            .filter(|&i| !item_bounds[i].is_empty())
            .collect();
        let bounds = bounded
            .iter()
            .fold(Bounds3::default(), |b, &i| b.union(&item_bounds[i]));
        let mut grid = Grid {
            bounds,
            resolution: [1; 3],
            cell_size: Vec3::ONE,
            starts: vec![0, 0],
            items: Vec::new(),
            macro_full: vec![true],
            macro_resolution: [1; 3],
            item_count: item_bounds.len(),
            owner: new_owner(),
        };
        if bounded.is_empty() {
            return grid;
        }
        let extent = bounds.diagonal();
        let longest = extent.max_component();
        // Flat or point-like scenes: give every axis some thickness so the volume is positive.
        let floor = (longest * 1e-3).max(f64::MIN_POSITIVE);
        let thick = Vec3::new(
            extent.x.max(floor),
            extent.y.max(floor),
            extent.z.max(floor),
        );
        let per_unit = (LAMBDA * bounded.len() as f64 / (thick.x * thick.y * thick.z)).cbrt();
        for a in 0..3 {
            let cells = (extent[a] * per_unit).round() as usize;
            grid.resolution[a] = cells.clamp(1, MAX_RESOLUTION);
        }
        grid.cell_size = Vec3::new(
            extent.x / grid.resolution[0] as f64,
            extent.y / grid.resolution[1] as f64,
            extent.z / grid.resolution[2] as f64,
        );
        let cell_count = grid.resolution.iter().product::<usize>();
        // Two passes: count each cell's items, then file them (compressed rows).
        // Items are filed by their boxes grown a little, so that rounding in the cell
        // arithmetic can never leave an item out of a cell the ray meets it in.
        let margin = longest * 1e-9;
        let filed = |i: usize| item_bounds[i].expanded(margin);
        let mut counts = vec![0u32; cell_count + 1];
        for &i in &bounded {
            grid.for_cells(&filed(i), |c| counts[c] += 1);
        }
        let mut total = 0u32;
        for c in counts.iter_mut() {
            let n = *c;
            *c = total;
            total += n;
        }
        let mut fill = counts.clone();
        let mut items = vec![0u32; total as usize];
        for &i in &bounded {
            grid.for_cells(&filed(i), |c| {
                items[fill[c] as usize] = i as u32;
                fill[c] += 1;
            });
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
        grid.starts = counts;
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
        (self.starts.len() + self.items.len()) * 4 + self.macro_full.len()
    }

    /// The cell of a point along one axis, clamped to the grid.
    fn cell_of(&self, x: f64, axis: usize) -> usize {
        let size = self.cell_size[axis];
        if size <= 0.0 {
            return 0;
        }
        // Truncation is floor here (c ≥ 0), without a call into libm.
        let c = (x - self.bounds.min[axis]) / size;
        if c > 0.0 {
            (c as usize).min(self.resolution[axis] - 1)
        } else {
            0
        }
    }

    fn for_cells(&self, b: &Bounds3, mut f: impl FnMut(usize)) {
        let lo = [0, 1, 2].map(|a| self.cell_of(b.min[a], a));
        let hi = [0, 1, 2].map(|a| self.cell_of(b.max[a], a));
        let [nx, ny, _] = self.resolution;
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    f((z * ny + y) * nx + x);
                }
            }
        }
    }

    /// Visits the cells the ray crosses in order, handing `visit` the untested items of each
    /// (see [`super::Accel::traverse`]).
    pub fn traverse(&self, ray: &Ray, t_max: f64, mut visit: impl FnMut(&[u32], &mut f64) -> bool) {
        if self.items.is_empty() {
            return;
        }
        let Some((t_enter, t_exit)) = self.bounds.intersect_interval(ray, t_max) else {
            return;
        };
        let mut t_max = t_max;
        let p = ray.at(t_enter);
        let mut cell = [0usize; 3];
        let mut step = [0isize; 3];
        let mut next = [f64::INFINITY; 3];
        let mut delta = [f64::INFINITY; 3];
        for a in 0..3 {
            cell[a] = self.cell_of(p[a], a);
            let d = ray.direction[a];
            if d > 0.0 {
                step[a] = 1;
                let edge = self.bounds.min[a] + (cell[a] + 1) as f64 * self.cell_size[a];
                next[a] = (edge - ray.origin[a]) / d;
                delta[a] = self.cell_size[a] / d;
            } else if d < 0.0 {
                step[a] = -1;
                let edge = self.bounds.min[a] + cell[a] as f64 * self.cell_size[a];
                next[a] = (edge - ray.origin[a]) / d;
                delta[a] = -self.cell_size[a] / d;
            }
        }
        let mailbox = Mailbox::start(self.owner, self.item_count);
        let [nx, ny, _] = self.resolution;
        let [mx, my, _] = self.macro_resolution;
        loop {
            let m = ((cell[2] / MACRO) * my + cell[1] / MACRO) * mx + cell[0] / MACRO;
            if !self.macro_full[m] {
                // Jump across the empty macro cell: find the axis whose macro wall comes
                // first, move there, and bring the other axes up to that time.
                let walls = [0, 1, 2].map(|a| {
                    let first = cell[a] / MACRO * MACRO;
                    let last = (first + MACRO).min(self.resolution[a]) - 1;
                    if step[a] > 0 {
                        last - cell[a]
                    } else {
                        cell[a] - first
                    }
                });
                // An axis the ray does not move along is never crossed (and 0 · ∞ is NaN).
                let crossing = [0, 1, 2].map(|a| {
                    if step[a] == 0 {
                        f64::INFINITY
                    } else {
                        next[a] + walls[a] as f64 * delta[a]
                    }
                });
                let a = if crossing[0] < crossing[1] {
                    if crossing[0] < crossing[2] {
                        0
                    } else {
                        2
                    }
                } else if crossing[1] < crossing[2] {
                    1
                } else {
                    2
                };
                let t_out = crossing[a];
                if t_max < t_out || t_out > t_exit {
                    return;
                }
                for b in 0..3 {
                    if b == a || step[b] == 0 {
                        continue;
                    }
                    // Walls crossed before t_out, rounded down: being a cell behind only
                    // visits an empty cell; being a cell ahead could skip a full one.
                    let x = (t_out - next[b]) / delta[b];
                    let x = x - 1e-9 * (1.0 + x);
                    let crossed = if x > 0.0 {
                        // ⌈x⌉ without a call into libm.
                        let whole = x as usize;
                        (whole + usize::from((whole as f64) < x)).min(walls[b])
                    } else {
                        0
                    };
                    cell[b] = (cell[b] as isize + step[b] * crossed as isize) as usize;
                    next[b] += crossed as f64 * delta[b];
                }
                let moved = cell[a] as isize + step[a] * (walls[a] as isize + 1);
                if moved < 0 || moved >= self.resolution[a] as isize {
                    return;
                }
                cell[a] = moved as usize;
                next[a] = t_out + delta[a];
                continue;
            }
            let c = (cell[2] * ny + cell[1]) * nx + cell[0];
            let items = &self.items[self.starts[c] as usize..self.starts[c + 1] as usize];
            if !mailbox.visit_untested(items, &mut t_max, &mut visit) {
                return;
            }
            // Step to the neighbour across the nearest cell wall.
            let a = if next[0] < next[1] {
                if next[0] < next[2] {
                    0
                } else {
                    2
                }
            } else if next[1] < next[2] {
                1
            } else {
                2
            };
            // A hit before the wall cannot be beaten by anything in later cells.
            if t_max < next[a] || next[a] > t_exit {
                return;
            }
            let moved = cell[a] as isize + step[a];
            if moved < 0 || moved >= self.resolution[a] as isize {
                return;
            }
            cell[a] = moved as usize;
            next[a] += delta[a];
        }
    }
}
