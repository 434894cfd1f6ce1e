//! A flat disk: the points of a plane within `radius` of `center`.

use super::{plane_distance, project_onto_plane, HitRecord, Partial, SurfaceGeometry, UvMap};
use crate::math::{Bounds3, Ray, Vec3};
use std::f64::consts::{PI, TAU};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disk {
    pub center: Vec3,
    /// Unit normal.
    pub normal: Vec3,
    pub radius: f64,
    tangent_s: Vec3,
    tangent_t: Vec3,
    /// What is kept of it, in the scene's axes about `center` (pbrt-v4's disks lie in the
    /// xy plane): a hole, a sector. None: all.
    pub partial: Option<Partial>,
    /// Whose (u, v) it reports (pbrt-v4's and Mitsuba's measure angles in the xy plane).
    pub uv_map: UvMap,
}

impl Disk {
    pub fn new(center: Vec3, normal: Vec3, radius: f64) -> Self {
        let normal = normal.normalized();
        let (tangent_s, tangent_t) = normal.orthonormal_basis();
        Disk {
            center,
            normal,
            radius,
            tangent_s,
            tangent_t,
            partial: None,
            uv_map: UvMap::Plenum,
        }
    }

    /// The disk reporting `map`'s (u, v).
    pub fn with_uv_map(self, uv_map: UvMap) -> Self {
        Disk { uv_map, ..self }
    }

    /// φ_max and the inner radius pbrt-v4 maps (u, v) over.
    fn extent(&self) -> (f64, f64) {
        let p = self.partial.unwrap_or(Partial::WHOLE);
        (p.phi_max.min(TAU), p.inner_radius.clamp(0.0, self.radius))
    }

    /// The disk cut to what `partial` keeps.
    pub fn with_partial(self, partial: Partial) -> Self {
        Disk {
            partial: partial.cut(),
            ..self
        }
    }

    pub fn bounds(&self) -> Bounds3 {
        // Extent along each axis of a circle with normal n: r·√(1 − n_axis²).
        let n = self.normal;
        let e = Vec3::new(
            (1.0 - n.x * n.x).max(0.0).sqrt(),
            (1.0 - n.y * n.y).max(0.0).sqrt(),
            (1.0 - n.z * n.z).max(0.0).sqrt(),
        ) * self.radius;
        Bounds3::new(self.center - e, self.center + e)
    }

    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<HitRecord> {
        let t = plane_distance(ray, self.normal, self.normal.dot(self.center), t_max)?;
        let d = ray.at(t) - self.center;
        let kept = d.length_squared() <= self.radius * self.radius
            && self.partial.is_none_or(|p| p.keeps(d));
        kept.then_some(HitRecord {
            t,
            u: 0.0,
            v: 0.0,
            part: 0,
        })
    }

    pub fn surface(&self, ray: &Ray, hit: &HitRecord, want_uv: bool) -> SurfaceGeometry {
        let (p, p_error) =
            project_onto_plane(ray, hit.t, self.normal, self.normal.dot(self.center));
        let d = p - self.center;
        let angle = |x: f64, y: f64| {
            let phi = y.atan2(x);
            if phi < 0.0 {
                phi + 2.0 * PI
            } else {
                phi
            }
        };
        let uv = match (want_uv, self.uv_map) {
            (false, _) => [0.0, 0.0],
            (true, UvMap::Plenum) => {
                let (x, y) = (d.dot(self.tangent_s), d.dot(self.tangent_t));
                [
                    angle(x, y) / (2.0 * PI),
                    (x * x + y * y).sqrt() / self.radius,
                ]
            }
            (true, UvMap::Pbrt) => {
                let (phi_max, inner) = self.extent();
                let rho = (d.x * d.x + d.y * d.y).sqrt();
                let v = match self.radius - inner {
                    w if w > 0.0 => (self.radius - rho) / w,
                    _ => 0.0,
                };
                [angle(d.x, d.y) / phi_max, v]
            }
            (true, UvMap::Mitsuba) => [
                (d.x * d.x + d.y * d.y).sqrt() / self.radius,
                1.0 - angle(d.x, d.y) / (2.0 * PI),
            ],
        };
        SurfaceGeometry::flat(p, p_error, self.normal, uv)
    }

    /// ∂p/∂u and ∂p/∂v at `p`, for u = φ/2π and v = ρ/R: around and outward. Zero ∂p/∂u
    /// at the centre.
    pub fn uv_derivatives(&self, p: Vec3) -> [Vec3; 2] {
        let d = p - self.center;
        if self.uv_map != UvMap::Plenum {
            let rho = (d.x * d.x + d.y * d.y).sqrt();
            let around = Vec3::new(-d.y, d.x, 0.0);
            let outward = if rho > 0.0 {
                Vec3::new(d.x, d.y, 0.0) / rho
            } else {
                Vec3::X
            };
            return match self.uv_map {
                UvMap::Mitsuba => [outward * self.radius, around * (-2.0 * PI)],
                _ => {
                    let (phi_max, inner) = self.extent();
                    [around * phi_max, outward * -(self.radius - inner)]
                }
            };
        }
        let (x, y) = (d.dot(self.tangent_s), d.dot(self.tangent_t));
        let rho = (x * x + y * y).sqrt();
        let around = (self.tangent_t * x - self.tangent_s * y) * (2.0 * PI);
        let outward = if rho > 0.0 {
            (self.tangent_s * x + self.tangent_t * y) * (self.radius / rho)
        } else {
            self.tangent_s * self.radius
        };
        [around, outward]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ring_and_a_sector_keep_what_they_say() {
        let ring = Disk::new(Vec3::ZERO, Vec3::Z, 1.0).with_partial(Partial {
            inner_radius: 0.5,
            ..Partial::WHOLE
        });
        let at = |x: f64, y: f64| Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z);
        assert!(ring.intersect(&at(0.3, 0.3), 9.0).is_none());
        assert!(ring.intersect(&at(0.5, 0.5), 9.0).is_some());
        let half = Disk::new(Vec3::ZERO, -Vec3::Z, 1.0).with_partial(Partial {
            phi_max: PI,
            ..Partial::WHOLE
        });
        assert!(half.intersect(&at(0.1, 0.5), 9.0).is_some());
        assert!(half.intersect(&at(0.1, -0.5), 9.0).is_none());
    }

    #[test]
    fn hits_inside_radius_only() {
        let disk = Disk::new(Vec3::new(0.0, 0.0, 2.0), -Vec3::Z, 1.0);
        let hit = disk
            .intersect(&Ray::new(Vec3::new(0.5, 0.5, 0.0), Vec3::Z), 1e9)
            .unwrap();
        assert!((hit.t - 2.0).abs() < 1e-15);
        assert!(disk
            .intersect(&Ray::new(Vec3::new(0.8, 0.8, 0.0), Vec3::Z), 1e9)
            .is_none());
        let b = disk.bounds();
        assert!((b.max.x - 1.0).abs() < 1e-15 && (b.max.z - 2.0).abs() < 1e-15);
    }
}
