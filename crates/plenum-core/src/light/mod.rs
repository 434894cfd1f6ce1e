//! Lights. Point, directional and spot lights are Whitted's; area lights (rectangles, disks,
//! spheres and triangle meshes that emit) are distribution ray tracing's: shadow rays go to
//! points sampled over their area, so shadows get penumbrae. Ambient light is not among
//! them: the scene keeps one ambient colour I_a, the sum of the ambient lights its file
//! declares.
//!
//! Units: a point light's I_L reaches a surface undimmed unless an attenuation says otherwise
//! (Whitted's convention), while an area light of radiance L_e gives the irradiance physics
//! gives, ∫ L_e cos θ dω, which falls off with the square of the distance.

use crate::color::Color;
use crate::environment::EnvironmentMap;
use crate::geometry::Shape;
use crate::math::{Transform, Vec3};
use crate::sampling::{
    concentric_disk, uniform_cone, uniform_cone_pdf, uniform_sphere, uniform_triangle, Frame,
};
use std::sync::Arc;

mod emission;
mod profile;
mod textured;
pub use emission::{EmissionPdf, EmissionSample};
pub use profile::Profile;
pub use textured::EmissionTexture;
use textured::EmitterPoint;

/// Distance attenuation f(d) = min(1, 1 / (a + b·d + c·d²)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attenuation {
    pub constant: f64,
    pub linear: f64,
    pub quadratic: f64,
}

impl Default for Attenuation {
    /// No falloff, as in Whitted's paper.
    fn default() -> Self {
        Attenuation {
            constant: 1.0,
            linear: 0.0,
            quadratic: 0.0,
        }
    }
}

impl Attenuation {
    pub fn factor(&self, d: f64) -> f64 {
        let denominator = self.constant + self.linear * d + self.quadratic * d * d;
        if denominator <= 0.0 {
            1.0
        } else {
            (1.0 / denominator).min(1.0)
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    Point {
        position: Vec3,
        /// Colour times intensity: I_L.
        intensity: Color,
        attenuation: Attenuation,
    },
    /// A light at infinity shining along `direction` (unit).
    Directional { direction: Vec3, intensity: Color },
    /// A point light whose intensity varies with direction by `profile` (a goniometric
    /// diagram or a projected image), with the inverse-square law of physics.
    Profiled {
        position: Vec3,
        intensity: Color,
        profile: Arc<Profile>,
    },
    /// A point light limited to a cone, fading smoothly from the inner to the outer angle.
    Spot {
        position: Vec3,
        /// Unit axis of the cone, pointing away from the light.
        direction: Vec3,
        cos_inner: f64,
        cos_outer: f64,
        intensity: Color,
        attenuation: Attenuation,
    },
    /// A surface that emits radiance `radiance` from every point, toward both sides or, when
    /// not `two_sided`, only toward the side its normal points to.
    Area {
        shape: Emitter,
        radiance: Color,
        /// Shadow rays per shading point, stratified over the area (rounded up to a square).
        samples: u32,
        two_sided: bool,
        /// A texture that multiplies `radiance` over the surface (then RGB: a spectrum the
        /// light was given is not used).
        texture: Option<Arc<EmissionTexture>>,
    },
    /// Radiance `radiance` arriving from every direction at infinity (physically based
    /// integrators only; Whitted's scenes have their `background`).
    Infinite { radiance: Color },
    /// Radiance from infinity by direction, from an environment image, importance-sampled
    /// (physically based integrators only). `radiance` is the map's average, for Whitted's
    /// model and the light's power.
    Environment {
        map: EnvironmentLight,
        radiance: Color,
    },
}

/// An environment map shared by the scene's copies of its light, with where it came from
/// (to write the scene back); equal when it is the same map.
#[derive(Clone, Debug)]
pub struct EnvironmentLight {
    pub map: Arc<EnvironmentMap>,
    /// The image file, as the scene named it, resolved.
    pub file: String,
    /// The factor the image's radiance was scaled by.
    pub scale: f64,
}

impl PartialEq for EnvironmentLight {
    fn eq(&self, o: &Self) -> bool {
        Arc::ptr_eq(&self.map, &o.map)
    }
}

/// The surface of an area light, in world coordinates.
#[derive(Clone, Debug, PartialEq)]
pub enum Emitter {
    /// The parallelogram corner + a·edge_u + b·edge_v, a and b in [0, 1].
    Rectangle {
        corner: Vec3,
        edge_u: Vec3,
        edge_v: Vec3,
    },
    Disk {
        center: Vec3,
        normal: Vec3,
        radius: f64,
    },
    Sphere {
        center: Vec3,
        radius: f64,
    },
    /// Triangles, picked in proportion to their area.
    Triangles {
        triangles: Vec<[Vec3; 3]>,
        /// Each triangle's unit normal, by its winding: worked out once, not per sample.
        normals: Vec<Vec3>,
        /// Running sums of the triangles' areas, the last one the total.
        cumulative_area: Vec<f64>,
    },
}

impl Emitter {
    /// The emitter that samples a placed shape's surface: a sphere (under a transform that
    /// keeps it round) or disk as itself, a mesh, polygon, box or polyhedron by its
    /// triangles in world space (normals by their winding; a polygon's, concave or not, from
    /// [`Polygon::triangles`](crate::geometry::Polygon::triangles)); `None` for shapes it cannot
    /// sample (planes, cylinders, cones) or without area.
    pub fn of_shape(shape: &Shape, to_world: &Transform) -> Option<Emitter> {
        match shape {
            Shape::Sphere(s) => {
                let center = to_world.point(s.center);
                let axes = [Vec3::X, Vec3::Y, Vec3::Z].map(|a| to_world.vector(a).length());
                let round = axes.iter().all(|&l| (l - axes[0]).abs() <= 1e-9 * axes[0]);
                round.then(|| Emitter::Sphere {
                    center,
                    radius: s.radius * axes[0],
                })
            }
            Shape::Disk(d) if to_world.is_identity() => Some(Emitter::Disk {
                center: d.center,
                normal: d.normal.normalized(),
                radius: d.radius,
            }),
            _ => Emitter::triangles(
                Emitter::object_triangles(shape, to_world)?
                    .into_iter()
                    .map(|(_, t)| t.map(|p| to_world.point(p)))
                    .collect(),
            ),
        }
    }

    /// The triangles of [`Emitter::of_shape`] in the shape's own coordinates, in order, each
    /// with the part of the shape it lies on; `None` for shapes drawn otherwise.
    pub(crate) fn object_triangles(
        shape: &Shape,
        to_world: &Transform,
    ) -> Option<Vec<(u32, [Vec3; 3])>> {
        // A transform that mirrors (negative determinant) reverses the winding of what it
        // places, but not the normal a hit reports (the inverse transpose): wound back, the
        // triangles' normals are the hit's, so one-sided light leaves the same side for
        // light sampling, light paths and rays that meet it.
        let mirrors = {
            let [x, y, z] = [Vec3::X, Vec3::Y, Vec3::Z].map(|a| to_world.vector(a));
            x.dot(y.cross(z)) < 0.0
        };
        let wind = |(part, [p, q, r]): (u32, [Vec3; 3])| {
            if mirrors {
                (part, [p, r, q])
            } else {
                (part, [p, q, r])
            }
        };
        let on_part = |part: u32, ts: Vec<[Vec3; 3]>| ts.into_iter().map(move |t| wind((part, t)));
        // The box's faces are convex: a fan covers each.
        let fan = |part: u32, vs: &[Vec3]| -> Vec<(u32, [Vec3; 3])> {
            (1..vs.len().saturating_sub(1))
                .map(|i| wind((part, [vs[0], vs[i], vs[i + 1]])))
                .collect()
        };
        Some(match shape {
            Shape::Mesh(m) => m.outward_triangles().map(wind).collect(),
            // Concave faces too: the polygon's own triangles, not a fan.
            Shape::Polygon(p) => on_part(0, p.triangles()).collect(),
            Shape::Polyhedron(p) => (p.faces().iter().enumerate())
                .flat_map(|(i, f)| on_part(i as u32, f.triangles()))
                .collect(),
            Shape::Cuboid(c) => {
                let (a, b) = (c.min, c.max);
                let v = |x: bool, y: bool, z: bool| {
                    Vec3::new(
                        if x { b.x } else { a.x },
                        if y { b.y } else { a.y },
                        if z { b.z } else { a.z },
                    )
                };
                // Six faces, each wound so that its normal points out of the box, with the
                // part a hit on it reports (2·axis, +1 on the far side).
                let faces = [
                    (
                        4,
                        [
                            v(false, false, false),
                            v(false, true, false),
                            v(true, true, false),
                            v(true, false, false),
                        ],
                    ),
                    (
                        5,
                        [
                            v(false, false, true),
                            v(true, false, true),
                            v(true, true, true),
                            v(false, true, true),
                        ],
                    ),
                    (
                        2,
                        [
                            v(false, false, false),
                            v(true, false, false),
                            v(true, false, true),
                            v(false, false, true),
                        ],
                    ),
                    (
                        3,
                        [
                            v(false, true, false),
                            v(false, true, true),
                            v(true, true, true),
                            v(true, true, false),
                        ],
                    ),
                    (
                        0,
                        [
                            v(false, false, false),
                            v(false, false, true),
                            v(false, true, true),
                            v(false, true, false),
                        ],
                    ),
                    (
                        1,
                        [
                            v(true, false, false),
                            v(true, true, false),
                            v(true, true, true),
                            v(true, false, true),
                        ],
                    ),
                ];
                faces.iter().flat_map(|(part, f)| fan(*part, f)).collect()
            }
            _ => return None,
        })
    }

    /// An emitter made of world-space triangles; `None` when they have no area.
    pub fn triangles(triangles: Vec<[Vec3; 3]>) -> Option<Emitter> {
        let mut sum = 0.0;
        let cumulative_area: Vec<f64> = triangles
            .iter()
            .map(|t| {
                sum += 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
                sum
            })
            .collect();
        let normals = triangles
            .iter()
            .map(|[a, b, c]| (*b - *a).cross(*c - *a).normalized())
            .collect();
        (sum > 0.0).then_some(Emitter::Triangles {
            triangles,
            normals,
            cumulative_area,
        })
    }

    pub fn area(&self) -> f64 {
        match self {
            Emitter::Rectangle { edge_u, edge_v, .. } => edge_u.cross(*edge_v).length(),
            Emitter::Disk { radius, .. } => std::f64::consts::PI * radius * radius,
            Emitter::Sphere { radius, .. } => 4.0 * std::f64::consts::PI * radius * radius,
            Emitter::Triangles {
                cumulative_area, ..
            } => cumulative_area.last().copied().unwrap_or(0.0),
        }
    }

    /// The solid-angle pdf at `p` with which [`Emitter::sample`] picks the surface point `q`
    /// whose unit normal is `n`: the sphere's cone pdf seen from outside, otherwise the
    /// uniform area pdf converted by d² / |cos θ_light|.
    pub fn pdf(&self, p: Vec3, q: Vec3, n: Vec3) -> f64 {
        if let Emitter::Sphere { center, radius } = self {
            let d2 = (*center - p).length_squared();
            let r2 = radius * radius;
            if d2 > r2 * (1.0 + 1e-9) {
                let cos_max = ((d2 - r2).max(0.0)).sqrt() / d2.sqrt();
                return uniform_cone_pdf(cos_max);
            }
        }
        let to = q - p;
        let d2 = to.length_squared();
        let cos_light = n.dot(to).abs() / d2.sqrt();
        if cos_light <= 0.0 || d2 == 0.0 {
            return 0.0;
        }
        d2 / (cos_light * self.area())
    }

    /// A point uniform over the surface by area (density 1 / [`Emitter::area`]) and its unit
    /// normal: where light paths start.
    pub fn sample_area(&self, u: [f64; 2]) -> Option<(Vec3, Vec3)> {
        self.sample_point(u).map(|(p, n, _)| (p, n))
    }

    /// [`Emitter::sample_area`], with where on the emitter the point lies.
    #[inline]
    fn sample_point(&self, u: [f64; 2]) -> Option<(Vec3, Vec3, EmitterPoint)> {
        let world = |(p, n): (Vec3, Vec3)| (p, n, EmitterPoint::World(p));
        Some(match self {
            Emitter::Sphere { center, radius } => {
                let n = uniform_sphere(u);
                world((*center + n * *radius, n))
            }
            Emitter::Rectangle {
                corner,
                edge_u,
                edge_v,
            } => world((
                *corner + *edge_u * u[0] + *edge_v * u[1],
                edge_u.cross(*edge_v).normalized(),
            )),
            Emitter::Disk {
                center,
                normal,
                radius,
            } => {
                let (x, y) = concentric_disk(u);
                let (s, t) = normal.orthonormal_basis();
                world((*center + (s * x + t * y) * *radius, *normal))
            }
            Emitter::Triangles {
                triangles,
                normals,
                cumulative_area,
            } => {
                let total = *cumulative_area.last()?;
                let target = u[0] * total;
                let i = cumulative_area
                    .partition_point(|&a| a <= target)
                    .min(triangles.len() - 1);
                let below = if i == 0 { 0.0 } else { cumulative_area[i - 1] };
                let width = cumulative_area[i] - below;
                // Reuse what is left of u[0] inside the chosen triangle's share.
                let u0 = ((target - below) / width).clamp(0.0, 1.0 - f64::EPSILON);
                let [a, b, c] = triangles[i];
                let (b0, b1) = uniform_triangle([u0, u[1]]);
                (
                    a * b0 + b * b1 + c * (1.0 - b0 - b1),
                    normals[i],
                    EmitterPoint::Triangle {
                        triangle: i,
                        b: [b0, b1],
                    },
                )
            }
        })
    }

    /// A point of the surface for `p` to aim at, its unit normal, and the pdf of choosing it
    /// with respect to solid angle at `p` (the area pdf converted by d² / |cos θ_light|);
    /// `None` if the sample sees the surface edge-on. Also where on the emitter the point lies.
    #[inline]
    fn sample_with_normal(&self, p: Vec3, u: [f64; 2]) -> Option<(Vec3, Vec3, f64, EmitterPoint)> {
        if let Emitter::Sphere { center, radius } = self {
            let to_center = *center - p;
            let d2 = to_center.length_squared();
            let r2 = radius * radius;
            if d2 > r2 * (1.0 + 1e-9) {
                // Outside: sample the cone of directions the sphere fills, uniformly in
                // solid angle (the visible cap, without wasted samples on the far side).
                let d = d2.sqrt();
                let cos_max = ((d2 - r2).max(0.0)).sqrt() / d;
                let local = uniform_cone(u, cos_max);
                let w = Frame::from_z(to_center / d).to_world(local);
                // Nearest intersection of p + s·w with the sphere (s ≥ 0).
                let b = w.dot(to_center);
                let disc = (r2 - (d2 - b * b)).max(0.0);
                let s = b - disc.sqrt();
                let q = p + w * s;
                let n = (q - *center) / *radius;
                return Some((q, n, uniform_cone_pdf(cos_max), EmitterPoint::World(q)));
            }
        }
        let (point, normal, at) = self.sample_point(u)?;
        let to = point - p;
        let d2 = to.length_squared();
        let cos_light = normal.dot(to).abs() / d2.sqrt();
        if cos_light <= 0.0 || d2 == 0.0 {
            return None;
        }
        Some((point, normal, d2 / (cos_light * self.area()), at))
    }
}

/// A light sample for the physically based integrators, which weigh it by multiple
/// importance sampling: the light's spectrum is applied by the caller, `scale` holds the
/// geometric factors, and the pdf comes separately.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the shaded point toward the light.
    pub wi: Vec3,
    pub distance: f64,
    /// The light's point, for aiming shadow rays; None at infinity.
    pub position: Option<Vec3>,
    /// The unit normal of an area light's surface at that point.
    pub normal: Option<Vec3>,
    /// What multiplies the light's radiance (or intensity): 1/d² and a spot's falloff for
    /// point lights, 0 for an area light seen from its dark side, 1 otherwise.
    pub scale: f64,
    /// Solid-angle pdf of the direction; 1 for delta lights.
    pub pdf: f64,
    /// The light is a point or a direction: no other strategy can find it.
    pub delta: bool,
    /// Radiance that varies (an environment map's by direction, a textured area light's over
    /// its surface), linear RGB, in place of the light's spectrum times `scale`.
    pub radiance: Option<Color>,
    /// Where the shadow ray stops, as a fraction of the way to `position`.
    pub shadow_end: f64,
}

/// Light arriving at a point.
#[derive(Clone, Copy, Debug)]
pub struct Incident {
    /// Unit direction from the point toward the light.
    pub wi: Vec3,
    /// Distance to the light; infinite for directional lights.
    pub distance: f64,
    /// The light's point on the ray's far end, for aiming shadow rays; None at infinity.
    pub position: Option<Vec3>,
    /// f(d)·I_L, with the spot's cone falloff applied; for an area light, the sample's
    /// estimate L_e / pdf (solid-angle pdf), so that averaging over samples gives ∫ L_e dω
    /// weighted by whatever the shading multiplies it by.
    pub intensity: Color,
    /// Where shadow rays stop, as a fraction of the way to `position`: just short of a
    /// point light; a little further short of a sampled surface, whose own intersection
    /// carries the rounding of its (single-precision) mesh.
    pub shadow_end: f64,
}

/// Shadow rays to a point light stop just short of it.
const POINT_SHADOW_END: f64 = 1.0 - 1e-9;
/// Shadow rays to an area light stop this far short of the sampled point; so do rays to
/// any surface point, which a mesh's single-precision test may find a little early.
pub(crate) const AREA_SHADOW_END: f64 = 1.0 - 1e-4;

impl Light {
    pub fn is_area(&self) -> bool {
        matches!(self, Light::Area { .. })
    }

    /// Shadow rays per shading point: a square number, 1 for lights that are points.
    pub fn samples(&self) -> u32 {
        match *self {
            Light::Area { samples, .. } => {
                let n = (samples.max(1) as f64).sqrt().ceil() as u32;
                n * n
            }
            _ => 1,
        }
    }

    /// A light sample for the physically based integrators, at point `p` with `u` ∈ [0, 1)².
    /// Point and spot lights follow the inverse-square law here (Whitted's attenuation is
    /// not applied: it is the Phong model's).
    pub fn sample_li(&self, p: Vec3, u: [f64; 2]) -> Option<LightSample> {
        match *self {
            Light::Area {
                ref shape,
                two_sided,
                ..
            } => {
                let (q, n, pdf, at) = shape.sample_with_normal(p, u)?;
                let to = q - p;
                let d = to.length();
                if !(pdf > 0.0 && pdf.is_finite() && d > 0.0) {
                    return None;
                }
                let wi = to / d;
                let scale = if two_sided || n.dot(-wi) > 0.0 {
                    1.0
                } else {
                    0.0
                };
                Some(LightSample {
                    wi,
                    distance: d,
                    position: Some(q),
                    normal: Some(n),
                    scale,
                    pdf,
                    delta: false,
                    radiance: self.textured_radiance(at).map(|c| c * scale),
                    shadow_end: AREA_SHADOW_END,
                })
            }
            Light::Infinite { .. } => {
                let wi = uniform_sphere(u);
                Some(LightSample {
                    wi,
                    distance: f64::INFINITY,
                    position: None,
                    normal: None,
                    scale: 1.0,
                    pdf: 1.0 / (4.0 * std::f64::consts::PI),
                    delta: false,
                    radiance: None,
                    shadow_end: f64::INFINITY,
                })
            }
            Light::Environment { ref map, .. } => {
                let (wi, pdf, [r, g, b]) = map.map.sample(u)?;
                Some(LightSample {
                    wi,
                    distance: f64::INFINITY,
                    position: None,
                    normal: None,
                    scale: 1.0,
                    pdf,
                    delta: false,
                    radiance: Some(Color::new(r, g, b)),
                    shadow_end: f64::INFINITY,
                })
            }
            Light::Point { position, .. }
            | Light::Spot { position, .. }
            | Light::Profiled { position, .. } => {
                let to = position - p;
                let d2 = to.length_squared();
                let d = d2.sqrt();
                if d == 0.0 {
                    return None;
                }
                let wi = to / d;
                let (factor, radiance) = self.point_emission(-wi);
                if factor <= 0.0 || radiance.is_some_and(Color::is_black) {
                    return None;
                }
                Some(LightSample {
                    wi,
                    distance: d,
                    position: Some(position),
                    normal: None,
                    scale: factor / d2,
                    pdf: 1.0,
                    delta: true,
                    radiance: radiance.map(|c| c / d2),
                    shadow_end: POINT_SHADOW_END,
                })
            }
            Light::Directional { direction, .. } => Some(LightSample {
                wi: -direction,
                distance: f64::INFINITY,
                position: None,
                normal: None,
                scale: 1.0,
                pdf: 1.0,
                delta: true,
                radiance: None,
                shadow_end: f64::INFINITY,
            }),
        }
    }

    /// The solid-angle pdf at `p` of [`Light::sample_li`] choosing the point `q` (unit normal
    /// `n`) of an area light; 0 for other lights.
    pub fn pdf_li(&self, p: Vec3, q: Vec3, n: Vec3) -> f64 {
        match self {
            Light::Area { shape, .. } => shape.pdf(p, q, n),
            _ => 0.0,
        }
    }

    /// The solid-angle pdf of [`Light::sample_li`] choosing the direction `wi` of a light at
    /// infinity; 0 for other lights.
    pub fn pdf_direction(&self, wi: Vec3) -> f64 {
        match self {
            Light::Infinite { .. } => 1.0 / (4.0 * std::f64::consts::PI),
            Light::Environment { map, .. } => map.map.pdf(wi),
            _ => 0.0,
        }
    }

    /// A light at infinity, which rays that leave the scene see.
    pub fn is_infinite(&self) -> bool {
        matches!(self, Light::Infinite { .. } | Light::Environment { .. })
    }

    /// Whether an area light's surface, with unit normal `n`, emits toward `w`.
    pub fn emits_toward(&self, n: Vec3, w: Vec3) -> bool {
        match self {
            Light::Area { two_sided, .. } => *two_sided || n.dot(w) > 0.0,
            _ => true,
        }
    }

    /// The light's power by the luminance of its RGB value, in a scene of bounding radius
    /// `radius` (for lights at infinity): what the power light sampler picks lights by.
    pub fn power(&self, radius: f64) -> f64 {
        use std::f64::consts::PI;
        match self {
            Light::Point { intensity, .. } => 4.0 * PI * intensity.luminance(),
            Light::Profiled {
                intensity, profile, ..
            } => 4.0 * PI * intensity.luminance() * profile.mean_luminance(),
            Light::Spot {
                intensity,
                cos_inner,
                cos_outer,
                ..
            } => 2.0 * PI * intensity.luminance() * (1.0 - 0.5 * (cos_inner + cos_outer)),
            Light::Area {
                shape,
                radiance,
                two_sided,
                texture,
                ..
            } => {
                let sides = if *two_sided { 2.0 } else { 1.0 };
                let mean = match texture {
                    Some(t) => *radiance * t.texture.average(),
                    None => *radiance,
                };
                PI * sides * shape.area() * mean.luminance()
            }
            Light::Directional { intensity, .. } => PI * radius * radius * intensity.luminance(),
            Light::Infinite { radiance } => 4.0 * PI * PI * radius * radius * radiance.luminance(),
            Light::Environment { map, .. } => map.map.power_estimate(radius),
        }
    }

    /// A textured area light's radiance at a point of its surface (linear RGB); `None` where
    /// the light's spectrum is its radiance everywhere.
    #[inline]
    fn textured_radiance(&self, at: EmitterPoint) -> Option<Color> {
        match self {
            Light::Area {
                radiance,
                texture: Some(t),
                ..
            } => Some(*radiance * t.at(at)),
            _ => None,
        }
    }

    /// A textured area light's radiance where a ray met its surface (linear RGB); `None`
    /// where the light's spectrum is its radiance everywhere.
    pub fn textured_radiance_at(&self, at: &crate::texture::TextureCoords) -> Option<Color> {
        match self {
            Light::Area {
                radiance,
                texture: Some(t),
                ..
            } => Some(*radiance * t.texture.evaluate(at)),
            _ => None,
        }
    }

    /// Replaces the light's RGB value (by that of the spectrum it was given as).
    pub fn set_rgb(&mut self, c: Color) {
        match self {
            Light::Point { intensity, .. }
            | Light::Spot { intensity, .. }
            | Light::Profiled { intensity, .. }
            | Light::Directional { intensity, .. } => *intensity = c,
            Light::Area { radiance, .. }
            | Light::Infinite { radiance }
            | Light::Environment { radiance, .. } => *radiance = c,
        }
    }

    /// The light's RGB value: intensity, radiance or irradiance, as it was given.
    pub fn rgb(&self) -> Color {
        match *self {
            Light::Point { intensity, .. }
            | Light::Spot { intensity, .. }
            | Light::Profiled { intensity, .. }
            | Light::Directional { intensity, .. } => intensity,
            Light::Area { radiance, .. }
            | Light::Infinite { radiance }
            | Light::Environment { radiance, .. } => radiance,
        }
    }

    /// What the light sends to point `p` along its sample `u` ∈ [0, 1)² (ignored by lights
    /// that are points), before any shadowing; `None` when nothing arrives.
    pub fn incident(&self, p: Vec3, u: [f64; 2]) -> Option<Incident> {
        match *self {
            // Not lights of Whitted's model: the path tracer's only.
            Light::Infinite { .. } | Light::Environment { .. } => None,
            Light::Area {
                ref shape,
                radiance,
                ..
            } => {
                let (point, _, pdf, at) = shape.sample_with_normal(p, u)?;
                let to = point - p;
                let d = to.length();
                let radiance = self.textured_radiance(at).unwrap_or(radiance);
                (pdf > 0.0 && pdf.is_finite() && d > 0.0).then(|| Incident {
                    wi: to / d,
                    distance: d,
                    position: Some(point),
                    intensity: radiance / pdf,
                    shadow_end: AREA_SHADOW_END,
                })
            }
            Light::Point {
                position,
                intensity,
                attenuation,
            } => {
                let to = position - p;
                let d = to.length();
                (d > 0.0).then(|| Incident {
                    wi: to / d,
                    distance: d,
                    position: Some(position),
                    intensity: intensity * attenuation.factor(d),
                    shadow_end: POINT_SHADOW_END,
                })
            }
            Light::Profiled {
                position,
                intensity,
                ..
            } => {
                let to = position - p;
                let d = to.length();
                if d == 0.0 {
                    return None;
                }
                let wi = to / d;
                let intensity = match self.point_emission(-wi) {
                    (_, Some(c)) => c,
                    (k, None) => intensity * k,
                };
                (!intensity.is_black()).then_some(Incident {
                    wi,
                    distance: d,
                    position: Some(position),
                    intensity,
                    shadow_end: POINT_SHADOW_END,
                })
            }
            Light::Directional {
                direction,
                intensity,
            } => Some(Incident {
                wi: -direction,
                distance: f64::INFINITY,
                position: None,
                intensity,
                shadow_end: f64::INFINITY,
            }),
            Light::Spot {
                position,
                direction,
                cos_inner,
                cos_outer,
                intensity,
                attenuation,
            } => {
                let to = position - p;
                let d = to.length();
                if d == 0.0 {
                    return None;
                }
                let wi = to / d;
                let cos = (-wi).dot(direction);
                let cone = smoothstep(cos_outer, cos_inner, cos);
                (cone > 0.0).then(|| Incident {
                    wi,
                    distance: d,
                    position: Some(position),
                    intensity: intensity * (attenuation.factor(d) * cone),
                    shadow_end: POINT_SHADOW_END,
                })
            }
        }
    }
}

/// 0 below `lo`, 1 above `hi`, a smooth cubic between.
fn smoothstep(lo: f64, hi: f64, x: f64) -> f64 {
    if hi <= lo {
        return if x >= hi { 1.0 } else { 0.0 };
    }
    let t = ((x - lo) / (hi - lo)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A placed shape's emitter covers the shape: a box's twelve triangles have its surface
    /// area and face outward; a sphere keeps its centre and radius under a uniform scale
    /// and is refused (left to its triangles' owner) under a non-uniform one.
    #[test]
    fn emitters_of_placed_shapes() {
        use crate::geometry::{Cuboid, Sphere};
        let cube = Shape::Cuboid(Cuboid::new(
            Vec3::new(-1.0, -2.0, -3.0),
            Vec3::new(1.0, 2.0, 3.0),
        ));
        let place = Transform::rotate(Vec3::new(1.0, 2.0, 3.0), 40.0)
            .unwrap()
            .after(&Transform::translate(Vec3::new(1.0, -2.0, 3.0)));
        let e = Emitter::of_shape(&cube, &place).unwrap();
        assert!((e.area() - 2.0 * (2.0 * 4.0 + 2.0 * 6.0 + 4.0 * 6.0)).abs() < 1e-9);
        let Emitter::Triangles { triangles, .. } = &e else {
            panic!("a box emits by its triangles")
        };
        assert_eq!(triangles.len(), 12);
        let centre = place.point(Vec3::ZERO);
        for t in triangles {
            let n = (t[1] - t[0]).cross(t[2] - t[0]);
            let c = (t[0] + t[1] + t[2]) * (1.0 / 3.0);
            assert!(n.dot(c - centre) > 0.0, "a face turned inward");
        }
        let ball = Shape::Sphere(Sphere::new(Vec3::new(1.0, 0.0, 0.0), 0.5));
        let grow = Transform::scale(Vec3::splat(2.0)).unwrap();
        match Emitter::of_shape(&ball, &grow) {
            Some(Emitter::Sphere { center, radius }) => {
                assert!((center - Vec3::new(2.0, 0.0, 0.0)).length() < 1e-12);
                assert!((radius - 1.0).abs() < 1e-12);
            }
            other => panic!("{other:?}"),
        }
        let squash = Transform::scale(Vec3::new(1.0, 2.0, 1.0)).unwrap();
        assert!(Emitter::of_shape(&ball, &squash).is_none());
    }

    #[test]
    fn point_light_falls_off_with_the_inverse_square() {
        let light = Light::Point {
            position: Vec3::ZERO,
            intensity: Color::WHITE,
            attenuation: Attenuation {
                constant: 0.0,
                linear: 0.0,
                quadratic: 1.0,
            },
        };
        let at = |d: f64| {
            light
                .incident(Vec3::new(d, 0.0, 0.0), [0.5; 2])
                .unwrap()
                .intensity
                .r
        };
        assert!((at(2.0) / at(4.0) - 4.0).abs() < 1e-12);
        assert!((at(3.0) - 1.0 / 9.0).abs() < 1e-15);
        // min(1, ·) keeps it finite up close.
        assert_eq!(at(0.5), 1.0);
    }

    #[test]
    fn spot_light_cone() {
        let light = Light::Spot {
            position: Vec3::ZERO,
            direction: -Vec3::Y,
            cos_inner: 20f64.to_radians().cos(),
            cos_outer: 30f64.to_radians().cos(),
            intensity: Color::WHITE,
            attenuation: Attenuation::default(),
        };
        let at = |deg: f64| {
            let th = deg.to_radians();
            light
                .incident(Vec3::new(th.sin(), -th.cos(), 0.0) * 5.0, [0.5; 2])
                .map_or(0.0, |i| i.intensity.r)
        };
        assert_eq!(at(10.0), 1.0);
        assert!(at(25.0) > 0.0 && at(25.0) < 1.0);
        assert_eq!(at(35.0), 0.0);
    }

    /// The solid-angle pdf an area light's samples claim (L_e / intensity with L_e = 1),
    /// checked by chi-square against the pdf computed independently from the geometry, for
    /// each emitter seen from the origin (seed 0x5EED0005, 10⁶ samples; the crate-wide
    /// significance of chi_square.rs); and `Emitter::pdf` of each sampled point, which MIS
    /// uses for points found by BSDF rays, equal to the sample's own pdf (to 10⁻⁹).
    mod chi_square_tests {
        use super::*;
        use crate::sampling::chi_square::SphericalBins;

        const SAMPLES: usize = 1_000_000;
        const SEED: u64 = 0x5EED0005;

        fn check(shape: Emitter, pdf: impl Fn(Vec3) -> f64, what: &str) {
            let emitter = shape.clone();
            let light = Light::Area {
                shape,
                radiance: Color::WHITE,
                samples: 1,
                two_sided: true,
                texture: None,
            };
            SphericalBins::about_z(0.3, [30, 60])
                .test(
                    SAMPLES,
                    SEED,
                    |u| {
                        let inc = light.incident(Vec3::ZERO, u).expect("a visible light");
                        // The pdf the sample claims must be the true one where it landed.
                        let claimed = 1.0 / inc.intensity.r;
                        let truth = pdf(inc.wi);
                        assert!(
                            (claimed / truth - 1.0).abs() < 1e-6,
                            "{what}: claimed {claimed}, true {truth}"
                        );
                        // What the path tracer's MIS asks of a point a BSDF ray found, and
                        // what light sampling hands it, agree.
                        let (q, n, sampled, _) = emitter.sample_with_normal(Vec3::ZERO, u).unwrap();
                        let asked = emitter.pdf(Vec3::ZERO, q, n);
                        assert!(
                            (asked / sampled - 1.0).abs() < 1e-9,
                            "{what}: pdf of the point {asked}, of its sample {sampled}"
                        );
                        let ls = light.sample_li(Vec3::ZERO, u).unwrap();
                        assert!((ls.pdf / sampled - 1.0).abs() < 1e-12 && !ls.delta);
                        inc.wi
                    },
                    &pdf,
                )
                .assert_accepted(what);
        }

        /// Solid-angle pdf of uniform area sampling of a planar patch hit along w at all.
        fn planar_pdf(
            w: Vec3,
            point: Vec3,
            normal: Vec3,
            area: f64,
            inside: impl Fn(Vec3) -> bool,
        ) -> f64 {
            let s = point.dot(normal) / w.dot(normal);
            if s.is_nan() || s <= 0.0 || !inside(w * s) {
                return 0.0;
            }
            s * s / (w.dot(normal).abs() * area)
        }

        #[test]
        fn chi_square_rectangle_light() {
            let (corner, eu, ev) = (
                Vec3::new(-1.0, -0.5, 2.0),
                Vec3::new(2.5, 0.0, 0.5),
                Vec3::new(0.0, 1.5, 0.0),
            );
            let normal = eu.cross(ev).normalized();
            let area = eu.cross(ev).length();
            check(
                Emitter::Rectangle {
                    corner,
                    edge_u: eu,
                    edge_v: ev,
                },
                |w| {
                    planar_pdf(w, corner, normal, area, |q| {
                        let d = q - corner;
                        let (a, b) = (d.dot(eu) / eu.dot(eu), d.dot(ev) / ev.dot(ev));
                        (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b)
                    })
                },
                "rectangle light",
            );
        }

        #[test]
        fn chi_square_disk_light() {
            let (center, normal, radius) = (
                Vec3::new(0.3, 0.2, 2.0),
                Vec3::new(0.2, 0.1, -1.0).normalized(),
                0.9,
            );
            check(
                Emitter::Disk {
                    center,
                    normal,
                    radius,
                },
                |w| {
                    planar_pdf(
                        w,
                        center,
                        normal,
                        std::f64::consts::PI * radius * radius,
                        |q| (q - center).length() <= radius,
                    )
                },
                "disk light",
            );
        }

        #[test]
        fn chi_square_sphere_light() {
            let (center, radius) = (Vec3::new(0.4, -0.2, 3.0), 1.2);
            let d = center.length();
            let cos_max = (1.0 - (radius / d).powi(2)).sqrt();
            check(
                Emitter::Sphere { center, radius },
                |w| {
                    if w.dot(center) / d >= cos_max {
                        1.0 / (2.0 * std::f64::consts::PI * (1.0 - cos_max))
                    } else {
                        0.0
                    }
                },
                "sphere light",
            );
        }

        /// Two triangles of different areas, picked in proportion to area.
        #[test]
        fn chi_square_triangle_mesh_light() {
            let triangles = vec![
                [
                    Vec3::new(-1.0, -1.0, 2.0),
                    Vec3::new(0.5, -1.0, 2.0),
                    Vec3::new(-1.0, 0.8, 2.5),
                ],
                [
                    Vec3::new(0.6, 0.0, 1.5),
                    Vec3::new(1.2, 0.0, 1.5),
                    Vec3::new(0.6, 0.5, 1.5),
                ],
            ];
            let shape = Emitter::triangles(triangles.clone()).unwrap();
            let total = shape.area();
            check(
                shape,
                |w| {
                    let mut pdf = 0.0;
                    for [a, b, c] in &triangles {
                        let n = (*b - *a).cross(*c - *a);
                        let s = a.dot(n) / w.dot(n);
                        if s <= 0.0 {
                            continue;
                        }
                        let q = w * s;
                        // Inside when q is on the inner side of all three edges.
                        let inside = [(*a, *b), (*b, *c), (*c, *a)]
                            .iter()
                            .all(|(p0, p1)| (*p1 - *p0).cross(q - *p0).dot(n) >= 0.0);
                        if inside {
                            pdf += s * s / (w.dot(n.normalized()).abs() * total);
                        }
                    }
                    pdf
                },
                "triangle mesh light",
            );
        }
    }
}
