//! Quadrics cut as pbrt-v4's partial shapes are: a sphere between two heights, a disk with a
//! hole, any of them swept through less than a full turn. A hit on a cut-away part is
//! passed, and the ray goes on to the quadric's other root (the inside of a cut sphere shows
//! through its opening).

use crate::math::Vec3;
use std::f64::consts::TAU;

/// What is kept of a shape, in its own coordinates about its centre: z in [z_min, z_max], at
/// least `inner_radius` from the z axis, and the angle about z from +x toward +y at most
/// `phi_max` radians.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Partial {
    pub z_min: f64,
    pub z_max: f64,
    pub inner_radius: f64,
    pub phi_max: f64,
}

impl Partial {
    /// The whole shape.
    pub const WHOLE: Partial = Partial {
        z_min: f64::NEG_INFINITY,
        z_max: f64::INFINITY,
        inner_radius: 0.0,
        phi_max: TAU,
    };

    /// `Some` where something is cut away, `None` for the whole shape.
    pub fn cut(self) -> Option<Partial> {
        let whole = self.z_min == f64::NEG_INFINITY
            && self.z_max == f64::INFINITY
            && self.inner_radius <= 0.0
            && self.phi_max >= TAU;
        (!whole).then_some(self)
    }

    /// Whether point `p` (relative to the shape's centre) is kept.
    #[inline]
    pub fn keeps(&self, p: Vec3) -> bool {
        if p.z < self.z_min || p.z > self.z_max {
            return false;
        }
        let rho2 = p.x * p.x + p.y * p.y;
        if rho2 < self.inner_radius * self.inner_radius {
            return false;
        }
        if self.phi_max < TAU {
            // On the axis the angle is 0 (pbrt-v4 nudges x there to the same effect).
            let phi = p.y.atan2(p.x);
            let phi = if phi < 0.0 { phi + TAU } else { phi };
            return phi <= self.phi_max;
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_what_each_limit_allows() {
        let half_turn = Partial {
            phi_max: std::f64::consts::PI,
            ..Partial::WHOLE
        };
        assert!(half_turn.keeps(Vec3::new(1.0, 0.5, 0.0)));
        assert!(!half_turn.keeps(Vec3::new(1.0, -0.5, 0.0)));
        assert!(half_turn.keeps(Vec3::ZERO));
        let band = Partial {
            z_min: -0.5,
            z_max: 0.25,
            ..Partial::WHOLE
        };
        assert!(band.keeps(Vec3::new(0.0, 0.0, 0.2)) && !band.keeps(Vec3::new(0.0, 0.0, 0.3)));
        let ring = Partial {
            inner_radius: 0.5,
            ..Partial::WHOLE
        };
        assert!(!ring.keeps(Vec3::new(0.3, 0.3, 0.0)) && ring.keeps(Vec3::new(0.4, 0.4, 0.0)));
        assert_eq!(Partial::WHOLE.cut(), None);
        assert_eq!(band.cut(), Some(band));
    }
}
