//! Finite circular cylinders about the z axis from z = 0 to z = height, optionally capped:
//! a cone whose two radii are equal.

use super::{Cone, HitRecord, SurfaceGeometry};
use crate::math::{Bounds3, Ray};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylinder {
    shape: Cone,
}

impl Cylinder {
    pub fn new(radius: f64, height: f64, capped: bool) -> Self {
        Cylinder {
            shape: Cone {
                radius0: radius,
                radius1: radius,
                height,
                capped,
                inside_only: false,
            },
        }
    }

    pub fn radius(&self) -> f64 {
        self.shape.radius0
    }

    pub fn is_capped(&self) -> bool {
        self.shape.capped
    }

    pub fn height(&self) -> f64 {
        self.shape.height
    }

    pub fn bounds(&self) -> Bounds3 {
        self.shape.bounds()
    }

    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<HitRecord> {
        self.shape.intersect(ray, t_max)
    }

    pub fn surface(&self, ray: &Ray, hit: &HitRecord, want_uv: bool) -> SurfaceGeometry {
        self.shape.surface(ray, hit, want_uv)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    #[test]
    fn side_and_inside_hits() {
        let c = Cylinder::new(2.0, 3.0, false);
        let ray = Ray::new(Vec3::new(-10.0, 1.0, 1.5), Vec3::X);
        let hit = c.intersect(&ray, 1e9).unwrap();
        // x = −√(4 − 1)
        assert!((hit.t - (10.0 - 3f64.sqrt())).abs() < 1e-12);
        let g = c.surface(&ray, &hit, true);
        assert!((g.n - Vec3::new(-(3f64.sqrt()) / 2.0, 0.5, 0.0)).length() < 1e-12);
        // Above the top the open cylinder is missed.
        assert!(c
            .intersect(&Ray::new(Vec3::new(-10.0, 0.0, 3.5), Vec3::X), 1e9)
            .is_none());
        // From the axis, the inside wall.
        let hit = c
            .intersect(&Ray::new(Vec3::new(0.0, 0.0, 1.0), Vec3::Y), 1e9)
            .unwrap();
        assert!((hit.t - 2.0).abs() < 1e-12);
    }
}
