//! Spheres, with the numerically robust quadratic of Haines et al., "Precision improvements
//! for ray/sphere intersection" (Ray Tracing Gems, ch. 7): the discriminant is computed from
//! the ray's perpendicular offset to the centre, which stays accurate for far or huge spheres.

use super::{nearest_root, HitRecord, Partial, SurfaceGeometry, UvMap};
use crate::math::{gamma, Bounds3, Ray, Vec3};
use std::f64::consts::{PI, TAU};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f64,
    /// Only the inside of the surface is visible (NFF's negative radius).
    pub inside_only: bool,
    /// What is kept of it, about `center` (none: all).
    pub partial: Option<Partial>,
    /// Whose (u, v) it reports.
    pub uv_map: UvMap,
}

impl Sphere {
    pub fn new(center: Vec3, radius: f64) -> Self {
        Sphere {
            center,
            radius,
            inside_only: false,
            partial: None,
            uv_map: UvMap::Plenum,
        }
    }

    /// The sphere reporting `map`'s (u, v).
    pub fn with_uv_map(self, uv_map: UvMap) -> Self {
        Sphere { uv_map, ..self }
    }

    /// pbrt-v4's φ_max and the polar angles θ (from +z) at the bottom and top cuts.
    fn z_up_extent(&self) -> (f64, f64, f64) {
        let p = self.partial.unwrap_or(Partial::WHOLE);
        let theta = |z: f64| (z / self.radius).clamp(-1.0, 1.0).acos();
        (p.phi_max.min(TAU), theta(p.z_min), theta(p.z_max))
    }

    /// The sphere cut to what `partial` keeps.
    pub fn with_partial(self, partial: Partial) -> Self {
        Sphere {
            partial: partial.cut(),
            ..self
        }
    }

    pub fn bounds(&self) -> Bounds3 {
        let r = self.radius;
        // A band between two heights is bounded by them.
        let (z0, z1) = self.partial.map_or((-r, r), |p| {
            (p.z_min.max(-r), p.z_max.min(r).max(p.z_min.max(-r)))
        });
        Bounds3::new(
            self.center + Vec3::new(-r, -r, z0),
            self.center + Vec3::new(r, r, z1),
        )
    }

    /// Both roots of |o + t·d − c|² = r², ascending, or `None` when the ray misses.
    pub fn roots(&self, ray: &Ray) -> Option<(f64, f64)> {
        let f = ray.origin - self.center;
        let d = ray.direction;
        let a = d.length_squared();
        let half_b = -f.dot(d);
        // Perpendicular from the centre to the ray's line: |l|² is exact where b² − ac is not.
        let l = f + d * (half_b / a);
        let r = self.radius;
        let discriminant = a * (r * r - l.length_squared());
        if discriminant < 0.0 {
            return None;
        }
        // c = |f|² − r², factored so that an origin near the surface keeps its digits.
        let f_len = f.length();
        let c = (f_len - r) * (f_len + r);
        let q = half_b + discriminant.sqrt().copysign(half_b);
        let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (c / q, q / a) };
        Some((t0.min(t1), t0.max(t1)))
    }

    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<HitRecord> {
        let roots = self.roots(ray);
        // Seen from inside, the surface is always the far root.
        let roots = if self.inside_only {
            roots.map(|(_, t1)| (t1, t1))
        } else {
            roots
        };
        let kept = |t: f64| {
            self.partial
                .is_none_or(|p| p.keeps(ray.at(t) - self.center))
        };
        let t = nearest_root(roots, t_max, kept)?;
        Some(HitRecord {
            t,
            u: 0.0,
            v: 0.0,
            part: 0,
        })
    }

    pub fn surface(&self, ray: &Ray, hit: &HitRecord, want_uv: bool) -> SurfaceGeometry {
        // Re-project onto the sphere: removes the error of t (pbrt-v4 §6.8.5).
        let offset = ray.at(hit.t) - self.center;
        let offset = offset * (self.radius / offset.length());
        let p = self.center + offset;
        let p_error = (offset.abs() + self.center.abs()) * gamma(8);
        let n = offset / self.radius;
        let uv = match (want_uv, self.uv_map) {
            (false, _) => [0.0, 0.0],
            // Poles on the y axis, the scene's up: u runs around it, v from the top (0) down.
            (true, UvMap::Plenum) => {
                let phi = n.x.atan2(n.z);
                let phi = if phi < 0.0 { phi + 2.0 * PI } else { phi };
                [phi / (2.0 * PI), n.y.clamp(-1.0, 1.0).acos() / PI]
            }
            // Poles on z: u around from +x toward +y, v up from the bottom cut to the top.
            (true, UvMap::Pbrt | UvMap::Mitsuba) => {
                let (phi_max, theta_min, theta_max) = self.z_up_extent();
                let phi = n.y.atan2(n.x);
                let phi = if phi < 0.0 { phi + 2.0 * PI } else { phi };
                let theta = n.z.clamp(-1.0, 1.0).acos();
                [phi / phi_max, (theta_min - theta) / (theta_min - theta_max)]
            }
        };
        SurfaceGeometry::flat(p, p_error, n, uv)
    }

    /// ∂p/∂u and ∂p/∂v at `p` on the sphere, for the map of `surface`: p = c + r·(sin θ sin φ,
    /// cos θ, sin θ cos φ) with φ = 2πu and θ = πv. Zero at the poles.
    pub fn uv_derivatives(&self, p: Vec3) -> [Vec3; 2] {
        let o = p - self.center;
        if self.uv_map != UvMap::Plenum {
            // p = c + (ρ cos φ, ρ sin φ, r cos θ), φ = φ_max·u, θ = θ₀ − (θ₀ − θ₁)·v.
            let (phi_max, theta_min, theta_max) = self.z_up_extent();
            let rho = (o.x * o.x + o.y * o.y).sqrt();
            let dpdu = Vec3::new(-o.y, o.x, 0.0) * phi_max;
            let dpdv = if rho > 0.0 {
                Vec3::new(-o.z * o.x / rho, -o.z * o.y / rho, rho) * (theta_min - theta_max)
            } else {
                Vec3::ZERO
            };
            return [dpdu, dpdv];
        }
        // ρ = r sin θ, the distance from the axis.
        let rho = (o.x * o.x + o.z * o.z).sqrt();
        let dpdu = Vec3::new(o.z, 0.0, -o.x) * (2.0 * PI);
        let dpdv = if rho > 0.0 {
            Vec3::new(o.y * o.x / rho, -rho, o.y * o.z / rho) * PI
        } else {
            Vec3::ZERO
        };
        [dpdu, dpdv]
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_util::assert_close;
    use super::super::Shape;
    use super::*;

    #[test]
    fn hit_distance_and_normal_match_closed_form() {
        let s = Sphere::new(Vec3::new(0.0, 0.0, 5.0), 2.0);
        let ray = Ray::new(Vec3::new(1.0, 0.0, 0.0), Vec3::Z);
        let hit = s.intersect(&ray, f64::INFINITY).unwrap();
        // z = 5 − √(4 − 1)
        assert!((hit.t - (5.0 - 3f64.sqrt())).abs() < 1e-12);
        let g = s.surface(&ray, &hit, true);
        assert_close(g.n, Vec3::new(0.5, 0.0, -(3f64.sqrt()) / 2.0), 1e-12);
    }

    #[test]
    fn a_cut_sphere_is_hit_where_it_is_kept_and_seen_inside_through_the_cut() {
        // The upper half (z ≥ 0) of a unit sphere at (0, 0, 0).
        let top = Sphere::new(Vec3::ZERO, 1.0).with_partial(Partial {
            z_min: 0.0,
            ..Partial::WHOLE
        });
        let up = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
        // The near root (z = −1) is cut away: the inside of the dome at z = 1.
        assert!((top.intersect(&up, 1e9).unwrap().t - 6.0).abs() < 1e-12);
        let down = Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
        assert!((top.intersect(&down, 1e9).unwrap().t - 4.0).abs() < 1e-12);
        let b = top.bounds();
        assert_eq!((b.min.z, b.max.z), (0.0, 1.0));
        assert!(!Shape::Sphere(top).is_closed());
        // A quarter turn (φ from +x toward +y up to 90°): at y = 0.5 the near side (φ = 150°)
        // is cut, the far (φ = 30°) kept.
        let quarter = Sphere::new(Vec3::ZERO, 1.0).with_partial(Partial {
            phi_max: std::f64::consts::FRAC_PI_2,
            ..Partial::WHOLE
        });
        let ray = Ray::new(Vec3::new(-5.0, 0.5, 0.0), Vec3::X);
        let want = 5.0 + 0.75f64.sqrt();
        assert!((quarter.intersect(&ray, 1e9).unwrap().t - want).abs() < 1e-12);
        let ray = Ray::new(Vec3::new(-5.0, -0.5, 0.0), Vec3::X);
        assert!(quarter.intersect(&ray, 1e9).is_none());
        // Nothing cut: no partial kept.
        assert_eq!(
            Sphere::new(Vec3::ZERO, 1.0)
                .with_partial(Partial::WHOLE)
                .partial,
            None
        );
    }

    #[test]
    fn ray_from_inside_hits_the_far_side() {
        let s = Sphere::new(Vec3::ZERO, 1.0);
        let hit = s
            .intersect(&Ray::new(Vec3::ZERO, Vec3::X), f64::INFINITY)
            .unwrap();
        assert!((hit.t - 1.0).abs() < 1e-15);
    }

    #[test]
    fn misses_and_respects_t_max() {
        let s = Sphere::new(Vec3::new(0.0, 0.0, 5.0), 1.0);
        assert!(s
            .intersect(&Ray::new(Vec3::new(2.0, 0.0, 0.0), Vec3::Z), 1e9)
            .is_none());
        assert!(s.intersect(&Ray::new(Vec3::ZERO, Vec3::Z), 3.0).is_none());
        assert!(s.intersect(&Ray::new(Vec3::ZERO, -Vec3::Z), 1e9).is_none());
    }

    #[test]
    fn inside_only_sphere_shows_its_far_side() {
        let mut s = Sphere::new(Vec3::new(0.0, 0.0, 5.0), 1.0);
        s.inside_only = true;
        let hit = s.intersect(&Ray::new(Vec3::ZERO, Vec3::Z), 1e9).unwrap();
        assert!((hit.t - 6.0).abs() < 1e-12);
    }

    #[test]
    fn huge_far_sphere_has_no_cancellation() {
        // A sphere of radius 1e6 seen from 1e7 away, grazing at 0.5 unit inside its rim:
        // the schoolbook discriminant b² − 4ac loses every digit here.
        let r = 1e6;
        let s = Sphere::new(Vec3::new(0.0, 0.0, 1e7), r);
        let x = r - 0.5;
        let ray = Ray::new(Vec3::new(x, 0.0, 0.0), Vec3::Z);
        let hit = s.intersect(&ray, f64::INFINITY).unwrap();
        let exact = 1e7 - (r * r - x * x).sqrt();
        assert!((hit.t - exact).abs() < 1e-6, "{} vs {exact}", hit.t);
        let g = s.surface(&ray, &hit, true);
        assert!(((g.p - s.center).length() - r).abs() < 1e-8);
    }
}
