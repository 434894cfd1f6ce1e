//! The watertight ray–triangle test of Woop, Benthin and Wald (JCGT 2013): in f64 for one
//! triangle, and the parts the block test computes in f32 lanes, with pbrt-v4's
//! conservative bound on the hit distance's error (§6.8.4).

use crate::accel::ray_f32::gamma_f32;
use crate::accel::simd::Lanes;
use crate::math::{gamma, Ray, Vec3};

/// The edge functions of the watertight test, of the sheared corners `a`, `b`, `c` (x, y):
/// for each edge, twice the signed area of the triangle it makes with the ray's axis.
#[inline(always)]
pub(super) fn edge_functions<V: Lanes>(a: [V; 3], b: [V; 3], c: [V; 3]) -> [V; 3] {
    [
        b[0].mul(c[1]).sub(b[1].mul(c[0])),
        c[0].mul(a[1]).sub(c[1].mul(a[0])),
        a[0].mul(b[1]).sub(a[1].mul(b[0])),
    ]
}

/// The largest magnitude of three, lane by lane.
#[inline(always)]
pub(super) fn max_abs<V: Lanes>(p: V, q: V, s: V) -> V {
    p.abs().max(q.abs()).max(s.abs())
}

/// The lanes whose hit distance is surely above pbrt-v4's conservative bound δt (§6.8.4),
/// found without its division. `extent` holds the largest |coordinate| of the sheared
/// corners on x, y and z (X, Y, Z), `t_scaled` the distance times the determinant.
///
/// With m = max(X, Y), the triangle's reach across the ray: the edge functions are at most
/// 2m², δe ≤ (2γ₂ + 4γ₅)m² + 4γ₅Zm, and δt·|det| = 3Z(2γ₃·max|e| + δe) ≤ γ₅Zm(21.6m + 12Z)
/// < 34γ₅·Z·m·max(m, Z); t·|det| = |t_scaled|. Against that, 48γ₅ leaves room for f32's
/// roundings. A bound in M³, M the largest coordinate of all, missed hits on a small
/// triangle far away (M ≈ t there, m ≪ t): 43 % of the bunny's camera-ray hits took the
/// division. This one leaves only hits near the origin, and slivers seen edge on.
#[inline(always)]
pub(super) fn clear_of_origin_cheaply<V: Lanes>(isa: V::Isa, extent: [V; 3], t_scaled: V) -> u32 {
    let [x, y, z] = extent;
    let across = x.max(y);
    let bound = V::splat(isa, 48.0 * gamma_f32(5))
        .mul(across.max(z))
        .mul(z)
        .mul(across);
    // With m and Z from 2⁻³⁰ up, no product above falls below f32's normal range, where its
    // rounding would no longer be relative; a bound that overflows is infinite and settles
    // nothing.
    const SMALLEST: f32 = 1.0 / (1u32 << 30) as f32;
    let normal = V::splat(isa, SMALLEST).le(across.min(z));
    bound.lt(t_scaled.abs()) & normal
}

/// The lanes whose distance `t` is above pbrt-v4's conservative bound δt (§6.8.4), in f32 as
/// pbrt computes it; `extent` as for [`clear_of_origin_cheaply`], `e` the edge functions.
#[inline(always)]
pub(super) fn beyond_error_bound<V: Lanes>(
    isa: V::Isa,
    extent: [V; 3],
    e: [V; 3],
    det: V,
    t: V,
) -> u32 {
    let splat = |v: f32| V::splat(isa, v);
    let [max_x, max_y, max_z] = extent;
    let delta_z = max_z.mul(splat(gamma_f32(3)));
    let delta_x = max_x.add(max_z).mul(splat(gamma_f32(5)));
    let delta_y = max_y.add(max_z).mul(splat(gamma_f32(5)));
    let delta_e = max_x
        .mul(max_y)
        .mul(splat(gamma_f32(2)))
        .add(delta_y.mul(max_x))
        .add(delta_x.mul(max_y))
        .mul(splat(2.0));
    let max_e = max_abs(e[0], e[1], e[2]);
    let delta_t = max_e
        .mul(max_z)
        .mul(splat(gamma_f32(3)))
        .add(delta_e.mul(max_z))
        .add(delta_z.mul(max_e))
        .mul(splat(3.0))
        .div(det.abs());
    delta_t.lt(t)
}

/// a·b − c·d with one rounding error's worth of accuracy (Kahan's algorithm with FMA).
pub(super) fn difference_of_products(a: f64, b: f64, c: f64, d: f64) -> f64 {
    let cd = c * d;
    let err = (-c).mul_add(d, cd);
    a.mul_add(b, -cd) + err
}

/// The watertight test. Returns (t, b1, b2) with the hit at b0·p0 + b1·p1 + b2·p2.
pub fn intersect_triangle(
    ray: &Ray,
    t_max: f64,
    [p0, p1, p2]: [Vec3; 3],
) -> Option<(f64, f64, f64)> {
    // Translate to the ray origin, permute so z is the direction's largest axis, then shear
    // so the ray runs along +z: the test becomes a 2-D edge-function test at the origin.
    let d = ray.direction;
    let kz = d.max_abs_axis();
    let kx = (kz + 1) % 3;
    let ky = (kx + 1) % 3;
    let permute = |v: Vec3| Vec3::new(v[kx], v[ky], v[kz]);
    let d = permute(d);
    let (mut a, mut b, mut c) = (
        permute(p0 - ray.origin),
        permute(p1 - ray.origin),
        permute(p2 - ray.origin),
    );
    let (sx, sy, sz) = (-d.x / d.z, -d.y / d.z, 1.0 / d.z);
    for p in [&mut a, &mut b, &mut c] {
        p.x += sx * p.z;
        p.y += sy * p.z;
    }
    let e0 = difference_of_products(b.x, c.y, b.y, c.x);
    let e1 = difference_of_products(c.x, a.y, c.y, a.x);
    let e2 = difference_of_products(a.x, b.y, a.y, b.x);
    if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
        return None;
    }
    let det = e0 + e1 + e2;
    if det == 0.0 {
        return None;
    }
    a.z *= sz;
    b.z *= sz;
    c.z *= sz;
    let t_scaled = e0 * a.z + e1 * b.z + e2 * c.z;
    if det < 0.0 && (t_scaled >= 0.0 || t_scaled < t_max * det) {
        return None;
    }
    if det > 0.0 && (t_scaled <= 0.0 || t_scaled > t_max * det) {
        return None;
    }
    let inv_det = 1.0 / det;
    let t = t_scaled * inv_det;
    // Is t conservatively greater than zero? (pbrt-v4 §6.8.4)
    let max_z = a.z.abs().max(b.z.abs()).max(c.z.abs());
    let max_x = a.x.abs().max(b.x.abs()).max(c.x.abs());
    let max_y = a.y.abs().max(b.y.abs()).max(c.y.abs());
    let delta_z = gamma(3) * max_z;
    let delta_x = gamma(5) * (max_x + max_z);
    let delta_y = gamma(5) * (max_y + max_z);
    let delta_e = 2.0 * (gamma(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
    let max_e = e0.abs().max(e1.abs()).max(e2.abs());
    let delta_t =
        3.0 * (gamma(3) * max_e * max_z + delta_e * max_z + delta_z * max_e) * inv_det.abs();
    if t <= delta_t {
        return None;
    }
    Some((t, e1 * inv_det, e2 * inv_det))
}
