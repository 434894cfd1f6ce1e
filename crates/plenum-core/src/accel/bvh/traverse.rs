//! The walks of a ray through the BVH: front to back for the nearest hit, in any order for
//! a shadow ray, with a fixed-size stack and the children fetched ahead of their test.

use super::{is_leaf, leaf_run, Bvh, MAX_DEPTH, WIDTH};
use crate::accel::cost;
#[cfg(target_arch = "x86_64")]
use crate::accel::ray_f32::BoxRayAvx;
use crate::accel::ray_f32::{round_up_distance, BoxRay};
use crate::accel::simd::F4;
use crate::math::Ray;
use std::mem::MaybeUninit;
use std::ops::Range;

/// A node pushes at most seven children. Each wide node is at least one binary split below
/// its parent; splits are binned down to MAX_DEPTH levels, then at most 31 levels more, as
/// every level halves the items.
const STACK: usize = 7 * (MAX_DEPTH + 32);

impl Bvh {
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
        let mut visits = cost::Visits::start();
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
                visits.nodes += 1;
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

/// A child waiting on the traversal stack: its entry distance, never negative, in the high
/// half and its reference in the low half. Non-negative floats order as their bits, so the
/// nearer of two entries is the smaller number.
#[inline(always)]
fn waiting(child: u32, near: f32) -> u64 {
    (u64::from(near.to_bits()) << 32) | u64::from(child)
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
