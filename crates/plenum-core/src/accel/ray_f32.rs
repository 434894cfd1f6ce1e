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

/// A ray prepared for slab tests against four boxes at once.
pub struct BoxRay {
    /// Per axis, the plane (0–5: min x, y, z, max x, y, z) the ray enters and leaves by.
    near_plane: [usize; 3],
    far_plane: [usize; 3],
    /// The origin rounded so that entry distances are never overestimated and exit distances
    /// never underestimated.
    origin_near: [F4; 3],
    origin_far: [F4; 3],
    inv_dir: [F4; 3],
}

/// Relative enlargement of exit distances: the subtraction, the multiplication and the
/// rounding of the reciprocal direction, with margin.
const FAR_SCALE: f32 = 1.0 + 2.0 * gamma_f32(5);

impl BoxRay {
    pub fn new(ray: &Ray) -> BoxRay {
        let mut near_plane = [0; 3];
        let mut far_plane = [0; 3];
        let mut origin_near = [F4::splat(0.0); 3];
        let mut origin_far = [F4::splat(0.0); 3];
        let mut inv_dir = [F4::splat(0.0); 3];
        for a in 0..3 {
            let d = ray.direction[a];
            // A zero component would make 0·∞ = NaN at a plane through the origin; a tiny
            // one gives the same answer without it.
            let d = if d.abs() < 1e-30 {
                1e-30f64.copysign(d)
            } else {
                d
            };
            let inv = (1.0 / d) as f32;
            // One ulp either side brackets the f64 origin without comparing.
            let o = ray.origin[a] as f32;
            let (lo, hi) = (o.next_down(), o.next_up());
            if inv >= 0.0 {
                near_plane[a] = a;
                far_plane[a] = 3 + a;
                origin_near[a] = F4::splat(hi);
                origin_far[a] = F4::splat(lo);
            } else {
                near_plane[a] = 3 + a;
                far_plane[a] = a;
                origin_near[a] = F4::splat(lo);
                origin_far[a] = F4::splat(hi);
            }
            inv_dir[a] = F4::splat(inv);
        }
        BoxRay {
            near_plane,
            far_plane,
            origin_near,
            origin_far,
            inv_dir,
        }
    }

    /// Entry distances of four boxes and the mask of those the ray crosses in [0, far].
    #[inline(always)]
    pub fn test4(&self, planes: &[[f32; 4]; 6], far: F4) -> (F4, u32) {
        let slab = |a: usize| {
            let t0 = F4::load(&planes[self.near_plane[a]])
                .sub(self.origin_near[a])
                .mul(self.inv_dir[a]);
            let t1 = F4::load(&planes[self.far_plane[a]])
                .sub(self.origin_far[a])
                .mul(self.inv_dir[a]);
            (t0, t1)
        };
        let (x0, x1) = slab(0);
        let (y0, y1) = slab(1);
        let (z0, z1) = slab(2);
        let near = x0.max(y0).max(z0.max(F4::splat(0.0)));
        let exit = x1.min(y1).min(z1.min(far));
        (near, near.le(exit.mul(F4::splat(FAR_SCALE))))
    }
}
