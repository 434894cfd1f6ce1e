//! The f32 form of a ray for box tests, made conservative: boxes are rounded outward, the
//! origin is rounded toward each plane's worst case, and the far distance is enlarged by
//! the relative error of the slab arithmetic (pbrt-v4 §6.8.2).

use super::simd::F4;
use crate::math::Ray;

/// Unit roundoff of f32.
const EPSILON_F32: f32 = f32::EPSILON * 0.5;

/// γₙ for f32 (see [`crate::math::gamma`]).
pub const fn gamma_f32(n: u32) -> f32 {
    let ne = n as f32 * EPSILON_F32;
    ne / (1.0 - ne)
}

/// The largest f32 not above `x`.
pub fn round_down(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x {
        f.next_down()
    } else {
        f
    }
}

/// The smallest f32 not below `x`.
pub fn round_up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x {
        f.next_up()
    } else {
        f
    }
}

/// A ray prepared for slab tests against four or eight boxes at once.
pub struct BoxRay {
    /// The origin rounded up, for the distances to min planes, and down, for max planes:
    /// whichever of the two is the entry, it is never overestimated, and the exit never
    /// underestimated, whatever the direction's sign.
    origin_up: [F4; 3],
    origin_down: [F4; 3],
    inv_dir: [F4; 3],
}

/// Relative enlargement of exit distances: the subtraction, the multiplication and the two
/// roundings of the reciprocal direction, with margin.
const FAR_SCALE: f32 = 1.0 + 2.0 * gamma_f32(5);

impl BoxRay {
    /// Per ray, so kept to one vector division and no branches.
    #[inline]
    pub fn new(ray: &Ray) -> BoxRay {
        let (o, d) = (ray.origin, ray.direction);
        // A zero component would make 0·∞ = NaN at a plane through the origin; a tiny one
        // gives the same answer without it.
        let away = |x: f64| x.abs().max(1e-30).copysign(x) as f32;
        let inv = F4::splat(1.0).div(F4::from_array([away(d.x), away(d.y), away(d.z), 1.0]));
        // The f32 origin moved by at least one ulp either way brackets the f64 one.
        let o = F4::from_array([o.x as f32, o.y as f32, o.z as f32, 0.0]);
        let ulp = o
            .abs()
            .mul(F4::splat(f32::EPSILON))
            .add(F4::splat(f32::MIN_POSITIVE));
        // Lanes spread in registers: a store and narrower reloads would stall forwarding.
        let xyz = F4::spread3;
        BoxRay {
            origin_up: xyz(o.add(ulp)),
            origin_down: xyz(o.sub(ulp)),
            inv_dir: xyz(inv),
        }
    }

    /// Entry distances of four boxes and the mask of those the ray crosses in [0, far].
    #[inline(always)]
    pub fn test4(&self, planes: &[[f32; 4]; 6], far: F4) -> (F4, u32) {
        let slab = |a: usize| {
            let t0 = F4::load(&planes[a])
                .sub(self.origin_up[a])
                .mul(self.inv_dir[a]);
            let t1 = F4::load(&planes[3 + a])
                .sub(self.origin_down[a])
                .mul(self.inv_dir[a]);
            (t0.min(t1), t0.max(t1))
        };
        let (x0, x1) = slab(0);
        let (y0, y1) = slab(1);
        let (z0, z1) = slab(2);
        let near = x0.max(y0).max(z0.max(F4::splat(0.0)));
        let exit = x1.min(y1).min(z1.min(far));
        (near, near.le(exit.mul(F4::splat(FAR_SCALE))))
    }

    /// Entry distances of eight boxes and the mask of those the ray crosses in [0, far], as
    /// two four-box tests (any x86-64, or no SIMD at all).
    #[inline(always)]
    pub fn test8(&self, planes: &[[f32; 8]; 6], far: F4) -> ([f32; 8], u32) {
        let half = |k: usize| {
            let p = [0, 1, 2, 3, 4, 5].map(|a| {
                let mut q = [0.0f32; 4];
                q.copy_from_slice(&planes[a][4 * k..4 * k + 4]);
                q
            });
            self.test4(&p, far)
        };
        let (n0, m0) = half(0);
        let (n1, m1) = half(1);
        let mut out = [0.0f32; 8];
        out[..4].copy_from_slice(&n0.to_array());
        out[4..].copy_from_slice(&n1.to_array());
        (out, m0 | (m1 << 4))
    }

    /// The ray's numbers in 256-bit vectors, for [`BoxRayAvx::test8`].
    ///
    /// # Safety
    /// The CPU must support AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    #[inline]
    pub unsafe fn avx(&self) -> BoxRayAvx {
        use std::arch::x86_64::_mm256_set_m128;
        let wide = |v: &[F4; 3]| v.map(|x| _mm256_set_m128(x.raw(), x.raw()));
        BoxRayAvx {
            origin_up: wide(&self.origin_up),
            origin_down: wide(&self.origin_down),
            inv_dir: wide(&self.inv_dir),
        }
    }
}

/// A [`BoxRay`] in AVX registers: eight boxes per test.
#[cfg(target_arch = "x86_64")]
pub struct BoxRayAvx {
    origin_up: [std::arch::x86_64::__m256; 3],
    origin_down: [std::arch::x86_64::__m256; 3],
    inv_dir: [std::arch::x86_64::__m256; 3],
}

#[cfg(target_arch = "x86_64")]
impl BoxRayAvx {
    /// [`BoxRay::test8`] in one pass of 256-bit vectors, the same arithmetic lane for lane.
    ///
    /// # Safety
    /// The CPU must support AVX.
    #[target_feature(enable = "avx")]
    #[inline]
    pub unsafe fn test8(&self, planes: &[[f32; 8]; 6], far: f32) -> ([f32; 8], u32) {
        use std::arch::x86_64::*;
        let slab = |a: usize| {
            // SAFETY: each load reads the 32 bytes of one [f32; 8].
            let (lo, hi) = unsafe {
                (
                    _mm256_loadu_ps(planes[a].as_ptr()),
                    _mm256_loadu_ps(planes[3 + a].as_ptr()),
                )
            };
            let t0 = _mm256_mul_ps(_mm256_sub_ps(lo, self.origin_up[a]), self.inv_dir[a]);
            let t1 = _mm256_mul_ps(_mm256_sub_ps(hi, self.origin_down[a]), self.inv_dir[a]);
            (_mm256_min_ps(t0, t1), _mm256_max_ps(t0, t1))
        };
        let (x0, x1) = slab(0);
        let (y0, y1) = slab(1);
        let (z0, z1) = slab(2);
        let near = _mm256_max_ps(
            _mm256_max_ps(x0, y0),
            _mm256_max_ps(z0, _mm256_setzero_ps()),
        );
        let exit = _mm256_min_ps(
            _mm256_min_ps(x1, y1),
            _mm256_min_ps(z1, _mm256_set1_ps(far)),
        );
        let exit = _mm256_mul_ps(exit, _mm256_set1_ps(FAR_SCALE));
        let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, exit)) as u32;
        let mut out = [0.0f32; 8];
        // SAFETY: stores the 32 bytes of `out`.
        unsafe { _mm256_storeu_ps(out.as_mut_ptr(), near) };
        (out, mask)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;
    use crate::sampling::Rng;

    /// The AVX node test gives the same distances and masks, bit for bit, as the portable
    /// one, on random rays (some axis-parallel) against random boxes (some empty, some
    /// behind the ray), seed 8.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx_node_test_matches_the_portable_one() {
        if !std::is_x86_feature_detected!("avx") {
            return;
        }
        let mut rng = Rng::new(8, 0);
        let mut v = || rng.uniform() * 4.0 - 2.0;
        for trial in 0..20_000 {
            let mut d = Vec3::new(v(), v(), v());
            if trial % 5 == 0 {
                d.x = 0.0;
            }
            let ray = Ray::new(Vec3::new(v(), v(), v()), d);
            let mut planes = [[0.0f32; 8]; 6];
            for lane in 0..8 {
                for a in 0..3 {
                    let (p, q) = (v() as f32, v() as f32);
                    // Every fourth box inside out: empty.
                    let (lo, hi) = if lane % 4 == 3 {
                        (p.max(q), p.min(q))
                    } else {
                        (p.min(q), p.max(q))
                    };
                    planes[a][lane] = lo;
                    planes[3 + a][lane] = hi;
                }
            }
            let far = if trial % 3 == 0 {
                f32::INFINITY
            } else {
                (v() + 2.0) as f32
            };
            let r = BoxRay::new(&ray);
            let portable = r.test8(&planes, F4::splat(far));
            // SAFETY: AVX was detected above.
            let avx = unsafe { r.avx().test8(&planes, far) };
            assert_eq!(portable.1, avx.1, "mask, trial {trial}");
            for lane in 0..8 {
                if portable.1 >> lane & 1 == 1 {
                    assert_eq!(
                        portable.0[lane].to_bits(),
                        avx.0[lane].to_bits(),
                        "trial {trial}"
                    );
                }
            }
        }
    }
}
