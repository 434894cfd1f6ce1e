//! Axis-aligned bounding boxes.

use super::{gamma, Ray, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds3 {
    pub min: Vec3,
    pub max: Vec3,
}

impl Default for Bounds3 {
    /// The empty box: the identity of `union`.
    fn default() -> Self {
        Bounds3 {
            min: Vec3::splat(f64::INFINITY),
            max: Vec3::splat(f64::NEG_INFINITY),
        }
    }
}

impl Bounds3 {
    pub fn new(a: Vec3, b: Vec3) -> Self {
        Bounds3 {
            min: a.min(b),
            max: a.max(b),
        }
    }

    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Self {
        points
            .into_iter()
            .fold(Bounds3::default(), |b, p| b.union_point(p))
    }

    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    pub fn union(&self, o: &Bounds3) -> Bounds3 {
        Bounds3 {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    pub fn union_point(&self, p: Vec3) -> Bounds3 {
        Bounds3 {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    pub fn diagonal(&self) -> Vec3 {
        self.max - self.min
    }

    pub fn centroid(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    pub fn surface_area(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.diagonal();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// The eight corners, for transforming a box.
    pub fn corners(&self) -> [Vec3; 8] {
        let (a, b) = (self.min, self.max);
        [
            Vec3::new(a.x, a.y, a.z),
            Vec3::new(b.x, a.y, a.z),
            Vec3::new(a.x, b.y, a.z),
            Vec3::new(b.x, b.y, a.z),
            Vec3::new(a.x, a.y, b.z),
            Vec3::new(b.x, a.y, b.z),
            Vec3::new(a.x, b.y, b.z),
            Vec3::new(b.x, b.y, b.z),
        ]
    }

    /// The smallest sphere around the box's centre that contains it: (centre, radius).
    pub fn bounding_sphere(&self) -> (Vec3, f64) {
        let c = self.centroid();
        (c, (self.max - c).length())
    }

    /// The parametric interval where the ray is inside the box, clipped to (0, t_max).
    /// `inv_dir` is 1/direction per axis. The far distance is widened by 2γ₃ so that
    /// rounding never makes the slab test miss a hit (pbrt-v4 §6.1.2).
    /// [`Bounds3::intersect`] for a single test, computing the reciprocal direction.
    pub fn intersect_interval(&self, ray: &Ray, t_max: f64) -> Option<(f64, f64)> {
        let d = ray.direction;
        self.intersect(ray, Vec3::new(1.0 / d.x, 1.0 / d.y, 1.0 / d.z), t_max)
    }

    /// The box grown by `margin` on every side.
    pub fn expanded(&self, margin: f64) -> Bounds3 {
        Bounds3 {
            min: self.min - Vec3::splat(margin),
            max: self.max + Vec3::splat(margin),
        }
    }

    pub fn intersect(&self, ray: &Ray, inv_dir: Vec3, t_max: f64) -> Option<(f64, f64)> {
        let mut t0 = 0.0f64;
        let mut t1 = t_max;
        for axis in 0..3 {
            let mut near = (self.min[axis] - ray.origin[axis]) * inv_dir[axis];
            let mut far = (self.max[axis] - ray.origin[axis]) * inv_dir[axis];
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            far *= 1.0 + 2.0 * gamma(3);
            // NaN (0 · ∞ for a ray in a slab's plane) must not shrink the interval.
            if near > t0 {
                t0 = near;
            }
            if far < t1 {
                t1 = far;
            }
            if t0 > t1 {
                return None;
            }
        }
        Some((t0, t1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slab_test_hits_and_misses() {
        let b = Bounds3::new(Vec3::ZERO, Vec3::ONE);
        let ray = Ray::new(Vec3::new(0.5, 0.5, -1.0), Vec3::Z);
        let inv = Vec3::new(f64::INFINITY, f64::INFINITY, 1.0);
        let (t0, t1) = b.intersect(&ray, inv, f64::INFINITY).unwrap();
        assert!((t0 - 1.0).abs() < 1e-12 && (t1 - 2.0).abs() < 1e-9);
        let ray = Ray::new(Vec3::new(1.5, 0.5, -1.0), Vec3::Z);
        assert!(b.intersect(&ray, inv, f64::INFINITY).is_none());
    }
}
