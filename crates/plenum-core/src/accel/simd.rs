//! Four f32 lanes: SSE on x86-64 (part of the baseline, so no run-time detection), plain arrays
//! elsewhere. Only what the node and triangle tests need.

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
}
