//! Floating-point error analysis (Higham 2002; pbrt-v4 §6.8).
//!
//! Every intersection routine reports the point it found together with a conservative
//! bound on its absolute error per axis. A secondary ray starts at that point pushed out
//! along the surface normal past the bound, so it can never re-intersect the surface it
//! leaves: no hand-tuned epsilon, and no acne at any scene scale.

use super::Vec3;

/// Unit roundoff of `f64`: half the machine epsilon.
pub const MACHINE_EPSILON: f64 = f64::EPSILON * 0.5;

/// Higham's γₙ = nε/(1−nε): bounds the relative error of n chained roundings.
pub const fn gamma(n: u32) -> f64 {
    let ne = n as f64 * MACHINE_EPSILON;
    ne / (1.0 - ne)
}

/// A ray origin moved from `p` (with per-axis absolute error `p_error`) along the normal `n`
/// far enough to lie outside the error box, on the side `w` points to.
pub fn offset_ray_origin(p: Vec3, p_error: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let d = n.abs().dot(p_error);
    let mut offset = n * d;
    if w.dot(n) < 0.0 {
        offset = -offset;
    }
    let po = p + offset;
    // Rounding the sum could land back inside the box: step one ulp further out.
    let away = |v: f64, o: f64| {
        if o > 0.0 {
            v.next_up()
        } else if o < 0.0 {
            v.next_down()
        } else {
            v
        }
    };
    Vec3::new(
        away(po.x, offset.x),
        away(po.y, offset.y),
        away(po.z, offset.z),
    )
}

/// Solves a·t² + b·t + c = 0, returning the roots in ascending order, without the
/// catastrophic cancellation of the schoolbook formula (Press et al., Numerical Recipes §5.6).
pub fn solve_quadratic(a: f64, b: f64, c: f64) -> Option<(f64, f64)> {
    if a == 0.0 {
        if b == 0.0 {
            return None;
        }
        let t = -c / b;
        return Some((t, t));
    }
    let discriminant = b * b - 4.0 * a * c;
    if discriminant < 0.0 {
        return None;
    }
    let q = -0.5 * (b + discriminant.sqrt().copysign(b));
    let (t0, t1) = if q == 0.0 {
        // b = 0 and c = 0: a double root at zero.
        (0.0, 0.0)
    } else {
        (q / a, c / q)
    };
    Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gamma_grows_with_n() {
        assert!(gamma(1) > MACHINE_EPSILON && gamma(2) > gamma(1));
    }

    #[test]
    fn quadratic_keeps_the_small_root_accurate() {
        // Roots 1e-9 and 1e9: the schoolbook formula loses the small one entirely.
        let (t0, t1) = solve_quadratic(1.0, -(1e9 + 1e-9), 1.0).unwrap();
        assert!((t0 - 1e-9).abs() < 1e-22, "{t0}");
        assert!((t1 - 1e9).abs() < 1e-6);
    }

    #[test]
    fn offset_origin_leaves_the_error_box() {
        let p = Vec3::new(1.0, 2.0, 3.0);
        let err = Vec3::splat(1e-6);
        let n = Vec3::new(0.0, 0.0, 1.0);
        let o = offset_ray_origin(p, err, n, n);
        assert!(o.z - p.z > 1e-6);
        let o = offset_ray_origin(p, err, n, -n);
        assert!(p.z - o.z > 1e-6);
    }
}
