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

/// [`round_up`] for a distance, never negative (nor NaN): stepping up is then adding one to
/// the bits, without the cases of a negative, infinite or NaN `x`. Infinity stays infinite.
#[inline(always)]
pub fn round_up_distance(x: f64) -> f32 {
    debug_assert!(x >= 0.0);
    let f = x as f32;
    f32::from_bits(f.to_bits() + u32::from((f as f64) < x))
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

/// The ray's numbers for the box tests, in lanes x, y, z: the reciprocal direction and the f32
/// origin rounded up and down. Per ray, so kept to one vector division and no branches.
#[inline(always)]
fn prepare(ray: &Ray) -> (F4, F4, F4) {
    let (o, d) = (ray.origin, ray.direction);
    let d = F4::from_array([d.x as f32, d.y as f32, d.z as f32, 1.0]);
    // A zero component would make 0·∞ = NaN at a plane through the origin; a tiny one
    // gives the same answer without it.
    let away = d.abs().max(F4::splat(1e-30)).copysign(d);
    let inv = F4::splat(1.0).div(away);
    // The f32 origin moved by two ulps either way brackets the f64 one, and its product
    // with 1/d, rounded, still brackets o·(1/d) (see `BoxRayAvx::new`). The absolute part
    // of the move keeps that product a normal number where a coordinate is 0 (a ray leaving
    // a floor at y = 0 toward a light, its direction longer than 1): a subnormal there made
    // every box test of the ray take the CPU's slow path (Whitted's scene, 35 % of its time).
    // Its effect on a distance, 2⁻¹²⁵ or less, is nil.
    let o = F4::from_array([o.x as f32, o.y as f32, o.z as f32, 0.0]);
    let ulp = o.abs().mul(F4::splat(2.0 * f32::EPSILON)).add(
        d.abs()
            .max(F4::splat(1.0))
            .mul(F4::splat(2.0 * f32::MIN_POSITIVE)),
    );
    (inv, o.add(ulp), o.sub(ulp))
}

impl BoxRay {
    #[inline]
    pub fn new(ray: &Ray) -> BoxRay {
        let (inv, up, down) = prepare(ray);
        // Lanes spread in registers: a store and narrower reloads would stall forwarding.
        let xyz = F4::spread3;
        BoxRay {
            origin_up: xyz(up),
            origin_down: xyz(down),
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
}

/// For each set of axes the ray runs down (bit a for axis a), the byte offsets within a
/// node's planes of the plane it enters each slab through and of the one it leaves through:
/// the min plane (row a) and then the max plane (row 3 + a) when it runs up the axis, the
/// other way round when it runs down.
#[cfg(target_arch = "x86_64")]
const PLANE_OFFSETS: [[[usize; 3]; 2]; 8] = {
    let row = std::mem::size_of::<[f32; 8]>();
    let mut table = [[[0; 3]; 2]; 8];
    let mut signs = 0;
    while signs < 8 {
        let mut a = 0;
        while a < 3 {
            let down = (signs >> a) & 1;
            table[signs][0][a] = (a + 3 * down) * row;
            table[signs][1][a] = (a + 3 * (1 - down)) * row;
            a += 1;
        }
        signs += 1;
    }
    table
};

/// A [`BoxRay`] in AVX registers: eight boxes per test, each slab distance one fused
/// multiply-subtract from the plane the ray enters or leaves through.
#[cfg(target_arch = "x86_64")]
pub struct BoxRayAvx {
    inv_dir: [std::arch::x86_64::__m256; 3],
    /// Byte offsets, within a node's planes, of the plane the ray enters each slab through
    /// and of the one it leaves through.
    entry_offset: [usize; 3],
    exit_offset: [usize; 3],
    /// Bounds on origin·(1/direction) from above and below.
    entry_shift: [std::arch::x86_64::__m256; 3],
    exit_shift: [std::arch::x86_64::__m256; 3],
}

#[cfg(target_arch = "x86_64")]
impl BoxRayAvx {
    /// Made straight from the ray, each number computed once in four lanes and then spread:
    /// per ray, so it matters.
    ///
    /// # Safety
    /// The CPU must support AVX.
    #[target_feature(enable = "avx")]
    #[inline]
    pub unsafe fn new(ray: &Ray) -> BoxRayAvx {
        use std::arch::x86_64::*;
        let (inv, up, down) = prepare(ray);
        // o·(1/d) for each bracketing origin: the larger one never overestimates an entry
        // distance, the smaller one never underestimates an exit, whatever the sign.
        let (up, down) = (up.mul(inv), down.mul(inv));
        let spread = |v: F4| {
            let v = v.raw();
            let lanes = [
                _mm_permute_ps::<0x00>(v),
                _mm_permute_ps::<0x55>(v),
                _mm_permute_ps::<0xAA>(v),
            ];
            lanes.map(|l| _mm256_set_m128(l, l))
        };
        // Looked up by the signs, where working them out takes six selects.
        let [entry_offset, exit_offset] = PLANE_OFFSETS[inv.lt(F4::splat(0.0)) as usize & 7];
        BoxRayAvx {
            inv_dir: spread(inv),
            entry_offset,
            exit_offset,
            entry_shift: spread(up.max(down)),
            exit_shift: spread(up.min(down)),
        }
    }

    /// Entry distances of eight boxes and the mask of those the ray crosses in [0, far].
    /// Like [`BoxRay::test8`] but for rounding: one rounding per distance instead of two.
    ///
    /// # Safety
    /// The CPU must support AVX and FMA.
    #[target_feature(enable = "avx,fma")]
    #[inline]
    pub unsafe fn test8(&self, planes: &[[f32; 8]; 6], far: f32) -> ([f32; 8], u32) {
        use std::arch::x86_64::*;
        let base = planes.as_ptr() as *const u8;
        let slab = |offset: usize, a: usize, shift: &[__m256; 3]| {
            // SAFETY: offsets name one of the six [f32; 8] rows.
            let plane = unsafe { _mm256_loadu_ps(base.add(offset) as *const f32) };
            _mm256_fmsub_ps(plane, self.inv_dir[a], shift[a])
        };
        let entry = |a: usize| slab(self.entry_offset[a], a, &self.entry_shift);
        let exit = |a: usize| slab(self.exit_offset[a], a, &self.exit_shift);
        let near = _mm256_max_ps(
            _mm256_max_ps(entry(0), entry(1)),
            _mm256_max_ps(entry(2), _mm256_setzero_ps()),
        );
        let leave = _mm256_min_ps(
            _mm256_min_ps(exit(0), exit(1)),
            _mm256_min_ps(exit(2), _mm256_set1_ps(far)),
        );
        let leave = _mm256_mul_ps(leave, _mm256_set1_ps(FAR_SCALE));
        let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, leave)) as u32;
        let mut out = [0.0f32; 8];
        // SAFETY: stores the 32 bytes of `out`.
        unsafe { _mm256_storeu_ps(out.as_mut_ptr(), near) };
        (out, mask)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn distances_round_up_as_any_number_does() {
        use super::{round_up, round_up_distance};
        let third = 1.0 / 3.0;
        for x in [
            0.0,
            1e-300,
            third,
            1.0,
            1e30,
            f32::MAX as f64,
            3.5e38,
            1e300,
            f64::INFINITY,
        ] {
            assert_eq!(round_up_distance(x).to_bits(), round_up(x).to_bits(), "{x}");
        }
    }

    use super::*;
    use crate::math::Vec3;
    use crate::sampling::Rng;

    /// The exact interval of a ray in a box, in f64: where it crosses [0, far], or None.
    fn exact_crossing(ray: &Ray, lo: [f32; 3], hi: [f32; 3], far: f64) -> Option<f64> {
        let (mut enter, mut leave) = (0.0f64, far);
        for a in 0..3 {
            let (o, d) = (ray.origin[a], ray.direction[a]);
            let (l, h) = (lo[a] as f64, hi[a] as f64);
            if d == 0.0 {
                if o < l || o > h {
                    return None;
                }
                continue;
            }
            let (t0, t1) = ((l - o) / d, (h - o) / d);
            enter = enter.max(t0.min(t1));
            leave = leave.min(t0.max(t1));
        }
        (enter <= leave).then_some(enter)
    }

    /// Both node tests, portable and AVX, against the exact f64 slab test on random rays
    /// (some axis-parallel, some starting on a plane) and boxes (some flat, some behind the
    /// ray), seed 8: no box the ray crosses is missed, no entry distance overestimated by
    /// more than 1e-6 relative, and no box missed by more than 1e-5 relative reported.
    #[test]
    #[allow(clippy::needless_range_loop)] // a lane indexes an entry and an exit row at once
    fn node_tests_bracket_the_exact_slab_test() {
        let mut rng = Rng::new(8, 0);
        let mut v = || rng.uniform() * 4.0 - 2.0;
        for trial in 0..20_000 {
            let mut d = Vec3::new(v(), v(), v());
            if trial % 5 == 0 {
                d.x = 0.0;
            }
            let mut planes = [[0.0f32; 8]; 6];
            for lane in 0..8 {
                for a in 0..3 {
                    let (p, q) = (v() as f32, v() as f32);
                    planes[a][lane] = p.min(q);
                    // Every fourth box flat in x.
                    planes[3 + a][lane] = if lane % 4 == 3 && a == 0 {
                        p.min(q)
                    } else {
                        p.max(q)
                    };
                }
            }
            let mut o = Vec3::new(v(), v(), v());
            if trial % 7 == 0 {
                o.y = planes[1][trial % 8] as f64;
            }
            let ray = Ray::new(o, d);
            let far = if trial % 3 == 0 {
                f32::INFINITY
            } else {
                (v() + 2.0) as f32
            };
            let r = BoxRay::new(&ray);
            let mut results = vec![r.test8(&planes, F4::splat(far))];
            #[cfg(target_arch = "x86_64")]
            if std::is_x86_feature_detected!("avx") && std::is_x86_feature_detected!("fma") {
                // SAFETY: AVX and FMA were detected.
                results.push(unsafe { BoxRayAvx::new(&ray).test8(&planes, far) });
            }
            for (near, mask) in results {
                for lane in 0..8 {
                    let lo = [0, 1, 2].map(|a| planes[a][lane]);
                    let hi = [3, 4, 5].map(|a| planes[a][lane]);
                    let hit = mask >> lane & 1 == 1;
                    match exact_crossing(&ray, lo, hi, far as f64) {
                        Some(enter) => {
                            assert!(hit, "trial {trial} lane {lane}: missed");
                            let n = near[lane] as f64;
                            assert!(n <= enter * (1.0 + 1e-6), "trial {trial}: {n} > {enter}");
                        }
                        None if hit => {
                            let grown = [0, 1, 2].map(|a| {
                                let pad = 1e-5 * (1.0 + lo[a].abs().max(hi[a].abs()));
                                (lo[a] - pad, hi[a] + pad)
                            });
                            let lo = grown.map(|g| g.0);
                            let hi = grown.map(|g| g.1);
                            assert!(
                                exact_crossing(&ray, lo, hi, far as f64 * (1.0 + 1e-5)).is_some(),
                                "trial {trial} lane {lane}: reported a box the ray misses"
                            );
                        }
                        None => {}
                    }
                }
            }
        }
    }

    /// A ray from a point with zero coordinates, its direction shorter or longer than 1 (a
    /// shadow ray from a floor at y = 0 to a light): the numbers every box test computes
    /// with stay normal or zero, since a subnormal one sends each test down the CPU's slow
    /// path. Checked on the products that decide a plane through the origin, portable and
    /// AVX.
    #[test]
    fn box_tests_of_rays_from_zero_coordinates_meet_no_subnormal() {
        let normal_or_zero = |x: f32| x == 0.0 || x.is_normal();
        for length in [1e-3, 0.1, 1.0, 6.0, 1e4, 1e8] {
            for o in [Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.5, 0.0, -2.0)] {
                let d = Vec3::new(-3.0, 6.0, 5.0).normalized() * length;
                let ray = Ray::new(o, d);
                let r = BoxRay::new(&ray);
                for a in 0..3 {
                    for origin in [r.origin_up[a], r.origin_down[a]] {
                        // A plane at 0, as the floor's flat box has.
                        let t = F4::splat(0.0).sub(origin).mul(r.inv_dir[a]).to_array();
                        assert!(t.into_iter().all(normal_or_zero), "{length} {o:?}: {t:?}");
                    }
                }
                #[cfg(target_arch = "x86_64")]
                if std::is_x86_feature_detected!("avx") {
                    // SAFETY: AVX was detected.
                    let w = unsafe { BoxRayAvx::new(&ray) };
                    for shift in w.entry_shift.iter().chain(&w.exit_shift) {
                        // SAFETY: __m256 and [f32; 8] have the same size.
                        let lanes: [f32; 8] = unsafe { std::mem::transmute(*shift) };
                        assert!(lanes.into_iter().all(normal_or_zero), "{length}: {lanes:?}");
                    }
                }
            }
        }
    }
}
