//! Finite cones and truncated cones (frusta) about the z axis from z = 0 to z = height, with
//! radius going linearly from `radius0` to `radius1`, optionally closed by disk caps. The
//! scene places them with a transform.

use super::{nearest_root, HitRecord, Partial, SurfaceGeometry};
use crate::math::{gamma, solve_quadratic, Bounds3, Ray, Vec3};
use std::f64::consts::PI;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    pub radius0: f64,
    pub radius1: f64,
    pub height: f64,
    pub capped: bool,
    /// Only the inside of the side is visible (NFF's negative radii); for open cones.
    pub inside_only: bool,
    /// What is kept of it, about the axis (none: all): a sector of less than a full turn.
    pub partial: Option<Partial>,
}

const SIDE: u32 = 0;
const BOTTOM: u32 = 1;
const TOP: u32 = 2;

impl Cone {
    pub fn bounds(&self) -> Bounds3 {
        let r = self.radius0.max(self.radius1);
        Bounds3::new(Vec3::new(-r, -r, 0.0), Vec3::new(r, r, self.height))
    }

    /// dr/dz along the side.
    fn slope(&self) -> f64 {
        (self.radius1 - self.radius0) / self.height
    }

    fn radius_at(&self, z: f64) -> f64 {
        self.radius0 + self.slope() * z
    }

    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<HitRecord> {
        let (o, d) = (ray.origin, ray.direction);
        let k = self.slope();
        // x² + y² = (r₀ + k·z)² along o + t·d.
        let r_o = self.radius0 + k * o.z;
        let a = d.x * d.x + d.y * d.y - k * k * d.z * d.z;
        let b = 2.0 * (o.x * d.x + o.y * d.y - k * r_o * d.z);
        let c = o.x * o.x + o.y * o.y - r_o * r_o;
        let in_height = |t: f64| {
            let p = ray.at(t);
            let facing_in = || {
                // The outward normal ∝ (x, y, −k·r(z)) turned away from the ray: an inside hit.
                let n = Vec3::new(p.x, p.y, -k * self.radius_at(p.z));
                n.dot(d) > 0.0
            };
            (0.0..=self.height).contains(&p.z)
                && (!self.inside_only || facing_in())
                && self.partial.is_none_or(|c| c.keeps(p))
        };
        let mut best: Option<HitRecord> = nearest_root(solve_quadratic(a, b, c), t_max, in_height)
            .map(|t| HitRecord {
                t,
                u: 0.0,
                v: 0.0,
                part: SIDE,
            });
        if self.capped && d.z != 0.0 {
            for (part, z, r) in [
                (BOTTOM, 0.0, self.radius0),
                (TOP, self.height, self.radius1),
            ] {
                let t = (z - o.z) / d.z;
                let limit = best.map_or(t_max, |h| h.t);
                if t > 0.0 && t < limit {
                    let (x, y) = (o.x + t * d.x, o.y + t * d.y);
                    let kept = self.partial.is_none_or(|c| c.keeps(Vec3::new(x, y, z)));
                    if x * x + y * y <= r * r && kept {
                        best = Some(HitRecord {
                            t,
                            u: 0.0,
                            v: 0.0,
                            part,
                        });
                    }
                }
            }
        }
        best
    }

    pub fn surface(&self, ray: &Ray, hit: &HitRecord, want_uv: bool) -> SurfaceGeometry {
        let p = ray.at(hit.t);
        if hit.part == SIDE {
            // Re-project radially onto the side at this height.
            let z = p.z.clamp(0.0, self.height);
            let r = self.radius_at(z);
            let rho = (p.x * p.x + p.y * p.y).sqrt();
            let (x, y) = if rho > 0.0 {
                (p.x * r / rho, p.y * r / rho)
            } else {
                (p.x, p.y)
            };
            let p = Vec3::new(x, y, z);
            // ∇(x² + y² − (r₀ + k·z)²) ∝ (x, y, −k·r(z)). At an apex the gradient vanishes:
            // use the axis, pointing out of the tip.
            let n = Vec3::new(x, y, -self.slope() * r).normalized();
            let n = if n.length_squared() > 0.0 {
                n
            } else if self.slope() < 0.0 {
                Vec3::Z
            } else {
                -Vec3::Z
            };
            let u = if want_uv {
                let phi = y.atan2(x);
                (if phi < 0.0 { phi + 2.0 * PI } else { phi }) / (2.0 * PI)
            } else {
                0.0
            };
            let err = (p.abs() + Vec3::splat(r)) * gamma(8);
            SurfaceGeometry::flat(p, err, n, [u, z / self.height])
        } else {
            let (z, n) = if hit.part == BOTTOM {
                (0.0, -Vec3::Z)
            } else {
                (self.height, Vec3::Z)
            };
            let p = Vec3::new(p.x, p.y, z);
            let r = if hit.part == BOTTOM {
                self.radius0
            } else {
                self.radius1
            };
            let uv = [0.5 + p.x / (2.0 * r), 0.5 + p.y / (2.0 * r)];
            SurfaceGeometry::flat(p, p.abs() * gamma(4), n, uv)
        }
    }

    /// ∂p/∂u and ∂p/∂v at `p` (see `surface`): on the side, around (u = φ/2π) and up the
    /// slant (v = z/height); on a cap, along x and y across its diameter.
    pub fn uv_derivatives(&self, hit: &HitRecord, p: Vec3) -> [Vec3; 2] {
        if hit.part == SIDE {
            let r = self.radius_at(p.z);
            let k = if r > 0.0 { self.slope() / r } else { 0.0 };
            [
                Vec3::new(-p.y, p.x, 0.0) * (2.0 * PI),
                Vec3::new(k * p.x, k * p.y, 1.0) * self.height,
            ]
        } else {
            let r = if hit.part == BOTTOM {
                self.radius0
            } else {
                self.radius1
            };
            [Vec3::X * (2.0 * r), Vec3::Y * (2.0 * r)]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn side_hit_and_normal_of_a_cone() {
        // Radius 1 at z = 0 shrinking to 0 at z = 1: the side is at 45°.
        let cone = Cone {
            radius0: 1.0,
            radius1: 0.0,
            height: 1.0,
            capped: false,
            inside_only: false,
            partial: None,
        };
        let ray = Ray::new(Vec3::new(-5.0, 0.0, 0.5), Vec3::X);
        let hit = cone.intersect(&ray, 1e9).unwrap();
        assert!((hit.t - 4.5).abs() < 1e-12);
        let g = cone.surface(&ray, &hit, true);
        let s = 0.5f64.sqrt();
        assert!((g.n - Vec3::new(-s, 0.0, s)).length() < 1e-12, "{:?}", g.n);
    }

    #[test]
    fn apex_has_a_normal() {
        let cone = Cone {
            radius0: 1.0,
            radius1: 0.0,
            height: 1.0,
            capped: false,
            inside_only: false,
            partial: None,
        };
        let ray = Ray::new(Vec3::new(0.0, 0.0, 3.0), -Vec3::Z);
        let hit = cone.intersect(&ray, 1e9).unwrap();
        assert!((hit.t - 2.0).abs() < 1e-12);
        assert_eq!(cone.surface(&ray, &hit, true).n, Vec3::Z);
    }

    #[test]
    fn cap_hit_only_when_capped() {
        let mut cone = Cone {
            radius0: 1.0,
            radius1: 0.5,
            height: 2.0,
            capped: false,
            inside_only: false,
            partial: None,
        };
        let ray = Ray::new(Vec3::new(0.1, 0.0, 5.0), -Vec3::Z);
        // Open: the ray passes down the axis and leaves through the open bottom.
        assert!(cone.intersect(&ray, 1e9).is_none());
        cone.capped = true;
        let hit = cone.intersect(&ray, 1e9).unwrap();
        assert!((hit.t - 3.0).abs() < 1e-12);
        assert_eq!(cone.surface(&ray, &hit, true).n, Vec3::Z);
    }
}
