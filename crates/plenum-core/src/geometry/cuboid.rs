//! Axis-aligned boxes by the slab method (Kay and Kajiya 1986).

use super::{HitRecord, SurfaceGeometry};
use crate::math::{gamma, Bounds3, Ray, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cuboid {
    pub min: Vec3,
    pub max: Vec3,
}

impl Cuboid {
    pub fn new(a: Vec3, b: Vec3) -> Self {
        Cuboid {
            min: a.min(b),
            max: a.max(b),
        }
    }

    pub fn bounds(&self) -> Bounds3 {
        Bounds3::new(self.min, self.max)
    }

    /// Parts number the faces: 2·axis for the min side, 2·axis + 1 for the max side.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<HitRecord> {
        let mut near = (f64::NEG_INFINITY, 0u32);
        let mut far = (f64::INFINITY, 0u32);
        for axis in 0..3 {
            let (o, d) = (ray.origin[axis], ray.direction[axis]);
            if d == 0.0 {
                if o < self.min[axis] || o > self.max[axis] {
                    return None;
                }
                continue;
            }
            let t_min = (self.min[axis] - o) / d;
            let t_max_axis = (self.max[axis] - o) / d;
            let axis = axis as u32;
            let (enter, exit) = if d > 0.0 {
                ((t_min, 2 * axis), (t_max_axis, 2 * axis + 1))
            } else {
                ((t_max_axis, 2 * axis + 1), (t_min, 2 * axis))
            };
            if enter.0 > near.0 {
                near = enter;
            }
            if exit.0 < far.0 {
                far = exit;
            }
        }
        if near.0 > far.0 {
            return None;
        }
        let (t, part) = if near.0 > 0.0 { near } else { far };
        (t > 0.0 && t < t_max).then_some(HitRecord {
            t,
            u: 0.0,
            v: 0.0,
            part,
        })
    }

    pub fn surface(&self, ray: &Ray, hit: &HitRecord) -> SurfaceGeometry {
        let axis = (hit.part / 2) as usize;
        let max_side = hit.part % 2 == 1;
        let mut c = ray.at(hit.t).to_array();
        // Snap onto the face: the coordinate along the normal becomes exact.
        c[axis] = if max_side {
            self.max[axis]
        } else {
            self.min[axis]
        };
        let p = Vec3::from_array(c);
        let mut n = [0.0; 3];
        n[axis] = if max_side { 1.0 } else { -1.0 };
        let (ua, va) = ((axis + 1) % 3, (axis + 2) % 3);
        let size = self.max - self.min;
        let uv = [
            (c[ua] - self.min[ua]) / size[ua],
            (c[va] - self.min[va]) / size[va],
        ];
        SurfaceGeometry::flat(p, p.abs() * gamma(4), Vec3::from_array(n), uv)
    }

    /// The face's edges along which u and v run (see `surface`).
    pub fn uv_derivatives(&self, hit: &HitRecord) -> [Vec3; 2] {
        let axis = (hit.part / 2) as usize;
        let size = (self.max - self.min).to_array();
        [(axis + 1) % 3, (axis + 2) % 3].map(|a| {
            let mut e = [0.0; 3];
            e[a] = size[a];
            Vec3::from_array(e)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn enters_and_leaves_through_the_right_faces() {
        let b = Cuboid::new(Vec3::splat(-1.0), Vec3::splat(1.0));
        let ray = Ray::new(Vec3::new(0.2, 0.3, -5.0), Vec3::Z);
        let hit = b.intersect(&ray, 1e9).unwrap();
        assert!((hit.t - 4.0).abs() < 1e-15);
        assert_eq!(b.surface(&ray, &hit).n, -Vec3::Z);
        let inside = Ray::new(Vec3::ZERO, Vec3::new(1.0, 0.5, 0.0));
        let hit = b.intersect(&inside, 1e9).unwrap();
        assert!((hit.t - 1.0).abs() < 1e-15);
        assert_eq!(b.surface(&inside, &hit).n, Vec3::X);
        assert!(b
            .intersect(&Ray::new(Vec3::new(2.0, 0.0, -5.0), Vec3::Z), 1e9)
            .is_none());
    }
}
