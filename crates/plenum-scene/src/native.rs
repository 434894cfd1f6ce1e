//! Plenum's native scene format: TOML, documented field by field in docs/scene-format.md.

use crate::diagnostics::{did_you_mean, SceneError};
use crate::reader::{Fields, Result, Source, Value};
use crate::{obj, ply, RenderDefaults};
use plenum_core::camera::{CameraSettings, Lens};
use plenum_core::color::Color;
use plenum_core::geometry::{
    Cone, Cuboid, Cylinder, Disk, Plane, Polygon, Polyhedron, Shape, Sphere, TriangleMesh,
};
use plenum_core::integrator::{ColorMode, IntegratorKind, MAX_DEPTH};
use plenum_core::light::{Attenuation, Emitter, Light};
use plenum_core::light_sampler::LightSamplerKind;
use plenum_core::material::PhongMaterial;
use plenum_core::math::{Matrix4, Transform, Vec3};
use plenum_core::sampling::MAX_SPP;
use plenum_core::scene::{MaterialId, SceneBuilder};
use plenum_core::texture::{ImageTexture, Texture};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use toml::de::{DeTable, DeValue};

const TOP_LEVEL: &[&str] = &[
    "background",
    "render",
    "camera",
    "materials",
    "meshes",
    "lights",
    "objects",
];
mod physical;

const COMMON: [&str; 5] = ["type", "name", "material", "transform", "transform_close"];

/// Parses a native scene. `base_dir` resolves relative paths (meshes, textures).
/// Also returns warnings: statements of referenced mesh files that were read past.
pub fn parse(
    path: &Path,
    text: &str,
    base_dir: &Path,
) -> Result<(SceneBuilder, RenderDefaults, Vec<String>)> {
    let doc = DeTable::parse(text).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        SceneError::at(path, text, span, e.message().trim().to_string())
    })?;
    let src = Source { path, text };
    let top = Fields::new(src, doc.get_ref(), doc.span(), "the scene", TOP_LEVEL)?;
    let mut reader = Reader {
        src,
        base_dir: base_dir.to_path_buf(),
        builder: SceneBuilder::default(),
        materials: HashMap::new(),
        meshes: HashMap::new(),
        warnings: Vec::new(),
    };
    if let Some(v) = top.get("background") {
        reader.builder.background = reader.color(v)?;
    }
    let mut defaults = RenderDefaults::default();
    if let Some(v) = top.get("render") {
        reader.render(v, &mut defaults)?;
    }
    if let Some(v) = top.get("camera") {
        reader.camera(v, &mut defaults)?;
    }
    if let Some(v) = top.get("materials") {
        let DeValue::Table(t) = v.get_ref() else {
            return Err(src.error(
                v.span(),
                "expected a table of named materials: [materials.NAME]",
            ));
        };
        for (name, value) in t.iter() {
            reader.material(name.get_ref(), value)?;
        }
    }
    if let Some(v) = top.get("meshes") {
        let DeValue::Table(t) = v.get_ref() else {
            return Err(src.error(v.span(), "expected a table of named meshes: [meshes.NAME]"));
        };
        for (name, value) in t.iter() {
            let f = src.table(
                value,
                &format!("mesh `{}`", name.get_ref()),
                &["file", "positions", "indices", "normals", "uvs"],
            )?;
            let mesh = reader.mesh_data(&f)?;
            reader.meshes.insert(name.get_ref().to_string(), mesh);
        }
    }
    if let Some(v) = top.get("lights") {
        for (i, light) in src
            .array(v, "an array of lights: [[lights]]")?
            .iter()
            .enumerate()
        {
            reader.light(i, light)?;
        }
    }
    if let Some(v) = top.get("objects") {
        for (i, object) in src
            .array(v, "an array of objects: [[objects]]")?
            .iter()
            .enumerate()
        {
            reader.object(i, object)?;
        }
    }
    Ok((reader.builder, defaults, reader.warnings))
}

struct Reader<'s> {
    src: Source<'s>,
    base_dir: PathBuf,
    builder: SceneBuilder,
    materials: HashMap<String, MaterialId>,
    meshes: HashMap<String, Arc<TriangleMesh>>,
    warnings: Vec<String>,
}

impl<'s> Reader<'s> {
    fn render(&mut self, v: &Value<'s>, d: &mut RenderDefaults) -> Result<()> {
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

    fn camera(&mut self, v: &Value<'s>, d: &mut RenderDefaults) -> Result<()> {
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
        self.builder.camera = CameraSettings {
            position,
            look_at,
            up,
            fov_degrees: fov,
            lens,
            shutter,
            motion,
            left_handed: f.bool_or("left_handed", false)?,
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

    /// A colour: `[r, g, b]`, a grey level, or a texture table.
    fn color(&self, v: &Value<'s>) -> Result<Color> {
        match v.get_ref() {
            DeValue::Integer(_) | DeValue::Float(_) => {
                let g = self.src.number(v)?;
                self.non_negative(v, Color::gray(g))
            }
            _ => {
                let c = self
                    .src
                    .numbers::<3>(v, "a colour: [r, g, b] or a number")?;
                self.non_negative(v, Color::new(c[0], c[1], c[2]))
            }
        }
    }

    fn non_negative(&self, v: &Value<'s>, c: Color) -> Result<Color> {
        if c.r < 0.0 || c.g < 0.0 || c.b < 0.0 {
            Err(self.src.error(v.span(), "expected colour components ≥ 0"))
        } else {
            Ok(c)
        }
    }

    fn texture(&self, v: &Value<'s>) -> Result<Texture> {
        let DeValue::Table(_) = v.get_ref() else {
            return Ok(Texture::Constant(self.color(v)?));
        };
        let kind = {
            let f = self
                .src
                .table(v, "a texture", &["texture", "even", "odd", "scale", "file"])?;
            let k = f.required("texture")?;
            (self.src.string(k)?.to_string(), k.span())
        };
        match kind.0.as_str() {
            "checker" | "checker3d" => {
                let f =
                    self.src
                        .table(v, "a checker texture", &["texture", "even", "odd", "scale"])?;
                let even = f.get("even").map_or(Ok(Color::WHITE), |c| self.color(c))?;
                let odd = f.get("odd").map_or(Ok(Color::BLACK), |c| self.color(c))?;
                let scale = f.positive("scale", Some(1.0))?;
                Ok(if kind.0 == "checker" {
                    Texture::Checker2d { even, odd, scale }
                } else {
                    Texture::Checker3d { even, odd, scale }
                })
            }
            "image" => {
                let f = self
                    .src
                    .table(v, "an image texture", &["texture", "file", "scale"])?;
                let file = f.required("file")?;
                let path = self.base_dir.join(self.src.string(file)?);
                let texels = plenum_image::read_texture(&path)
                    .map_err(|e| self.src.error(file.span(), e.to_string()))?;
                let scale = match f.get("scale") {
                    None => [1.0, 1.0],
                    Some(s) => {
                        let r = self.src.numbers::<2>(s, "[u, v] repeats")?;
                        if r[0] <= 0.0 || r[1] <= 0.0 {
                            return Err(self.src.error(s.span(), "expected repeats > 0"));
                        }
                        r
                    }
                };
                let (width, height) = (texels.width, texels.height);
                let texels = texels
                    .rgb
                    .iter()
                    .map(|p| Color::new(p[0] as f64, p[1] as f64, p[2] as f64))
                    .collect();
                let image = ImageTexture::new(width, height, texels, scale)
                    .ok_or_else(|| self.src.error(file.span(), "the image is empty"))?;
                Ok(Texture::Image(Arc::new(image)))
            }
            other => {
                let e = self.src.error(kind.1, format!("unknown texture `{other}`"));
                Err(
                    match did_you_mean(other, ["checker", "checker3d", "image"]) {
                        Some(s) => e.with_help(format!("did you mean `{s}`?")),
                        None => e.with_help("expected one of: checker, checker3d, image"),
                    },
                )
            }
        }
    }

    fn material(&mut self, name: &str, v: &Value<'s>) -> Result<()> {
        if let DeValue::Table(t) = v.get_ref() {
            if t.get("type").is_some() {
                let kind = self.kind(v, &format!("material `{name}`"), physical::MATERIAL_TYPES)?;
                if let Some(m) = self.physical_material(name, &kind, v)? {
                    let two_sided = match t.get("two_sided") {
                        Some(b) => match b.get_ref() {
                            DeValue::Boolean(b) => *b,
                            _ => return Err(self.src.error(b.span(), "expected true or false")),
                        },
                        None => true,
                    };
                    let id = self.builder.add_material(name, m);
                    if !two_sided {
                        self.builder.set_one_sided(id);
                    }
                    self.materials.insert(name.to_string(), id);
                    return Ok(());
                }
            }
        }
        const FIELDS: &[&str] = &[
            "type",
            "emissive",
            "ambient",
            "diffuse",
            "specular",
            "shininess",
            "reflective",
            "transmissive",
            "ior",
            "fresnel",
            "gloss",
        ];
        let f = self.src.table(v, &format!("material `{name}`"), FIELDS)?;
        let d = PhongMaterial::default();
        let tex = |key: &str, default: Texture| f.get(key).map_or(Ok(default), |v| self.texture(v));
        let fresnel = f.bool_or("fresnel", d.fresnel)?;
        // With Fresnel weighting, k_r is a tint: white unless given.
        let reflective_default = if fresnel { Color::WHITE } else { Color::BLACK };
        let diffuse = tex("diffuse", d.diffuse.clone())?;
        let m = PhongMaterial {
            emissive: tex("emissive", d.emissive.clone())?,
            // Ambient light lights a surface in its own colour unless told otherwise.
            ambient: tex("ambient", diffuse.clone())?,
            diffuse,
            specular: tex("specular", d.specular.clone())?,
            shininess: match f.get("shininess") {
                None => d.shininess,
                Some(s) => {
                    let n = self.src.number(s)?;
                    if n < 0.0 {
                        return Err(self
                            .src
                            .error(s.span(), format!("expected a shininess ≥ 0, found {n}")));
                    }
                    n
                }
            },
            reflective: tex("reflective", Texture::Constant(reflective_default))?,
            transmissive: tex("transmissive", d.transmissive.clone())?,
            ior: f.positive("ior", Some(1.0))?,
            fresnel,
            gloss: match f.get("gloss") {
                None => None,
                Some(_) => Some(f.positive("gloss", None)?),
            },
        };
        // Whitted's coefficients are fractions of the light arriving: above 1 a surface
        // returns more than it receives, and recursion multiplies the excess.
        for (key, t) in [
            ("diffuse", &m.diffuse),
            ("reflective", &m.reflective),
            ("transmissive", &m.transmissive),
        ] {
            if let Some(v) = f.get(key).filter(|_| t.max_component() > 1.0) {
                let e = self.src.error(
                    v.span(),
                    format!("{key} {} exceeds 1: the surface gives out more light than reaches it (energy is not conserved)", t.max_component()),
                );
                self.warnings.push(e.as_warning());
            }
        }
        let id = self.builder.add_material(name, m);
        self.materials.insert(name.to_string(), id);
        Ok(())
    }

    fn light(&mut self, index: usize, v: &Value<'s>) -> Result<()> {
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
    fn emission(
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
    fn light_samples(&self, f: &Fields<'_, 's>, key: &str) -> Result<u32> {
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

    /// The `type` of a light or object, checked against the known kinds.
    fn kind(&self, v: &Value<'s>, what: &str, kinds: &[&'static str]) -> Result<String> {
        let DeValue::Table(t) = v.get_ref() else {
            return Err(self
                .src
                .error(v.span(), format!("expected a table for {what}")));
        };
        let Some(k) = t.get("type") else {
            let start = v.span().start;
            let end = self.src.text[start..]
                .find('\n')
                .map_or(self.src.text.len(), |i| start + i);
            return Err(self
                .src
                .error(start..end, format!("missing field `type` in {what}"))
                .with_help(format!("expected one of: {}", kinds.join(", "))));
        };
        let kind = self.src.string(k)?;
        if kinds.contains(&kind) {
            return Ok(kind.to_string());
        }
        let e = self
            .src
            .error(k.span(), format!("unknown type `{kind}` for {what}"));
        Err(match did_you_mean(kind, kinds.iter().copied()) {
            Some(s) => e.with_help(format!("did you mean `{s}`?")),
            None => e.with_help(format!("expected one of: {}", kinds.join(", "))),
        })
    }

    fn object(&mut self, index: usize, v: &Value<'s>) -> Result<()> {
        const KINDS: &[&str] = &[
            "sphere",
            "plane",
            "disk",
            "box",
            "cylinder",
            "cone",
            "polygon",
            "polyhedron",
            "mesh",
        ];
        let kind = self.kind(v, "an object", KINDS)?;
        let fields: &[&'static str] = match kind.as_str() {
            "sphere" => &["center", "radius", "inside_only"],
            "plane" => &["point", "normal"],
            "disk" => &["center", "normal", "radius"],
            "box" => &["min", "max"],
            "cylinder" => &["base", "top", "radius", "capped"],
            "cone" => &[
                "base",
                "top",
                "radius",
                "top_radius",
                "capped",
                "inside_only",
            ],
            "polygon" => &["vertices"],
            "polyhedron" => &["vertices", "faces"],
            _ => &[
                "mesh",
                "file",
                "positions",
                "indices",
                "normals",
                "uvs",
                "vertex_materials",
            ],
        };
        const EMISSION: [&str; 4] = ["emission", "emission_scale", "two_sided", "light_samples"];
        let allowed: Vec<&'static str> = COMMON
            .iter()
            .chain(fields)
            .chain(&EMISSION)
            .copied()
            .collect();
        let f = self.src.table(v, &kind, &allowed)?;
        let (shape, frame) = self.shape(&kind, &f)?;
        let placement = match f.get("transform") {
            Some(t) => self.transform(t)?,
            None => Transform::IDENTITY,
        };
        let material = self.material_ref(f.get("material"))?;
        let name = f
            .string("name")?
            .map_or_else(|| format!("{kind} {}", index + 1), str::to_string);
        let to_world = placement.after(&frame);
        let close = match f.get("transform_close") {
            Some(t) => Some(self.transform(t)?.after(&frame)),
            None => None,
        };
        if let Some(e) = f.get("emission") {
            if f.get("vertex_materials").is_some() {
                return Err(self.src.error(
                    e.span(),
                    "an emitting object has one material: drop `vertex_materials`",
                ));
            }
            if close.is_some() {
                return Err(self.src.error(
                    e.span(),
                    "an emitting object cannot move (`transform_close`)",
                ));
            }
            let scale = f.non_negative_or("emission_scale", 1.0)?;
            let (radiance, spectrum) = self.emission(e, scale)?;
            let samples = self.light_samples(&f, "light_samples")?;
            let two_sided = f.bool_or("two_sided", true)?;
            // Without a material of its own the object only shows its light.
            let material = match f.get("material") {
                Some(_) => material,
                None => self.builder.add_material(
                    format!("{name} (emitter)"),
                    plenum_core::material::Material::emitter(radiance),
                ),
            };
            let what = f.required("emission")?.span();
            let added = self.builder.add_emissive_object(
                name, shape, to_world, material, radiance, two_sided, samples,
            );
            // A mesh without area is placed, dark, as before; other shapes cannot be sampled.
            if !added && kind != "mesh" {
                return Err(self.src.error(
                    what,
                    format!("a {kind} cannot be an area light: use a mesh, sphere, disk, polygon, box or polyhedron"),
                ));
            }
            if let Some(s) = spectrum {
                self.builder.set_last_light_spectrum(s, scale);
            }
            return Ok(());
        }
        match (f.get("vertex_materials"), shape) {
            (Some(list), Shape::Mesh(mesh)) => {
                let items = self
                    .src
                    .array(list, "an array of material names, one per vertex")?;
                if items.len() != mesh.vertex_count() {
                    return Err(self.src.error(
                        list.span(),
                        format!(
                            "{} vertex materials for {} vertices: give one per vertex",
                            items.len(),
                            mesh.vertex_count()
                        ),
                    ));
                }
                let ids = items
                    .iter()
                    .map(|v| self.material_ref(Some(v)))
                    .collect::<Result<Vec<_>>>()?;
                self.builder
                    .add_mesh_with_vertex_materials(name, mesh, to_world, ids);
            }
            (_, shape) => self.builder.add_object(name, shape, to_world, material),
        }
        if let Some(close) = close {
            self.builder.set_last_motion(close);
        }
        Ok(())
    }

    /// The material a `material` value names; none given: the default matte grey.
    fn material_ref(&mut self, value: Option<&Value<'s>>) -> Result<MaterialId> {
        let Some(v) = value else {
            if let Some(&id) = self.materials.get("default") {
                return Ok(id);
            }
            let id = self
                .builder
                .add_material("default", PhongMaterial::default());
            self.materials.insert("default".into(), id);
            return Ok(id);
        };
        let name = self.src.string(v)?;
        if let Some(&id) = self.materials.get(name) {
            return Ok(id);
        }
        let e = self
            .src
            .error(v.span(), format!("no material named `{name}` is defined"));
        let mut known: Vec<&str> = self.materials.keys().map(String::as_str).collect();
        known.sort();
        Err(match did_you_mean(name, known.iter().copied()) {
            Some(s) => e.with_help(format!("did you mean `{s}`?")),
            None if known.is_empty() => e.with_help("define it in a [materials.NAME] table"),
            None => e.with_help(format!("defined materials: {}", known.join(", "))),
        })
    }

    /// The shape in its own coordinates and the frame that places it (identity for most).
    fn shape(&mut self, kind: &str, f: &Fields<'_, 's>) -> Result<(Shape, Transform)> {
        let src = self.src;
        let shape = match kind {
            "sphere" => {
                let mut sphere = Sphere::new(
                    f.vec3_or("center", Vec3::ZERO)?,
                    f.positive("radius", None)?,
                );
                sphere.inside_only = f.bool_or("inside_only", false)?;
                Shape::Sphere(sphere)
            }
            "plane" => Shape::Plane(Plane::new(
                f.vec3_or("point", Vec3::ZERO)?,
                f.direction("normal", None)?,
            )),
            "disk" => Shape::Disk(Disk::new(
                f.vec3_or("center", Vec3::ZERO)?,
                f.direction("normal", None)?,
                f.positive("radius", None)?,
            )),
            "box" => {
                let (min, max) = (f.required_vec3("min")?, f.required_vec3("max")?);
                if min.x >= max.x || min.y >= max.y || min.z >= max.z {
                    return Err(src.error(
                        f.required("max")?.span(),
                        "expected max greater than min on every axis",
                    ));
                }
                Shape::Cuboid(Cuboid::new(min, max))
            }
            "cylinder" | "cone" => {
                let base = f.vec3_or("base", Vec3::ZERO)?;
                let top = f.vec3_or("top", Vec3::Y)?;
                let axis = top - base;
                let height = axis.length();
                let z = axis / height;
                let (x, y) = z.orthonormal_basis();
                let frame = Transform::frame(base, x, y, z)
                    .filter(|_| height > 0.0 && height.is_finite() && z.is_finite());
                let Some(frame) = frame else {
                    let span = f.get("top").map_or(f.span.clone(), |v| v.span());
                    return Err(src.error(
                        span,
                        "expected `top` apart from `base` by a finite, non-zero distance",
                    ));
                };
                let radius = f.positive("radius", None)?;
                let capped = f.bool_or("capped", true)?;
                let shape = if kind == "cylinder" {
                    Shape::Cylinder(Cylinder::new(radius, height, capped))
                } else {
                    let top_radius = f.number_or("top_radius", 0.0)?;
                    if top_radius < 0.0 {
                        return Err(src.error(
                            f.required("top_radius")?.span(),
                            format!("expected a top_radius ≥ 0, found {top_radius}"),
                        ));
                    }
                    Shape::Cone(Cone {
                        radius0: radius,
                        radius1: top_radius,
                        height,
                        capped,
                        inside_only: f.bool_or("inside_only", false)?,
                    })
                };
                return Ok((shape, frame));
            }
            "polygon" => {
                let v = f.required("vertices")?;
                let vertices = self.points(v)?;
                Shape::Polygon(Box::new(
                    Polygon::new(vertices).map_err(|e| src.error(v.span(), e.to_string()))?,
                ))
            }
            "polyhedron" => {
                let vs = f.required("vertices")?;
                let vertices = self.points(vs)?;
                let fv = f.required("faces")?;
                let mut faces = Vec::new();
                for face in src.array(fv, "an array of faces, each an array of vertex indices")? {
                    if src.array(face, "a face: an array of vertex indices")?.len() < 3 {
                        return Err(
                            src.error(face.span(), "expected a face of at least 3 vertex indices")
                        );
                    }
                    let mut loop_ = Vec::new();
                    for i in src.array(face, "a face: an array of vertex indices")? {
                        let index = src.index(i)?;
                        if index as usize >= vertices.len() {
                            return Err(src.error(
                                i.span(),
                                format!(
                                    "vertex index {index} is out of range: there are {} vertices",
                                    vertices.len()
                                ),
                            ));
                        }
                        loop_.push(index);
                    }
                    faces.push(loop_);
                }
                Shape::Polyhedron(Box::new(
                    Polyhedron::new(&vertices, &faces)
                        .map_err(|e| src.error(fv.span(), e.to_string()))?,
                ))
            }
            _ => {
                f.one_of(&["mesh", "file", "positions"])?;
                if let Some(m) = f.get("mesh") {
                    let name = src.string(m)?;
                    let Some(mesh) = self.meshes.get(name) else {
                        let e = src.error(m.span(), format!("no mesh named `{name}` is defined"));
                        return Err(
                            match did_you_mean(name, self.meshes.keys().map(String::as_str)) {
                                Some(s) => e.with_help(format!("did you mean `{s}`?")),
                                None => e.with_help("define it in a [meshes.NAME] table"),
                            },
                        );
                    };
                    Shape::Mesh(mesh.clone())
                } else {
                    Shape::Mesh(self.mesh_data(f)?)
                }
            }
        };
        Ok((shape, Transform::IDENTITY))
    }

    fn points(&self, v: &Value<'s>) -> Result<Vec<Vec3>> {
        self.src
            .array(v, "an array of points [[x, y, z], …]")?
            .iter()
            .map(|p| self.src.vec3(p))
            .collect()
    }

    /// A mesh from `file` (OBJ or PLY) or from inline `positions` and `indices`, keeping its
    /// vertex indices: an object may give it `vertex_materials`.
    fn mesh_data(&mut self, f: &Fields<'_, 's>) -> Result<Arc<TriangleMesh>> {
        let src = self.src;
        f.one_of(&["mesh", "file", "positions"])?;
        if let Some(file) = f.get("file") {
            let rel = src.string(file)?;
            let path = self.base_dir.join(rel);
            let extension = path
                .extension()
                .and_then(|e| e.to_str())
                .unwrap_or("")
                .to_ascii_lowercase();
            let unreadable = |e: std::io::Error| {
                src.error(
                    file.span(),
                    format!("cannot read mesh file `{}`: {e}", path.display()),
                )
            };
            return match extension.as_str() {
                "obj" => {
                    let (text, not_utf8) = crate::text::read_lenient(&path).map_err(unreadable)?;
                    self.warnings.extend(not_utf8);
                    let mut model = obj::parse_obj_model_with(&path, &text, false, true)?;
                    self.warnings.append(&mut model.warnings);
                    Ok(Arc::new(model.groups.remove(0).1))
                }
                "ply" => {
                    std::fs::metadata(&path).map_err(unreadable)?;
                    ply::load_ply_with(&path, true).map(Arc::new)
                }
                _ => Err(src.error(file.span(), "expected a mesh file: .obj or .ply")),
            };
        }
        let pv = f.required("positions")?;
        let positions = self.points(pv)?;
        let iv = f.required("indices")?;
        let mut triangles = Vec::new();
        for tri in src.array(iv, "an array of triangles [[i, j, k], …]")? {
            let items = src.array(tri, "a triangle: [i, j, k]")?;
            if items.len() != 3 {
                return Err(src.error(
                    tri.span(),
                    format!("expected a triangle of 3 indices, found {}", items.len()),
                ));
            }
            let mut t = [0u32; 3];
            for (slot, i) in t.iter_mut().zip(items) {
                *slot = src.index(i)?;
                if *slot as usize >= positions.len() {
                    return Err(src.error(
                        i.span(),
                        format!(
                            "vertex index {} is out of range: there are {} positions",
                            slot,
                            positions.len()
                        ),
                    ));
                }
            }
            triangles.push(t);
        }
        let normals = match f.get("normals") {
            Some(n) => self.points(n)?,
            None => Vec::new(),
        };
        let uvs = match f.get("uvs") {
            Some(u) => src
                .array(u, "an array of [u, v] pairs")?
                .iter()
                .map(|p| src.numbers::<2>(p, "a texture coordinate [u, v]"))
                .collect::<Result<Vec<_>>>()?,
            None => Vec::new(),
        };
        TriangleMesh::new_keeping_indices(positions, triangles, normals, uvs)
            .map(Arc::new)
            .map_err(|e| src.error(pv.span(), e.to_string()))
    }

    /// A list of transform steps, the first applied first.
    fn transform(&self, v: &Value<'s>) -> Result<Transform> {
        let src = self.src;
        let steps: Vec<&Value<'s>> = match v.get_ref() {
            DeValue::Table(_) => vec![v],
            _ => src
                .array(v, "a list of transforms [{ translate = … }, …]")?
                .iter()
                .collect(),
        };
        let mut total = Transform::IDENTITY;
        for step in steps {
            let f = src.table(
                step,
                "a transform step",
                &["translate", "rotate", "scale", "matrix"],
            )?;
            let (key, value) = match ["translate", "rotate", "scale", "matrix"].iter().filter_map(|k| f.get(k).map(|v| (*k, v))).collect::<Vec<_>>()[..] {
                [one] => one,
                _ => return Err(src.error(step.span(), "expected exactly one of translate, rotate, scale or matrix in each transform step")),
            };
            let t = match key {
                "translate" => Some(Transform::translate(src.vec3(value)?)),
                "rotate" => {
                    let r = src.table(value, "a rotation", &["axis", "degrees"])?;
                    Transform::rotate(
                        r.direction("axis", None)?,
                        r.src.number(r.required("degrees")?)?,
                    )
                }
                "scale" => {
                    let s = match value.get_ref() {
                        DeValue::Array(_) => src.vec3(value)?,
                        _ => Vec3::splat(src.number(value)?),
                    };
                    Transform::scale(s)
                }
                _ => {
                    let rows = src.array(value, "a 4×4 matrix: 4 rows of 4 numbers")?;
                    if rows.len() != 4 {
                        return Err(
                            src.error(value.span(), "expected a 4×4 matrix: 4 rows of 4 numbers")
                        );
                    }
                    let mut m = [[0.0; 4]; 4];
                    for (row, r) in m.iter_mut().zip(rows) {
                        *row = src.numbers::<4>(r, "a matrix row of 4 numbers")?;
                    }
                    Transform::from_matrix(Matrix4(m))
                }
            };
            let t = t.ok_or_else(|| {
                src.error(
                    value.span(),
                    format!("this {key} is singular or not affine: it cannot be inverted"),
                )
            })?;
            total = t.after(&total);
        }
        Ok(total)
    }
}
