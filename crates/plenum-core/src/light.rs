//! Lights of the Whitted model. Ambient light is not among them: the scene keeps one
//! ambient colour I_a, the sum of the ambient lights its file declares.

use crate::color::Color;
use crate::math::Vec3;

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
    /// f(d)·I_L, with the spot's cone falloff applied.
    pub intensity: Color,
}

impl Light {
    /// What the light sends to point `p`, before any shadowing; `None` when nothing arrives.
    pub fn incident(&self, p: Vec3) -> Option<Incident> {
        match *self {
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
        let at = |d: f64| light.incident(Vec3::new(d, 0.0, 0.0)).unwrap().intensity.r;
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
                .incident(Vec3::new(th.sin(), -th.cos(), 0.0) * 5.0)
                .map_or(0.0, |i| i.intensity.r)
        };
        assert_eq!(at(10.0), 1.0);
        assert!(at(25.0) > 0.0 && at(25.0) < 1.0);
        assert_eq!(at(35.0), 0.0);
    }
}
