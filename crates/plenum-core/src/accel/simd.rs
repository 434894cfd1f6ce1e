//! Four f32 lanes: SSE on x86-64 (part of the baseline, so no run-time detection), plain arrays
//! elsewhere; eight lanes with AVX on x86-64, where the CPU has it. Only what the node and
//! triangle tests need, and the [`Lanes`] trait over both, so that one triangle test serves
//! four lanes and eight.

#[cfg(target_arch = "x86_64")]
mod imp {
    use std::arch::x86_64::*;

    #[derive(Clone, Copy, Debug)]
    #[repr(transparent)]
    pub struct F4(__m128);

    // SAFETY (every `unsafe` block below): SSE and SSE2 are part of the x86-64 baseline, and
    // the loads read exactly the 16 bytes of a `[f32; 4]`.
    impl F4 {
        #[inline(always)]
        pub fn splat(v: f32) -> F4 {
            unsafe { F4(_mm_set1_ps(v)) }
        }
        #[inline(always)]
        #[cfg_attr(not(test), allow(dead_code))]
        pub fn from_array(a: [f32; 4]) -> F4 {
            unsafe { F4(_mm_loadu_ps(a.as_ptr())) }
        }
        #[inline(always)]
        pub fn load(a: &[f32; 4]) -> F4 {
            unsafe { F4(_mm_loadu_ps(a.as_ptr())) }
        }
        #[inline(always)]
        pub fn to_array(self) -> [f32; 4] {
            let mut out = [0.0; 4];
            unsafe { _mm_storeu_ps(out.as_mut_ptr(), self.0) };
            out
        }
        /// Lanes 0, 1 and 2, each spread over a whole vector without a trip through memory.
        #[inline(always)]
        pub fn spread3(self) -> [F4; 3] {
            unsafe {
                [
                    F4(_mm_shuffle_ps::<0x00>(self.0, self.0)),
                    F4(_mm_shuffle_ps::<0x55>(self.0, self.0)),
                    F4(_mm_shuffle_ps::<0xAA>(self.0, self.0)),
                ]
            }
        }
        /// The SSE register, for 256-bit code built on it.
        #[inline(always)]
        pub fn raw(self) -> __m128 {
            self.0
        }
        #[inline(always)]
        pub fn add(self, o: F4) -> F4 {
            unsafe { F4(_mm_add_ps(self.0, o.0)) }
        }
        #[inline(always)]
        pub fn sub(self, o: F4) -> F4 {
            unsafe { F4(_mm_sub_ps(self.0, o.0)) }
        }
        #[inline(always)]
        pub fn mul(self, o: F4) -> F4 {
            unsafe { F4(_mm_mul_ps(self.0, o.0)) }
        }
        #[inline(always)]
        pub fn div(self, o: F4) -> F4 {
            unsafe { F4(_mm_div_ps(self.0, o.0)) }
        }
        /// Lane-wise minimum; where a lane of `self` is NaN, the lane of `o`.
        #[inline(always)]
        pub fn min(self, o: F4) -> F4 {
            unsafe { F4(_mm_min_ps(self.0, o.0)) }
        }
        /// Lane-wise maximum; where a lane of `self` is NaN, the lane of `o`.
        #[inline(always)]
        pub fn max(self, o: F4) -> F4 {
            unsafe { F4(_mm_max_ps(self.0, o.0)) }
        }
        #[inline(always)]
        pub fn abs(self) -> F4 {
            unsafe { F4(_mm_andnot_ps(_mm_set1_ps(-0.0), self.0)) }
        }
        /// The magnitudes of `self` with the signs of `o`.
        #[inline(always)]
        pub fn copysign(self, o: F4) -> F4 {
            unsafe {
                let sign = _mm_set1_ps(-0.0);
                F4(_mm_or_ps(
                    _mm_andnot_ps(sign, self.0),
                    _mm_and_ps(sign, o.0),
                ))
            }
        }
        /// Bit i set where lane i of `self` ≤ lane i of `o`.
        #[inline(always)]
        pub fn le(self, o: F4) -> u32 {
            unsafe { _mm_movemask_ps(_mm_cmple_ps(self.0, o.0)) as u32 }
        }
        /// Bit i set where lane i of `self` < lane i of `o`.
        #[inline(always)]
        pub fn lt(self, o: F4) -> u32 {
            unsafe { _mm_movemask_ps(_mm_cmplt_ps(self.0, o.0)) as u32 }
        }
        /// Bit i set where lane i equals `o`'s.
        #[inline(always)]
        pub fn eq(self, o: F4) -> u32 {
            unsafe { _mm_movemask_ps(_mm_cmpeq_ps(self.0, o.0)) as u32 }
        }
    }
}

#[cfg(not(target_arch = "x86_64"))]
mod imp {
    #[derive(Clone, Copy, Debug)]
    pub struct F4([f32; 4]);

    fn mask(f: impl Fn(usize) -> bool) -> u32 {
        (0..4).fold(0, |m, i| m | (f(i) as u32) << i)
    }

    impl F4 {
        #[inline(always)]
        pub fn splat(v: f32) -> F4 {
            F4([v; 4])
        }
        #[inline(always)]
        pub fn from_array(a: [f32; 4]) -> F4 {
            F4(a)
        }
        #[inline(always)]
        pub fn load(a: &[f32; 4]) -> F4 {
            F4(*a)
        }
        #[inline(always)]
        pub fn to_array(self) -> [f32; 4] {
            self.0
        }
        #[inline(always)]
        pub fn spread3(self) -> [F4; 3] {
            [F4([self.0[0]; 4]), F4([self.0[1]; 4]), F4([self.0[2]; 4])]
        }
        #[inline(always)]
        pub fn add(self, o: F4) -> F4 {
            F4(std::array::from_fn(|i| self.0[i] + o.0[i]))
        }
        #[inline(always)]
        pub fn sub(self, o: F4) -> F4 {
            F4(std::array::from_fn(|i| self.0[i] - o.0[i]))
        }
        #[inline(always)]
        pub fn mul(self, o: F4) -> F4 {
            F4(std::array::from_fn(|i| self.0[i] * o.0[i]))
        }
        #[inline(always)]
        pub fn div(self, o: F4) -> F4 {
            F4(std::array::from_fn(|i| self.0[i] / o.0[i]))
        }
        /// Lane-wise minimum; where a lane of `self` is NaN, the lane of `o` (as SSE does).
        #[inline(always)]
        pub fn min(self, o: F4) -> F4 {
            F4(std::array::from_fn(|i| {
                if self.0[i] < o.0[i] {
                    self.0[i]
                } else {
                    o.0[i]
                }
            }))
        }
        /// Lane-wise maximum; where a lane of `self` is NaN, the lane of `o` (as SSE does).
        #[inline(always)]
        pub fn max(self, o: F4) -> F4 {
            F4(std::array::from_fn(|i| {
                if self.0[i] > o.0[i] {
                    self.0[i]
                } else {
                    o.0[i]
                }
            }))
        }
        #[inline(always)]
        pub fn abs(self) -> F4 {
            F4(self.0.map(f32::abs))
        }
        #[inline(always)]
        pub fn copysign(self, o: F4) -> F4 {
            F4(std::array::from_fn(|i| self.0[i].copysign(o.0[i])))
        }
        #[inline(always)]
        pub fn le(self, o: F4) -> u32 {
            mask(|i| self.0[i] <= o.0[i])
        }
        #[inline(always)]
        pub fn lt(self, o: F4) -> u32 {
            mask(|i| self.0[i] < o.0[i])
        }
        #[inline(always)]
        pub fn eq(self, o: F4) -> u32 {
            mask(|i| self.0[i] == o.0[i])
        }
    }
}

pub use imp::F4;

/// What the triangle test asks of its lanes; bit i of a mask is lane i. `Isa` is what
/// making a vector takes: nothing for SSE, proof of AVX for eight lanes.
pub trait Lanes: Copy {
    type Isa: Copy;
    type Array: Copy + std::ops::Index<usize, Output = f32>;
    fn splat(isa: Self::Isa, v: f32) -> Self;
    fn add(self, o: Self) -> Self;
    fn sub(self, o: Self) -> Self;
    fn mul(self, o: Self) -> Self;
    fn div(self, o: Self) -> Self;
    /// Lane-wise minimum; where a lane of `self` is NaN, the lane of `o`.
    fn min(self, o: Self) -> Self;
    /// Lane-wise maximum; where a lane of `self` is NaN, the lane of `o`.
    fn max(self, o: Self) -> Self;
    fn abs(self) -> Self;
    fn le(self, o: Self) -> u32;
    fn lt(self, o: Self) -> u32;
    fn eq(self, o: Self) -> u32;
    fn to_array(self) -> Self::Array;
}

impl Lanes for F4 {
    type Isa = ();
    type Array = [f32; 4];
    #[inline(always)]
    fn splat(_: (), v: f32) -> F4 {
        F4::splat(v)
    }
    #[inline(always)]
    fn add(self, o: F4) -> F4 {
        F4::add(self, o)
    }
    #[inline(always)]
    fn sub(self, o: F4) -> F4 {
        F4::sub(self, o)
    }
    #[inline(always)]
    fn mul(self, o: F4) -> F4 {
        F4::mul(self, o)
    }
    #[inline(always)]
    fn div(self, o: F4) -> F4 {
        F4::div(self, o)
    }
    #[inline(always)]
    fn min(self, o: F4) -> F4 {
        F4::min(self, o)
    }
    #[inline(always)]
    fn max(self, o: F4) -> F4 {
        F4::max(self, o)
    }
    #[inline(always)]
    fn abs(self) -> F4 {
        F4::abs(self)
    }
    #[inline(always)]
    fn le(self, o: F4) -> u32 {
        F4::le(self, o)
    }
    #[inline(always)]
    fn lt(self, o: F4) -> u32 {
        F4::lt(self, o)
    }
    #[inline(always)]
    fn eq(self, o: F4) -> u32 {
        F4::eq(self, o)
    }
    #[inline(always)]
    fn to_array(self) -> [f32; 4] {
        F4::to_array(self)
    }
}

#[cfg(target_arch = "x86_64")]
pub use avx::{Avx, F8};

/// AVX is an x86 extension: elsewhere there is no proof of it to be had.
#[cfg(not(target_arch = "x86_64"))]
#[derive(Clone, Copy, Debug)]
pub enum Avx {}

#[cfg(not(target_arch = "x86_64"))]
impl Avx {
    pub fn detect() -> Option<Avx> {
        None
    }
}

#[cfg(target_arch = "x86_64")]
mod avx {
    use super::Lanes;
    use std::arch::x86_64::*;

    /// Proof that the CPU has AVX: only [`Avx::detect`] makes one.
    #[derive(Clone, Copy, Debug)]
    pub struct Avx(());

    impl Avx {
        pub fn detect() -> Option<Avx> {
            std::is_x86_feature_detected!("avx").then_some(Avx(()))
        }
    }

    /// Eight f32 lanes in a 256-bit AVX register. Every way to make one takes an [`Avx`],
    /// so the instructions below only ever run where the CPU has them; they become single
    /// instructions in callers compiled with `#[target_feature(enable = "avx")]` (and calls,
    /// correct but slow, elsewhere).
    #[derive(Clone, Copy, Debug)]
    #[repr(transparent)]
    pub struct F8(__m256);

    // SAFETY (every `unsafe` block below): an `F8` or an `Avx` exists, so the CPU has AVX;
    // the loads read exactly the 16 bytes of a `[f32; 4]`.
    impl F8 {
        /// Lanes 0–3 from `lo`, 4–7 from `hi`.
        #[inline(always)]
        pub fn join(_: Avx, lo: &[f32; 4], hi: &[f32; 4]) -> F8 {
            unsafe { F8(_mm256_loadu2_m128(hi.as_ptr(), lo.as_ptr())) }
        }

        #[inline(always)]
        fn mask(v: __m256) -> u32 {
            unsafe { _mm256_movemask_ps(v) as u32 }
        }
    }

    impl Lanes for F8 {
        type Isa = Avx;
        type Array = [f32; 8];
        #[inline(always)]
        fn splat(_: Avx, v: f32) -> F8 {
            unsafe { F8(_mm256_set1_ps(v)) }
        }
        #[inline(always)]
        fn add(self, o: F8) -> F8 {
            unsafe { F8(_mm256_add_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn sub(self, o: F8) -> F8 {
            unsafe { F8(_mm256_sub_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn mul(self, o: F8) -> F8 {
            unsafe { F8(_mm256_mul_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn div(self, o: F8) -> F8 {
            unsafe { F8(_mm256_div_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn min(self, o: F8) -> F8 {
            unsafe { F8(_mm256_min_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn max(self, o: F8) -> F8 {
            unsafe { F8(_mm256_max_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn abs(self) -> F8 {
            unsafe { F8(_mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0)) }
        }
        #[inline(always)]
        fn le(self, o: F8) -> u32 {
            unsafe { F8::mask(_mm256_cmp_ps::<_CMP_LE_OQ>(self.0, o.0)) }
        }
        #[inline(always)]
        fn lt(self, o: F8) -> u32 {
            unsafe { F8::mask(_mm256_cmp_ps::<_CMP_LT_OQ>(self.0, o.0)) }
        }
        #[inline(always)]
        fn eq(self, o: F8) -> u32 {
            unsafe { F8::mask(_mm256_cmp_ps::<_CMP_EQ_OQ>(self.0, o.0)) }
        }
        #[inline(always)]
        fn to_array(self) -> [f32; 8] {
            let mut out = [0.0; 8];
            unsafe { _mm256_storeu_ps(out.as_mut_ptr(), self.0) };
            out
        }
    }
}

#[cfg(test)]
mod tests {
    use super::F4;

    #[test]
    fn lanes_and_masks() {
        let a = F4::from_array([1.0, -2.0, 3.0, f32::NAN]);
        let b = F4::splat(2.0);
        assert_eq!(a.add(b).to_array()[..3], [3.0, 0.0, 5.0]);
        assert_eq!(a.abs().to_array()[1], 2.0);
        let signed = b
            .copysign(F4::from_array([-1.0, 1.0, -0.0, 0.0]))
            .to_array();
        assert_eq!(
            signed.map(f32::to_bits),
            [-2.0f32, 2.0, -2.0, 2.0].map(f32::to_bits)
        );
        assert_eq!(a.le(b), 0b0011);
        assert_eq!(a.lt(F4::splat(1.0)), 0b0010);
        // NaN lanes take the second operand, which the slab test relies on.
        assert_eq!(a.min(b).to_array()[3], 2.0);
        assert_eq!(a.max(b).to_array()[3], 2.0);
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn eight_lanes_as_two_fours() {
        use super::{Avx, Lanes, F8};
        let Some(avx) = Avx::detect() else {
            return;
        };
        let lo = [1.0, -2.0, 3.0, f32::NAN];
        let hi = [-0.5, 2.0, 0.0, 7.0];
        let a = F8::join(avx, &lo, &hi);
        let b = F8::splat(avx, 2.0);
        let ones = F8::splat(avx, 1.0);
        let (a4, b4) = (F4::from_array(lo), F4::from_array(hi));
        let halves = |m: u32| (m & 0xF, m >> 4);
        assert_eq!(
            halves(a.le(b)),
            (a4.le(F4::splat(2.0)), b4.le(F4::splat(2.0)))
        );
        assert_eq!(a.lt(ones), 0b0010 | 0b0101 << 4);
        assert_eq!(a.eq(b), 0b0010 << 4);
        let sum = a.add(b).sub(ones).mul(b).div(b).to_array();
        assert_eq!(sum[..3], [2.0, -1.0, 4.0]);
        assert!(sum[3].is_nan());
        assert_eq!(sum[4..], [0.5, 3.0, 1.0, 8.0]);
        // NaN lanes take the second operand, as in four lanes.
        assert_eq!(a.min(b).to_array()[3], 2.0);
        assert_eq!(a.max(b).to_array()[3], 2.0);
        assert_eq!(a.abs().to_array()[1], 2.0);
        assert_eq!(a.min(b).to_array()[4..], [-0.5, 2.0, 0.0, 2.0]);
        assert_eq!(a.max(b).to_array()[4..], [2.0, 2.0, 2.0, 7.0]);
    }
}
