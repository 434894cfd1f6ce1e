//! Rays: an origin and a direction, parametrised as o + t·d for t in (0, t_max), and a time.

use super::Vec3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    /// Not necessarily unit length; distances along the ray are in units of |direction|.
    pub direction: Vec3,
    /// When the ray is traced, within the camera's shutter interval: moving objects are
    /// intersected where they are at this time. Rays spawned at a hit inherit it.
    pub time: f64,
}

impl Ray {
    pub fn new(origin: Vec3, direction: Vec3) -> Self {
        Ray {
            origin,
            direction,
            time: 0.0,
        }
    }

    /// The same ray at another time.
    pub fn at_time(self, time: f64) -> Self {
        Ray { time, ..self }
    }

    pub fn at(&self, t: f64) -> Vec3 {
        self.origin + self.direction * t
    }
}
