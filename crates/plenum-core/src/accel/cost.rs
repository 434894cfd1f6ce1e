//! What the acceleration structures cost: the nodes (or cells) a ray's walk visits and the
//! primitives handed to their intersection tests, counted per thread. The render reads the
//! count before and after each pixel, which gives the `cost` view and the summary line's
//! totals. Counting stays on: a few additions per walk cost 0.7–1.2 % more instructions
//! (callgrind, 7 December: the path tracer on the Cornell box, Whitted on teapot.nff and
//! balls3.nff), within the noise of a render's time.

use std::cell::Cell;
use std::ops::{Add, AddAssign, Sub};

/// Work done by the acceleration structures.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Cost {
    /// Nodes visited: a BVH's interior nodes (eight boxes tested each), a grid's cells and
    /// empty macro cells stepped through, an octree's nodes entered, brute force's bounding
    /// spheres.
    pub nodes: u64,
    /// Intersection tests: a scene's primitives and a mesh's triangles.
    pub tests: u64,
}

impl Add for Cost {
    type Output = Cost;
    fn add(self, o: Cost) -> Cost {
        Cost {
            nodes: self.nodes + o.nodes,
            tests: self.tests + o.tests,
        }
    }
}

impl AddAssign for Cost {
    fn add_assign(&mut self, o: Cost) {
        *self = *self + o;
    }
}

impl Sub for Cost {
    type Output = Cost;
    /// The work done between two readings of [`so_far`] on one thread.
    fn sub(self, o: Cost) -> Cost {
        Cost {
            nodes: self.nodes - o.nodes,
            tests: self.tests - o.tests,
        }
    }
}

thread_local! {
    static SO_FAR: Cell<Cost> = const {
        Cell::new(Cost {
            nodes: 0,
            tests: 0,
        })
    };
}

/// The work this thread has done since it started.
pub fn so_far() -> Cost {
    SO_FAR.with(Cell::get)
}

/// Runs `work`, returning what it returns and the cost it spent on this thread.
pub fn spent<R>(work: impl FnOnce() -> R) -> (R, Cost) {
    let before = so_far();
    let r = work();
    (r, so_far() - before)
}

/// Counts `n` intersection tests.
#[inline(always)]
pub(crate) fn tested(n: usize) {
    SO_FAR.with(|c| {
        let mut v = c.get();
        v.tests += n as u64;
        c.set(v)
    });
}

/// The nodes one walk visits, added to the thread's count when the walk ends, at whichever
/// return.
pub(crate) struct Visits {
    pub nodes: u32,
}

impl Visits {
    #[inline(always)]
    pub fn start() -> Visits {
        Visits { nodes: 0 }
    }
}

impl Drop for Visits {
    #[inline(always)]
    fn drop(&mut self) {
        let nodes = self.nodes;
        SO_FAR.with(|c| {
            let mut v = c.get();
            v.nodes += nodes as u64;
            c.set(v)
        });
    }
}
