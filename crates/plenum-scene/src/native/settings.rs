//! The native format's `[render]` and `[camera]` tables: the render's defaults, and the camera
//! with its lens.

use super::Reader;
use crate::reader::{Fields, Result, Value};
use crate::RenderDefaults;
use plenum_core::camera::{CameraSettings, Lens};
use plenum_core::integrator::{ColorMode, IntegratorKind, MAX_DEPTH};
use plenum_core::light_sampler::LightSamplerKind;
use plenum_core::sampling::MAX_SPP;

impl<'s> Reader<'s> {
    pub(super) fn render(&mut self, v: &Value<'s>, d: &mut RenderDefaults) -> Result<()> {
        let f = self.src.table(
            v,
            "[render]",
            &[
                "spp",
                "sampler",
                "filter",
                "filter_radius",
                "max_depth",
                "min_weight",
                "exposure",
                "integrator",
                "color",
                "rr_depth",
                "light_sampler",
                "photons",
                "caustic_photons",
                "photon_nearest",
                "photon_radius",
                "gather_rays",
                "sppm_photons",
                "sppm_alpha",
            ],
        )?;
        // Each photon setting is checked as it is read, so an error points at its key.
        for key in [
            "photons",
            "caustic_photons",
            "photon_nearest",
            "photon_radius",
            "gather_rays",
            "sppm_photons",
            "sppm_alpha",
        ] {
            let Some(v) = f.get(key) else { continue };
            let p = &mut d.photon;
            match key {
                "photon_radius" => p.radius = f.non_negative_or(key, p.radius)?,
                "sppm_alpha" => p.alpha = f.number_or(key, p.alpha)?,
                _ => {
                    let n = f.count(key)?.unwrap_or(0);
                    match key {
                        "photons" => p.photons = n as u64,
                        "caustic_photons" => p.caustic_photons = n as u64,
                        "photon_nearest" => p.nearest = n,
                        "gather_rays" => p.gather_rays = n,
                        _ => p.sppm_photons = n as u64,
                    }
                }
            }
            p.check().map_err(|e| self.src.error(v.span(), e))?;
        }
        if let Some(v) = f.get("integrator") {
            let name = self.src.string(v)?;
            d.integrator = Some(IntegratorKind::from_name(name).ok_or_else(|| {
                let names: Vec<&str> = IntegratorKind::ALL.iter().map(|k| k.name()).collect();
                self.src
                    .error(v.span(), format!("unknown integrator `{name}`"))
                    .with_help(format!("expected one of: {}", names.join(", ")))
            })?);
        }
        if let Some(v) = f.get("color") {
            d.color = Some(match self.src.string(v)? {
                "spectral" => ColorMode::Spectral,
                "rgb" => ColorMode::Rgb,
                other => {
                    return Err(self
                        .src
                        .error(v.span(), format!("unknown colour mode `{other}`"))
                        .with_help("expected `spectral` or `rgb`"))
                }
            });
        }
        if let Some(n) = f.count("rr_depth")? {
            d.rr_depth = n;
        }
        if let Some(v) = f.get("light_sampler") {
            d.light_sampler = match self.src.string(v)? {
                "power" => LightSamplerKind::Power,
                "uniform" => LightSamplerKind::Uniform,
                other => {
                    return Err(self
                        .src
                        .error(v.span(), format!("unknown light sampler `{other}`"))
                        .with_help("expected `power` or `uniform`"))
                }
            };
        }
        if let Some(v) = f.get("sampler") {
            match self.src.string(v)? {
                "adaptive" => d.adaptive = true,
                name => {
                    d.sampler = name
                        .parse()
                        .map_err(|e: String| self.src.error(v.span(), e))?
                }
            }
        }
        if let Some(v) = f.get("filter") {
            d.filter = self
                .src
                .string(v)?
                .parse()
                .map_err(|e: String| self.src.error(v.span(), e))?;
        }
        if f.get("filter_radius").is_some() {
            d.filter_radius = Some(f.positive("filter_radius", None)?);
        }
        if let Some(spp) = f.count("spp")? {
            if spp == 0 || spp > MAX_SPP {
                return Err(self.src.error(
                    f.required("spp")?.span(),
                    format!("expected between 1 and {MAX_SPP} samples per pixel"),
                ));
            }
            d.spp = spp;
        }
        if let Some(depth) = f.count("max_depth")? {
            if depth > MAX_DEPTH {
                return Err(self.src.error(
                    f.required("max_depth")?.span(),
                    format!("expected a max_depth of at most {MAX_DEPTH}"),
                ));
            }
            d.max_depth = depth;
        }
        d.min_weight = f.non_negative_or("min_weight", d.min_weight)?;
        d.exposure = f.number_or("exposure", d.exposure)?;
        Ok(())
    }

    pub(super) fn camera(&mut self, v: &Value<'s>, d: &mut RenderDefaults) -> Result<()> {
        let f = self.src.table(
            v,
            "[camera]",
            &[
                "position",
                "look_at",
                "up",
                "fov",
                "resolution",
                "aperture",
                "f_number",
                "focal_length",
                "focus_distance",
                "blades",
                "blade_rotation",
                "shutter",
                "position_close",
                "look_at_close",
                "left_handed",
                "orthographic",
            ],
        )?;
        let c = CameraSettings::default();
        let position = f.vec3_or("position", c.position)?;
        let look_at = f.vec3_or("look_at", c.look_at)?;
        if (look_at - position).length_squared() == 0.0 {
            let span = f
                .get("look_at")
                .or(f.get("position"))
                .map_or(f.span.clone(), |v| v.span());
            return Err(self.src.error(
                span,
                "the camera looks at its own position: expected look_at ≠ position",
            ));
        }
        let up = f.direction("up", Some(c.up))?;
        if up.cross(look_at - position).length_squared() == 0.0 {
            let span = f.get("up").map_or(f.span.clone(), |v| v.span());
            return Err(self
                .src
                .error(span, "`up` is parallel to the viewing direction"));
        }
        let fov = f.number_or("fov", c.fov_degrees)?;
        if !(fov > 0.0 && fov < 180.0) {
            return Err(self.src.error(
                f.get("fov").map_or(f.span.clone(), |v| v.span()),
                format!("expected a field of view between 0 and 180 degrees, found {fov}"),
            ));
        }
        if let Some(r) = f.get("resolution") {
            let [w, h] = self.src.numbers::<2>(r, "[width, height] in pixels")?;
            if w < 1.0
                || h < 1.0
                || w.fract() != 0.0
                || h.fract() != 0.0
                || w * h > (1u64 << 28) as f64
            {
                return Err(self.src.error(
                    r.span(),
                    "expected a resolution of whole pixels ≥ 1, at most 2^28 in all",
                ));
            }
            d.width = w as u32;
            d.height = h as u32;
        }
        let lens = self.lens(&f, (look_at - position).length())?;
        let shutter = match f.get("shutter") {
            None => c.shutter,
            Some(v) => {
                let [open, close] = self.src.numbers::<2>(v, "[open, close] times")?;
                if close < open {
                    return Err(self.src.error(
                        v.span(),
                        format!("the shutter closes ({close}) before it opens ({open})"),
                    ));
                }
                [open, close]
            }
        };
        let motion = match (f.vec3("position_close")?, f.vec3("look_at_close")?) {
            (None, None) => None,
            (p, l) => {
                let (p, l) = (p.unwrap_or(position), l.unwrap_or(look_at));
                if (l - p).length_squared() == 0.0 || up.cross(l - p).length_squared() == 0.0 {
                    let span = f
                        .get("look_at_close")
                        .or(f.get("position_close"))
                        .map_or(f.span.clone(), |v| v.span());
                    return Err(self.src.error(
                        span,
                        "at shutter close the camera looks at its own position or along `up`",
                    ));
                }
                Some((p, l))
            }
        };
        // A parallel projection: the view's height in scene units, with neither a field of
        // view nor a lens (nothing for them to mean).
        let orthographic = match f.get("orthographic") {
            None => None,
            Some(v) => {
                let h = f.number_or("orthographic", 1.0)?;
                if !(h > 0.0 && h.is_finite()) {
                    return Err(self.src.error(
                        v.span(),
                        format!("expected the orthographic view's height in scene units, > 0, found {h}"),
                    ));
                }
                for key in [
                    "fov",
                    "aperture",
                    "f_number",
                    "focal_length",
                    "focus_distance",
                ] {
                    if let Some(k) = f.get(key) {
                        return Err(self.src.error(
                            k.span(),
                            format!("an orthographic camera has no `{key}`: its view is `orthographic` scene units high, its rays parallel"),
                        ));
                    }
                }
                Some(h)
            }
        };
        self.builder.camera = CameraSettings {
            position,
            look_at,
            up,
            fov_degrees: fov,
            lens,
            shutter,
            motion,
            left_handed: f.bool_or("left_handed", false)?,
            orthographic,
        };
        Ok(())
    }

    /// The thin lens: an aperture radius, or an f-number with a focal length (radius =
    /// focal length / 2N); focused at `focus_distance`, by default on `look_at`.
    fn lens(&self, f: &Fields<'_, 's>, look_distance: f64) -> Result<Lens> {
        let radius = match (f.get("aperture"), f.get("f_number")) {
            (Some(a), Some(_)) => {
                return Err(self
                    .src
                    .error(a.span(), "give either `aperture` or `f_number`, not both"))
            }
            (Some(_), None) => f.non_negative_or("aperture", 0.0)?,
            (None, Some(_)) => {
                let n = f.positive("f_number", None)?;
                let Some(_) = f.get("focal_length") else {
                    return Err(self.src.error(
                        f.required("f_number")?.span(),
                        "an f-number needs a `focal_length` (in scene units) to give an aperture",
                    ));
                };
                f.positive("focal_length", None)? / (2.0 * n)
            }
            (None, None) => {
                if let Some(v) = f.get("focal_length") {
                    return Err(self
                        .src
                        .error(v.span(), "`focal_length` is only used with `f_number`"));
                }
                0.0
            }
        };
        let blades = f.count("blades")?.unwrap_or(0);
        if blades == 1 || blades == 2 || blades > 64 {
            return Err(self.src.error(
                f.required("blades")?.span(),
                format!("expected 0 (a round aperture) or 3 to 64 blades, found {blades}"),
            ));
        }
        Ok(Lens {
            radius,
            focus_distance: f.positive("focus_distance", Some(look_distance))?,
            blades,
            rotation_degrees: f.number_or("blade_rotation", 0.0)?,
        })
    }
}
