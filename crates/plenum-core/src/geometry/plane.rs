//! The infinite plane n·p = n·point.

use super::{plane_distance, project_onto_plane, HitRecord, SurfaceGeometry};
use crate::math::{Ray, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    pub point: Vec3,
    /// Unit normal.
    pub normal: Vec3,
    /// Tangent axes giving texture coordinates: uv = ((p − point)·s, (p − point)·t).
    tangent_s: Vec3,
    tangent_t: Vec3,
}

impl Plane {
    /// `normal` need not be unit length but must not be zero.
    pub fn new(point: Vec3, normal: Vec3) -> Self {
        let normal = normal.normalized();
        let (tangent_s, tangent_t) = normal.orthonormal_basis();
        Plane {
            point,
            normal,
            tangent_s,
            tangent_t,
        }
    }

    fn dist(&self) -> f64 {
        self.normal.dot(self.point)
    }

    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<HitRecord> {
        let t = plane_distance(ray, self.normal, self.dist(), t_max)?;
        Some(HitRecord {
            t,
            u: 0.0,
            v: 0.0,
            part: 0,
        })
    }

    pub fn surface(&self, ray: &Ray, hit: &HitRecord) -> SurfaceGeometry {
        let (p, p_error) = project_onto_plane(ray, hit.t, self.normal, self.dist());
        let d = p - self.point;
        let uv = [d.dot(self.tangent_s), d.dot(self.tangent_t)];
        SurfaceGeometry::flat(p, p_error, self.normal, uv)
    }

    /// The unit axes of (u, v).
    pub fn uv_derivatives(&self) -> [Vec3; 2] {
        [self.tangent_s, self.tangent_t]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hit_at_closed_form_distance() {
        let plane = Plane::new(Vec3::new(0.0, -1.0, 0.0), Vec3::Y);
        let ray = Ray::new(Vec3::ZERO, Vec3::new(0.0, -1.0, 1.0));
        let hit = plane.intersect(&ray, f64::INFINITY).unwrap();
        assert!((hit.t - 1.0).abs() < 1e-15);
        let g = plane.surface(&ray, &hit);
        assert_eq!(g.n, Vec3::Y);
        assert!((g.p - Vec3::new(0.0, -1.0, 1.0)).length() < 1e-15);
        assert!(plane
            .intersect(&Ray::new(Vec3::ZERO, Vec3::X), 1e9)
            .is_none());
        assert!(plane
            .intersect(&Ray::new(Vec3::ZERO, Vec3::Y), 1e9)
            .is_none());
    }
}
