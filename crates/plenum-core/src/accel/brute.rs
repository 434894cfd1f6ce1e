//! No acceleration: every item is considered for every ray, after the cheap rejection the
//! lecture pairs with it, a bounding sphere per item. The test oracle for the others.

use crate::math::{Bounds3, Ray, Vec3};

#[derive(Clone, Debug)]
pub struct BruteForce {
    /// Per item: centre and squared radius of a sphere around its box (radius −1: no box).
    spheres: Vec<(Vec3, f64)>,
    bounds: Bounds3,
}

impl BruteForce {
    pub fn build(item_bounds: &[Bounds3]) -> BruteForce {
        let spheres = item_bounds
            .iter()
            .map(|b| {
                if b.is_empty() {
                    return (Vec3::ZERO, -1.0);
                }
                // Half the diagonal, grown a hair so rounding cannot reject a grazing ray.
                let r = b.diagonal().length() * 0.5 * (1.0 + 1e-9) + 1e-300;
                (b.centroid(), r * r)
            })
            .collect();
        let bounds = item_bounds
            .iter()
            .fold(Bounds3::default(), |b, i| b.union(i));
        BruteForce { spheres, bounds }
    }

    pub fn bounds(&self) -> Bounds3 {
        self.bounds
    }

    pub fn memory_bytes(&self) -> usize {
        self.spheres.len() * std::mem::size_of::<(Vec3, f64)>()
    }

    /// Hands `visit` every item whose bounding sphere the ray meets in (0, t_max)
    /// (see [`super::Accel::traverse`]).
    pub fn traverse(&self, ray: &Ray, t_max: f64, mut visit: impl FnMut(&[u32], &mut f64) -> bool) {
        let d = ray.direction;
        let dd = d.length_squared();
        if dd == 0.0 {
            return;
        }
        let mut t_max = t_max;
        let mut visits = super::cost::Visits::start();
        for (i, &(c, r2)) in self.spheres.iter().enumerate() {
            if r2 < 0.0 {
                continue;
            }
            visits.nodes += 1;
            // Closest approach of the ray's line to the centre.
            let oc = c - ray.origin;
            let t_closest = oc.dot(d) / dd;
            let miss2 = (oc - d * t_closest).length_squared();
            if miss2 > r2 * (1.0 + 1e-9) {
                continue;
            }
            // The sphere's span along the ray, against (0, t_max).
            let half = ((r2 - miss2).max(0.0) / dd).sqrt() * (1.0 + 1e-9);
            if t_closest + half < 0.0 || t_closest - half > t_max {
                continue;
            }
            if !visit(&[i as u32], &mut t_max) {
                return;
            }
        }
    }
}
