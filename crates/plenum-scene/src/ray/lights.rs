//! The `.ray` format's `camera` and lights (`directional_light`, `point_light`,
//! `spot_light`, `ambient_light`).

use super::Parser;
use crate::diagnostics::SceneError;
use plenum_core::color::Color;
use plenum_core::light::{Attenuation, Light};
use plenum_core::math::Vec3;

impl<'s> Parser<'s> {
    pub(super) fn camera(&mut self) -> Result<(), SceneError> {
        const KNOWN: &[&str] = &[
            "position",
            "viewdir",
            "updir",
            "aspectratio",
            "fov",
            "quaternion",
            "quaternian",
            "focaldistance",
        ];
        self.punct('{')?;
        let mut c = self.builder.camera;
        let mut viewdir = c.look_at - c.position;
        let mut up = c.up;
        while !self.eat('}') {
            let (name, span) = self.word()?;
            match name.as_str() {
                "position" => c.position = self.field(Self::vec3)?,
                "viewdir" => viewdir = self.field(Self::vec3)?,
                "updir" => up = self.field(Self::vec3)?,
                "aspectratio" => {
                    let s = self.span();
                    let a = self.field(Self::number)?;
                    if a.is_nan() || a <= 0.0 {
                        return Err(self.error(s, "expected an aspect ratio > 0"));
                    }
                    self.aspect = a;
                }
                "fov" => {
                    let s = self.span();
                    let f = self.field(Self::number)?;
                    if !(f > 0.0 && f < 180.0) {
                        return Err(
                            self.error(s, "expected a field of view between 0 and 180 degrees")
                        );
                    }
                    c.fov_degrees = f;
                }
                "quaternion" | "quaternian" => {
                    let [r, i, j, k] = self.field(Self::tuple::<4>)?;
                    let rotate = |v: Vec3| quaternion_rotate([r, i, j, k], v);
                    viewdir = rotate(-Vec3::Z);
                    up = rotate(Vec3::Y);
                }
                _ => self.unknown_field(&name, span, KNOWN)?,
            }
        }
        if viewdir.length_squared() == 0.0 || up.cross(viewdir).length_squared() == 0.0 {
            return Err(self.error(
                self.tokens[self.pos - 1].1.clone(),
                "the camera's viewdir is zero or parallel to updir",
            ));
        }
        c.look_at = c.position + viewdir;
        c.up = up;
        self.builder.camera = c;
        Ok(())
    }

    pub(super) fn light(&mut self, kind: &str) -> Result<(), SceneError> {
        const KNOWN: &[&str] = &[
            "position",
            "direction",
            "color",
            "colour",
            "constant_attenuation_coeff",
            "linear_attenuation_coeff",
            "quadratic_attenuation_coeff",
        ];
        let start = self.tokens[self.pos - 1].1.clone();
        self.punct('{')?;
        let (mut position, mut direction, mut color) = (None, None, None);
        let mut coeffs = [None; 3];
        while !self.eat('}') {
            let (name, span) = self.word()?;
            match name.as_str() {
                "position" => position = Some(self.field(Self::vec3)?),
                "direction" => direction = Some(self.field(Self::vec3)?),
                "color" | "colour" => color = Some(self.field(Self::color)?),
                "constant_attenuation_coeff" => coeffs[0] = Some(self.field(Self::number)?),
                "linear_attenuation_coeff" => coeffs[1] = Some(self.field(Self::number)?),
                "quadratic_attenuation_coeff" => coeffs[2] = Some(self.field(Self::number)?),
                _ => self.unknown_field(&name, span, KNOWN)?,
            }
        }
        let color = color.unwrap_or(Color::WHITE);
        self.lights += 1;
        let n = self.lights;
        match kind {
            "ambient_light" => self.builder.ambient += color,
            "point_light" => {
                let position = position
                    .ok_or_else(|| self.error(start.clone(), "a point_light needs a position"))?;
                let attenuation = if coeffs.iter().all(Option::is_none) {
                    Attenuation::default()
                } else {
                    Attenuation {
                        constant: coeffs[0].unwrap_or(0.0),
                        linear: coeffs[1].unwrap_or(0.0),
                        quadratic: coeffs[2].unwrap_or(1.0),
                    }
                };
                self.builder.add_light(
                    format!("point_light {n}"),
                    Light::Point {
                        position,
                        intensity: color,
                        attenuation,
                    },
                );
            }
            _ => {
                let d = direction
                    .filter(|d| d.length_squared() > 0.0)
                    .ok_or_else(|| {
                        self.error(
                            start.clone(),
                            "a directional_light needs a non-zero direction",
                        )
                    })?;
                self.builder.add_light(
                    format!("directional_light {n}"),
                    Light::Directional {
                        direction: d.normalized(),
                        intensity: color,
                    },
                );
            }
        }
        Ok(())
    }

    pub(super) fn color(&mut self) -> Result<Color, SceneError> {
        let s = self.span();
        let [r, g, b] = self.tuple::<3>()?;
        if r < 0.0 || g < 0.0 || b < 0.0 {
            return Err(self.error(s, "expected colour components ≥ 0"));
        }
        Ok(Color::new(r, g, b))
    }
}

/// Rotates `v` by the unit quaternion (r, i, j, k).
fn quaternion_rotate(q: [f64; 4], v: Vec3) -> Vec3 {
    let len = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    let [w, x, y, z] = q.map(|c| c / len.max(f64::MIN_POSITIVE));
    let u = Vec3::new(x, y, z);
    v * (w * w - u.dot(u)) + u * (2.0 * u.dot(v)) + u.cross(v) * (2.0 * w)
}
