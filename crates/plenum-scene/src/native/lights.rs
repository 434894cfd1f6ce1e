//! The native format's `[[lights]]`: point, spot, directional, area and ambient lights, the
//! environment, and their spectra, samples and attenuation.

use super::Reader;
use crate::reader::{Fields, Result, Value};
use plenum_core::color::Color;
use plenum_core::light::{Attenuation, Emitter, Light};
use plenum_core::math::Vec3;
use toml::de::DeValue;

impl<'s> Reader<'s> {
    pub(super) fn light(&mut self, index: usize, v: &Value<'s>) -> Result<()> {
        let kind = self.kind(
            v,
            "a light",
            &[
                "point",
                "directional",
                "spot",
                "ambient",
                "rectangle",
                "disk",
                "sphere",
                "infinite",
            ],
        )?;
        let what = format!("{kind} light");
        let name_of = |f: &Fields| -> Result<String> {
            Ok(f.string("name")?
                .map_or_else(|| format!("{kind} light {}", index + 1), str::to_string))
        };
        let intensity = |f: &Fields| -> Result<Color> {
            let c = f.get("color").map_or(Ok(Color::WHITE), |c| self.color(c))?;
            Ok(c * f.non_negative_or("intensity", 1.0)?)
        };
        match kind.as_str() {
            "point" => {
                let f = self.src.table(
                    v,
                    &what,
                    &[
                        "type",
                        "name",
                        "position",
                        "color",
                        "intensity",
                        "spectrum",
                        "attenuation",
                    ],
                )?;
                let light = Light::Point {
                    position: f.required_vec3("position")?,
                    intensity: intensity(&f)?,
                    attenuation: self.attenuation(&f)?,
                };
                self.builder.add_light(name_of(&f)?, light);
                self.light_spectrum(&f)?;
            }
            "directional" => {
                let f = self.src.table(
                    v,
                    &what,
                    &[
                        "type",
                        "name",
                        "direction",
                        "color",
                        "intensity",
                        "spectrum",
                    ],
                )?;
                let light = Light::Directional {
                    direction: f.direction("direction", None)?.normalized(),
                    intensity: intensity(&f)?,
                };
                self.builder.add_light(name_of(&f)?, light);
                self.light_spectrum(&f)?;
            }
            "spot" => {
                let f = self.src.table(
                    v,
                    &what,
                    &[
                        "type",
                        "name",
                        "position",
                        "direction",
                        "inner_angle",
                        "outer_angle",
                        "color",
                        "intensity",
                        "spectrum",
                        "attenuation",
                    ],
                )?;
                let outer = f.positive("outer_angle", Some(30.0))?;
                let inner = f.number_or("inner_angle", outer.min(20.0))?;
                if !(0.0..=outer).contains(&inner) || outer > 180.0 {
                    let span = f
                        .get("inner_angle")
                        .or(f.get("outer_angle"))
                        .map_or(f.span.clone(), |v| v.span());
                    return Err(self.src.error(span, format!("expected 0 ≤ inner_angle ≤ outer_angle ≤ 180 degrees, found {inner} and {outer}")));
                }
                let light = Light::Spot {
                    position: f.required_vec3("position")?,
                    direction: f.direction("direction", None)?.normalized(),
                    cos_inner: inner.to_radians().cos(),
                    cos_outer: outer.to_radians().cos(),
                    intensity: intensity(&f)?,
                    attenuation: self.attenuation(&f)?,
                };
                self.builder.add_light(name_of(&f)?, light);
                self.light_spectrum(&f)?;
            }
            "rectangle" | "disk" | "sphere" => {
                let shape_keys: &[&str] = match kind.as_str() {
                    "rectangle" => &["corner", "edge_u", "edge_v"],
                    "disk" => &["center", "normal", "radius"],
                    _ => &["center", "radius"],
                };
                let keys: Vec<&str> = [
                    "type",
                    "name",
                    "color",
                    "intensity",
                    "spectrum",
                    "samples",
                    "two_sided",
                ]
                .into_iter()
                .chain(shape_keys.iter().copied())
                .collect();
                let f = self.src.table(v, &what, &keys)?;
                let emitter = match kind.as_str() {
                    "rectangle" => {
                        let (edge_u, edge_v) =
                            (f.required_vec3("edge_u")?, f.required_vec3("edge_v")?);
                        if edge_u.cross(edge_v).length_squared() == 0.0 {
                            return Err(self.src.error(
                                f.required("edge_v")?.span(),
                                "the rectangle's edges are parallel: it has no area",
                            ));
                        }
                        Emitter::Rectangle {
                            corner: f.required_vec3("corner")?,
                            edge_u,
                            edge_v,
                        }
                    }
                    "disk" => Emitter::Disk {
                        center: f.required_vec3("center")?,
                        normal: f.direction("normal", None)?.normalized(),
                        radius: f.positive("radius", None)?,
                    },
                    _ => Emitter::Sphere {
                        center: f.required_vec3("center")?,
                        radius: f.positive("radius", None)?,
                    },
                };
                let samples = self.light_samples(&f, "samples")?;
                let radiance = intensity(&f)?;
                self.builder
                    .add_area_light(name_of(&f)?, emitter, radiance, samples);
                if !f.bool_or("two_sided", true)? {
                    self.builder.set_last_light_one_sided();
                }
                self.light_spectrum(&f)?;
            }
            "infinite" => {
                let f = self.src.table(
                    v,
                    &what,
                    &[
                        "type",
                        "name",
                        "color",
                        "intensity",
                        "spectrum",
                        "file",
                        "layout",
                        "up",
                        "axes",
                    ],
                )?;
                if let Some(file) = f.get("file") {
                    for key in ["color", "spectrum"] {
                        if let Some(c) = f.get(key) {
                            return Err(self.src.error(
                                c.span(),
                                format!(
                                    "an environment map gives the light's radiance: drop `{key}`"
                                ),
                            ));
                        }
                    }
                    let light = self.environment(&f, file)?;
                    self.builder.add_light(name_of(&f)?, light);
                } else {
                    let light = Light::Infinite {
                        radiance: intensity(&f)?,
                    };
                    self.builder.add_light(name_of(&f)?, light);
                    self.light_spectrum(&f)?;
                }
            }
            _ => {
                let f = self
                    .src
                    .table(v, &what, &["type", "name", "color", "intensity"])?;
                self.builder.ambient += intensity(&f)?;
            }
        }
        Ok(())
    }

    /// An emitter's radiance: an RGB colour, or a spectrum (whose RGB value is then worked
    /// out by the scene); times `scale`.
    pub(super) fn emission(
        &self,
        v: &Value<'s>,
        scale: f64,
    ) -> Result<(Color, Option<plenum_spectrum::Spectrum>)> {
        match v.get_ref() {
            DeValue::String(_) | DeValue::Table(_) => {
                let s = self.spectrum(v)?;
                let [r, g, b] = s.to_rgb_illuminant();
                Ok((Color::new(r, g, b) * scale, Some(s)))
            }
            _ => Ok((self.non_negative(v, self.color(v)?)? * scale, None)),
        }
    }

    /// An infinite light from an environment image (`file`: EXR, HDR, PFM, PNG or JPEG), in
    /// the latitude–longitude layout or pbrt-v4's equal-area square (`layout`), its pole
    /// along `up` (default +y), its radiance times `intensity`.
    fn environment(&self, f: &Fields<'_, 's>, file: &Value<'s>) -> Result<Light> {
        use plenum_core::environment::{EnvironmentLayout, EnvironmentMap};
        let path = self.base_dir.join(self.src.string(file)?);
        let image = plenum_image::read_float_image(&path)
            .map_err(|e| self.src.error(file.span(), e.to_string()))?;
        let layout = match f.get("layout") {
            None => EnvironmentLayout::LatLong,
            Some(l) => match self.src.string(l)? {
                "latlong" => EnvironmentLayout::LatLong,
                "latlong-poles" => EnvironmentLayout::LatLongPoles,
                "equalarea" => EnvironmentLayout::EqualArea,
                other => {
                    return Err(self
                        .src
                        .error(l.span(), format!("unknown layout `{other}`"))
                        .with_help("expected `latlong`, `latlong-poles` or `equalarea`"))
                }
            },
        };
        let scale = f.non_negative_or("intensity", 1.0)?;
        let frame = match f.get("axes") {
            None => {
                let up = f.direction("up", Some(Vec3::Y))?.normalized();
                plenum_core::sampling::Frame::from_z(up)
            }
            Some(a) => {
                if let Some(u) = f.get("up") {
                    return Err(self
                        .src
                        .error(u.span(), "give either `up` or `axes`, not both"));
                }
                let rows = self.points(a)?;
                let unit = |v: Vec3| (v.length() - 1.0).abs() < 1e-6;
                let ok = rows.len() == 3
                    && rows.iter().all(|v| unit(*v))
                    && rows[0].dot(rows[1]).abs() < 1e-6
                    && rows[1].dot(rows[2]).abs() < 1e-6
                    && rows[0].dot(rows[2]).abs() < 1e-6;
                if !ok {
                    return Err(self.src.error(
                        a.span(),
                        "expected three orthonormal axes [[x], [y], [z]] (z the pole, φ from x toward y)",
                    ));
                }
                plenum_core::sampling::Frame {
                    x: rows[0],
                    y: rows[1],
                    z: rows[2],
                }
            }
        };
        let map = EnvironmentMap::new(
            image.width as usize,
            image.height as usize,
            image.pixels,
            layout,
            frame,
            scale,
        )
        .map_err(|e| self.src.error(file.span(), e))?;
        let [r, g, b] = map.average();
        Ok(Light::Environment {
            map: plenum_core::light::EnvironmentLight {
                map: std::sync::Arc::new(map),
                file: path.display().to_string(),
                scale,
            },
            radiance: Color::new(r, g, b),
        })
    }

    /// A light's `spectrum`, which replaces its `color` (times its `intensity`).
    fn light_spectrum(&mut self, f: &Fields<'_, 's>) -> Result<()> {
        if let Some(v) = f.get("spectrum") {
            if let Some(c) = f.get("color") {
                return Err(self
                    .src
                    .error(c.span(), "give either `color` or `spectrum`, not both"));
            }
            let s = self.spectrum(v)?;
            let scale = f.non_negative_or("intensity", 1.0)?;
            self.builder.set_last_light_spectrum(s, scale);
        }
        Ok(())
    }

    /// Shadow rays per shading point for an area light: 1 to 1024, 1 by default (more
    /// pixel samples smooth the penumbra just as well).
    pub(super) fn light_samples(&self, f: &Fields<'_, 's>, key: &str) -> Result<u32> {
        let n = f.count(key)?.unwrap_or(1);
        if n == 0 || n > 1024 {
            return Err(self.src.error(
                f.required(key)?.span(),
                format!("expected between 1 and 1024 shadow rays per point, found {n}"),
            ));
        }
        Ok(n)
    }

    fn attenuation(&self, f: &Fields<'_, 's>) -> Result<Attenuation> {
        let Some(v) = f.get("attenuation") else {
            return Ok(Attenuation::default());
        };
        let [a, b, c] = self
            .src
            .numbers::<3>(v, "[constant, linear, quadratic] coefficients")?;
        if a < 0.0 || b < 0.0 || c < 0.0 || a + b + c == 0.0 {
            return Err(self.src.error(
                v.span(),
                "expected attenuation coefficients ≥ 0, not all zero",
            ));
        }
        Ok(Attenuation {
            constant: a,
            linear: b,
            quadratic: c,
        })
    }
}
