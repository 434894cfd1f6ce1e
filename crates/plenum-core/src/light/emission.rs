//! Light leaving the lights: the first ray of a light path (light tracing, photon mapping,
//! the light half of bidirectional path tracing), and the densities with which it is drawn,
//! for their MIS weights (pbrt-v4's `SampleLe` and `PDF_Le`, §12.1–12.6).
//!
//! Area lights start from a point uniform by area, leaving by a cosine-weighted direction
//! (one side, or either side of a two-sided surface with probability ½ each). Point lights
//! leave uniformly over the sphere, spots uniformly over their outer cone. Lights at infinity
//! (directional, uniform, environment maps) enter the scene from a disk facing the chosen
//! direction, of the scene's bounding radius, just outside it.

use super::Light;
use crate::color::Color;
use crate::math::{Ray, Vec3};
use crate::sampling::{
    concentric_disk, cosine_hemisphere, uniform_cone, uniform_cone_pdf, uniform_sphere, Frame,
};
use std::f64::consts::PI;

/// A ray of light leaving a light.
#[derive(Clone, Copy, Debug)]
pub struct EmissionSample {
    /// From the light's point, unit direction.
    pub ray: Ray,
    /// The unit surface normal at the origin, for an area light.
    pub n: Option<Vec3>,
    /// What multiplies the light's spectrum: a spot's falloff, 1 otherwise.
    pub scale: f64,
    /// Radiance that varies (an environment map's by direction, a textured area light's over
    /// its surface), linear RGB, in place of the light's spectrum times `scale`.
    pub radiance: Option<Color>,
    pub pdf: EmissionPdf,
}

/// The densities of an emitted ray: its origin per unit area (of the light's surface, or of
/// the entry disk for lights at infinity) and its direction per steradian. A delta
/// component (a point's position, a directional light's direction) is reported as 1.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EmissionPdf {
    pub pos: f64,
    pub dir: f64,
}

impl Light {
    /// The origin is a point (point and spot lights): no strategy can hit it.
    pub fn is_delta_position(&self) -> bool {
        matches!(
            self,
            Light::Point { .. } | Light::Spot { .. } | Light::Profiled { .. }
        )
    }

    /// The direction is fixed (directional lights).
    pub fn is_delta_direction(&self) -> bool {
        matches!(self, Light::Directional { .. })
    }

    /// A ray leaving the light, from `u_pos` and `u_dir` ∈ [0, 1)², in a scene bounded by the
    /// sphere (`center`, `radius`) (for lights at infinity).
    pub fn sample_le(
        &self,
        u_pos: [f64; 2],
        u_dir: [f64; 2],
        center: Vec3,
        radius: f64,
    ) -> Option<EmissionSample> {
        let sample = |origin: Vec3, d: Vec3, n, scale, radiance, pos, dir| EmissionSample {
            ray: Ray::new(origin, d),
            n,
            scale,
            radiance,
            pdf: EmissionPdf { pos, dir },
        };
        match *self {
            Light::Area {
                ref shape,
                two_sided,
                ..
            } => {
                let (q, n, at) = shape.sample_point(u_pos)?;
                // A two-sided surface: u_dir[0] picks the side and is stretched back to [0, 1).
                let (side, u, half) = if two_sided {
                    if u_dir[0] < 0.5 {
                        (n, [2.0 * u_dir[0], u_dir[1]], 0.5)
                    } else {
                        (
                            -n,
                            [(2.0 * u_dir[0] - 1.0).min(1.0 - f64::EPSILON), u_dir[1]],
                            0.5,
                        )
                    }
                } else {
                    (n, u_dir, 1.0)
                };
                let local = cosine_hemisphere(u);
                let d = Frame::from_z(side).to_world(local);
                let pdf_dir = half * local.z / PI;
                let radiance = self.textured_radiance(at);
                (pdf_dir > 0.0)
                    .then(|| sample(q, d, Some(n), 1.0, radiance, 1.0 / shape.area(), pdf_dir))
            }
            Light::Point { position, .. } => Some(sample(
                position,
                uniform_sphere(u_dir),
                None,
                1.0,
                None,
                1.0,
                1.0 / (4.0 * PI),
            )),
            Light::Spot {
                position,
                direction,
                cos_outer,
                ..
            } => {
                let d = Frame::from_z(direction).to_world(uniform_cone(u_dir, cos_outer));
                let (scale, _) = self.point_emission(d);
                Some(sample(
                    position,
                    d,
                    None,
                    scale,
                    None,
                    1.0,
                    uniform_cone_pdf(cos_outer),
                ))
            }
            Light::Profiled {
                position,
                ref profile,
                ..
            } => {
                let (d, pdf) = profile.sample(u_dir);
                let (scale, radiance) = self.point_emission(d);
                (pdf > 0.0).then(|| sample(position, d, None, scale, radiance, 1.0, pdf))
            }
            Light::Directional { direction, .. } => {
                let (o, pos) = entry_disk(-direction, u_pos, center, radius);
                Some(sample(o, direction, None, 1.0, None, pos, 1.0))
            }
            Light::Infinite { .. } => {
                let wi = uniform_sphere(u_dir);
                let (o, pos) = entry_disk(wi, u_pos, center, radius);
                Some(sample(o, -wi, None, 1.0, None, pos, 1.0 / (4.0 * PI)))
            }
            Light::Environment { ref map, .. } => {
                let (wi, pdf, [r, g, b]) = map.map.sample(u_dir)?;
                let (o, pos) = entry_disk(wi, u_pos, center, radius);
                (pdf > 0.0).then(|| sample(o, -wi, None, 1.0, Some(Color::new(r, g, b)), pos, pdf))
            }
        }
    }

    /// The densities with which [`Light::sample_le`] draws the ray leaving an area light's
    /// point (unit normal `n`) along `d`, or entering from infinity along `d`; for point
    /// lights the density of the direction `d` alone. Zero where the light sends nothing.
    pub fn pdf_le(&self, n: Vec3, d: Vec3, radius: f64) -> EmissionPdf {
        let disk = 1.0 / (PI * radius * radius);
        match *self {
            Light::Area {
                ref shape,
                two_sided,
                ..
            } => {
                let cos = n.dot(d);
                let dir = if two_sided {
                    0.5 * cos.abs() / PI
                } else {
                    cos.max(0.0) / PI
                };
                EmissionPdf {
                    pos: 1.0 / shape.area(),
                    dir,
                }
            }
            Light::Point { .. } => EmissionPdf {
                pos: 1.0,
                dir: 1.0 / (4.0 * PI),
            },
            Light::Spot {
                direction,
                cos_outer,
                ..
            } => EmissionPdf {
                pos: 1.0,
                dir: if d.dot(direction) >= cos_outer {
                    uniform_cone_pdf(cos_outer)
                } else {
                    0.0
                },
            },
            Light::Profiled { ref profile, .. } => EmissionPdf {
                pos: 1.0,
                dir: profile.pdf(d),
            },
            Light::Directional { .. } => EmissionPdf {
                pos: disk,
                dir: 1.0,
            },
            Light::Infinite { .. } | Light::Environment { .. } => EmissionPdf {
                pos: disk,
                dir: self.pdf_direction(-d),
            },
        }
    }

    /// What a light that is a point sends toward the unit direction `d`: a factor on its
    /// spectrum (a spot's smooth falloff, a goniometric diagram's value), or an RGB
    /// intensity in place of its spectrum (a projected image's colour times the light's
    /// intensity). (1, None) for other lights.
    pub fn point_emission(&self, d: Vec3) -> (f64, Option<Color>) {
        match *self {
            Light::Spot {
                direction,
                cos_inner,
                cos_outer,
                ..
            } => (
                super::smoothstep(cos_outer, cos_inner, d.dot(direction)),
                None,
            ),
            Light::Profiled {
                intensity,
                ref profile,
                ..
            } => {
                let f = profile.factor(d);
                match profile.is_grey() {
                    true => (f.r, None),
                    false => (1.0, Some(intensity * f)),
                }
            }
            _ => (1.0, None),
        }
    }
}

/// A point on the disk of radius `radius` facing the direction `toward` (the direction the
/// light comes from), just outside the scene's bounding sphere, and its area density.
fn entry_disk(toward: Vec3, u: [f64; 2], center: Vec3, radius: f64) -> (Vec3, f64) {
    let (x, y) = concentric_disk(u);
    let (s, t) = toward.orthonormal_basis();
    let o = center + (toward + (s * x + t * y)) * radius;
    (o, 1.0 / (PI * radius * radius))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::Emitter;
    use crate::sampling::Rng;

    fn rect(two_sided: bool) -> Light {
        Light::Area {
            shape: Emitter::Rectangle {
                corner: Vec3::new(-1.0, 0.0, -0.5),
                edge_u: Vec3::new(2.0, 0.0, 0.0),
                edge_v: Vec3::new(0.0, 0.0, 1.0),
            },
            radiance: Color::gray(1.0),
            samples: 1,
            two_sided,
            texture: None,
        }
    }

    /// An area light's emission samples against their claimed densities, by chi-square
    /// (10⁶ samples, seeds 0x5EED0011 and 0x5EED0012, the crate-wide significance of
    /// chi_square.rs): the origins uniform over the rectangle (1/A), the directions
    /// cosine-distributed about the emitting side's normal, both sides taken equally where
    /// the light is two-sided (|cos|/2π over the sphere); and `pdf_le` of each sampled ray
    /// equal to the densities `sample_le` reported for it. (The product cos/(pdf_pos pdf_dir)
    /// is π·A for any sample, so a power estimate could not see a wrong distribution.)
    #[test]
    fn area_emission_samples_follow_their_densities() {
        use crate::sampling::chi_square::{PlanarBins, PolarBins};
        const SAMPLES: usize = 1_000_000;
        for two_sided in [false, true] {
            let light = rect(two_sided);
            let Light::Area { ref shape, .. } = light else {
                unreachable!()
            };
            let normal = shape.sample_area([0.5, 0.5]).unwrap().1;
            let mut rng = Rng::new(0x5EED_0010, two_sided as u64);
            let mut sample = |u: [f64; 2]| {
                let v = [rng.uniform(), rng.uniform()];
                let s = light.sample_le(u, v, Vec3::ZERO, 10.0).unwrap();
                let p = light.pdf_le(s.n.unwrap(), s.ray.direction, 10.0);
                assert!((p.pos - s.pdf.pos).abs() < 1e-12 && (p.dir - s.pdf.dir).abs() < 1e-12);
                s
            };
            // Origins: the rectangle spans x ∈ [−1, 1], z ∈ [−0.5, 0.5]; as unit coordinates
            // their density is 1.
            PlanarBins::square(0.0, 1.0, 20)
                .test(
                    SAMPLES,
                    0x5EED_0011,
                    |u| {
                        let o = sample(u).ray.origin;
                        ((o.x + 1.0) / 2.0, o.z + 0.5)
                    },
                    |_, _| 1.0,
                )
                .assert_accepted("area light: emission origins");
            let bins = PolarBins {
                frame: crate::sampling::Frame::from_z(normal),
                bins: [40, 20],
            };
            let sides = if two_sided { 0.5 } else { 1.0 };
            bins.test(
                SAMPLES,
                0x5EED_0012,
                |u| sample([u[0], u[1]]).ray.direction,
                |w| {
                    let cos = w.dot(normal);
                    if two_sided || cos > 0.0 {
                        sides * cos.abs() / PI
                    } else {
                        0.0
                    }
                },
            )
            .assert_accepted(if two_sided {
                "two-sided area light: emission directions"
            } else {
                "one-sided area light: emission directions"
            });
        }
    }

    /// A spot light's rays stay inside its outer cone; lights at infinity enter from outside
    /// the scene's sphere, heading into it.
    #[test]
    fn spot_and_infinite_rays() {
        let spot = Light::Spot {
            position: Vec3::ZERO,
            direction: Vec3::Y,
            cos_inner: 0.95,
            cos_outer: 0.9,
            intensity: Color::gray(1.0),
            attenuation: Default::default(),
        };
        let env = Light::Infinite {
            radiance: Color::gray(1.0),
        };
        let mut rng = Rng::new(3, 2);
        for _ in 0..1000 {
            let u = [rng.uniform(), rng.uniform()];
            let v = [rng.uniform(), rng.uniform()];
            let s = spot.sample_le(u, v, Vec3::ZERO, 1.0).unwrap();
            assert!(s.ray.direction.dot(Vec3::Y) >= 0.9 - 1e-12);
            assert!(s.scale >= 0.0 && s.scale <= 1.0);
            let c = Vec3::new(1.0, 2.0, 3.0);
            let e = env.sample_le(u, v, c, 2.0).unwrap();
            let to_centre = c - e.ray.origin;
            assert!(to_centre.length() >= 2.0 - 1e-9);
            assert!(e.ray.direction.dot(to_centre) > 0.0);
            let p = env.pdf_le(Vec3::ZERO, e.ray.direction, 2.0);
            assert!((p.dir - e.pdf.dir).abs() < 1e-12 && (p.pos - e.pdf.pos).abs() < 1e-12);
        }
    }
}
