//! Finite circular cylinders about the z axis from z = 0 to z = height, optionally capped:
//! a cone whose two radii are equal.

use super::{Cone, HitRecord, Partial, SurfaceGeometry, UvMap};
use crate::math::{Bounds3, Ray, Vec3};
use std::f64::consts::TAU;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylinder {
    shape: Cone,
    /// Whose (u, v) its side reports: Plenum's (φ/2π about z from +x, z/height) is
    /// pbrt-v4's for a whole turn; pbrt-v4 divides φ by φ_max, Mitsuba turns v down.
    uv_map: UvMap,
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
                partial: None,
            },
            uv_map: UvMap::Plenum,
        }
    }

    /// The cylinder reporting `map`'s (u, v).
    pub fn with_uv_map(self, uv_map: UvMap) -> Self {
        Cylinder { uv_map, ..self }
    }

    /// What multiplies Plenum's u and v for the map (v: 1 − v where negative).
    fn uv_scale(&self) -> (f64, f64) {
        match self.uv_map {
            UvMap::Plenum => (1.0, 1.0),
            UvMap::Pbrt => (
                TAU / self.shape.partial.map_or(TAU, |p| p.phi_max.min(TAU)),
                1.0,
            ),
            UvMap::Mitsuba => (1.0, -1.0),
        }
    }

    /// The cylinder swept through less than a full turn, as `partial` keeps it.
    pub fn with_partial(mut self, partial: Partial) -> Self {
        self.shape.partial = partial.cut();
        self
    }

    pub fn partial(&self) -> Option<Partial> {
        self.shape.partial
    }

    pub fn radius(&self) -> f64 {
        self.shape.radius0
    }

    pub fn uv_map(&self) -> UvMap {
        self.uv_map
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
        let mut g = self.shape.surface(ray, hit, want_uv);
        if want_uv && self.uv_map != UvMap::Plenum {
            let (su, sv) = self.uv_scale();
            g.uv = [g.uv[0] * su, if sv < 0.0 { 1.0 - g.uv[1] } else { g.uv[1] }];
        }
        g
    }

    pub fn uv_derivatives(&self, hit: &HitRecord, p: Vec3) -> [Vec3; 2] {
        let [dpdu, dpdv] = self.shape.uv_derivatives(hit, p);
        let (su, sv) = self.uv_scale();
        [dpdu / su, dpdv * sv]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    #[test]
    fn half_a_cylinder_shows_its_inside_through_the_cut() {
        // φ up to 180°: the half at y ≥ 0. A ray along +y from below passes the cut half and
        // meets the inside of the kept one.
        let c = Cylinder::new(1.0, 2.0, false).with_partial(Partial {
            phi_max: std::f64::consts::PI,
            ..Partial::WHOLE
        });
        let hit = c
            .intersect(&Ray::new(Vec3::new(0.0, -5.0, 1.0), Vec3::Y), 1e9)
            .unwrap();
        assert!((hit.t - 6.0).abs() < 1e-12);
        assert!(c
            .intersect(&Ray::new(Vec3::new(5.0, -0.5, 1.0), -Vec3::X), 1e9)
            .is_none());
        assert!(!super::super::Shape::Cylinder(c).is_closed() && c.partial().is_some());
    }

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
