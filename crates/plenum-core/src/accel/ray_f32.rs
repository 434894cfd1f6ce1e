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
    /// The origin rounded up, for the distances to min planes, and down, for max planes:
    /// whichever of the two is the entry, it is never overestimated, and the exit never
    /// underestimated, whatever the direction's sign.
    origin_up: [F4; 3],
    origin_down: [F4; 3],
    inv_dir: [F4; 3],
}

/// Relative enlargement of exit distances: the subtraction, the multiplication and the
/// rounding of the reciprocal direction, with margin.
const FAR_SCALE: f32 = 1.0 + 2.0 * gamma_f32(5);

impl BoxRay {
    pub fn new(ray: &Ray) -> BoxRay {
        let axis = |a: usize| {
            // A zero component would make 0·∞ = NaN at a plane through the origin; a tiny
            // one gives the same answer without it.
            let d = ray.direction[a];
            let d = if d.abs() < 1e-30 {
                1e-30f64.copysign(d)
            } else {
                d
            };
            // One ulp either side brackets the f64 origin without comparing.
            let o = ray.origin[a] as f32;
            (
                F4::splat(o.next_up()),
                F4::splat(o.next_down()),
                F4::splat((1.0 / d) as f32),
            )
        };
        let (x, y, z) = (axis(0), axis(1), axis(2));
        BoxRay {
            origin_up: [x.0, y.0, z.0],
            origin_down: [x.1, y.1, z.1],
            inv_dir: [x.2, y.2, z.2],
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
}
