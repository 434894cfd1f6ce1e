//! `plenum render scene.xml`: Mitsuba 3's XML scenes. [`xml`] reads the document as
//! Mitsuba's parser does; this module maps its plugins onto Plenum's (docs/mitsuba.md gives
//! the table). Mitsuba's conventions are kept: one-sided BSDFs unless wrapped in `twosided`,
//! one-sided area emitters, a shape without a BSDF diffuse 0.5 (black if it emits), roughness
//! as GGX α without remapping, and `max_depth` M as Plenum's M − 2. Whatever has no
//! counterpart, and every property that is never read, gets a located warning.

mod serialized;
mod xml;

use crate::diagnostics::{did_you_mean, SceneError};
use crate::RenderDefaults;
use plenum_core::camera::{CameraSettings, Lens};
use plenum_core::color::Color;
use plenum_core::geometry::{Cuboid, Cylinder, Disk, Shape, Sphere, TriangleMesh, UvMap};
use plenum_core::integrator::IntegratorKind;
use plenum_core::light::{Attenuation, Light};
use plenum_core::material::{
    CoatedDiffuseMaterial, ConductorMaterial, ConductorSpec, DielectricMaterial, DiffuseMaterial,
    FloatTexture, Material, Roughness, SpectralTexture, SpectrumKind, SpectrumValue,
    ThinDielectricMaterial,
};
use plenum_core::math::{Transform, Vec3};
use plenum_core::sampling::{FilterKind, SamplerKind};
use plenum_core::scene::{Alpha, Bitangent, Bump, MaterialId, SceneBuilder};
use plenum_core::texture::{ImageTexture, Texture, Wrap};
use plenum_spectrum::Spectrum;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;
use xml::{Document, Loc, Property, Result, SpectrumData, Value};

/// Indices of refraction by name, as Mitsuba's documentation lists them (`dielectric`'s
/// table, after Mitsuba's `ior.h`).
const IORS: &[(&str, f64)] = &[
    ("vacuum", 1.0),
    ("helium", 1.00004),
    ("hydrogen", 1.00013),
    ("air", 1.00028),
    ("carbon dioxide", 1.00045),
    ("water", 1.3330),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.470),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.5750),
    ("diamond", 2.419),
];

/// Mitsuba's conductor names Plenum has measured η and k for (docs/spectra.md).
const METALS: &[&str] = &["Ag", "Al", "Au", "Cr", "Cu"];
/// The rest of Mitsuba's list: read, with a warning, as the nearest grey metal.
const OTHER_METALS: &[&str] = &[
    "a-C", "AlAs", "AlSb", "Be", "CsI", "Cu2O", "CuO", "d-C", "Hg", "HgTe", "Ir", "K", "Li", "MgO",
    "Mo", "Na_palik", "Nb", "Ni_palik", "Rh", "Se", "SiC", "SnTe", "Ta", "Te", "ThF4", "TiC",
    "TiN", "TiO2", "VC", "V_palik", "VN", "W",
];

/// Parses a Mitsuba 3 scene: the scene, the render settings it asks for, and warnings.
pub fn parse(
    path: &Path,
    text: String,
) -> std::result::Result<(SceneBuilder, RenderDefaults, Vec<String>), SceneError> {
    let doc = Document::parse(path, text)?;
    let mut b = Builder {
        doc: &doc,
        builder: SceneBuilder::default(),
        defaults: RenderDefaults {
            integrator: Some(IntegratorKind::Path),
            sampler: SamplerKind::Random,
            ..RenderDefaults::default()
        },
        warnings: Vec::new(),
        materials: HashMap::new(),
        opacities: HashMap::new(),
        bumps: HashMap::new(),
        default_diffuse: None,
        in_progress: Vec::new(),
        read: Vec::new(),
        count: 0,
    };
    b.scene()?;
    b.report_unread();
    Ok((b.builder, b.defaults, b.warnings))
}

struct Builder<'d> {
    doc: &'d Document,
    builder: SceneBuilder,
    defaults: RenderDefaults,
    warnings: Vec<String>,
    /// BSDF objects already added.
    materials: HashMap<usize, MaterialId>,
    /// Per BSDF object: the opacity of a `mask` it is or holds (through `twosided`).
    opacities: HashMap<usize, FloatTexture>,
    /// Per BSDF object: the map of a `normalmap` or `bumpmap` it is or holds.
    bumps: HashMap<usize, Bump>,
    default_diffuse: Option<MaterialId>,
    /// BSDFs being mapped, to refuse one that contains itself.
    in_progress: Vec<usize>,
    /// The objects mapped, whose unread properties are reported.
    read: Vec<usize>,
    /// Shapes and lights placed, for default names.
    count: usize,
}

/// A BSDF as Plenum reads it, before it is added.
struct Bsdf {
    material: Material,
    two_sided: bool,
}

impl<'d> Builder<'d> {
    // ---- Properties ----

    fn obj(&self, o: usize) -> &'d xml::Object {
        &self.doc.objects[o]
    }

    /// The property `name` of object `o` (the last one written), marked as read.
    fn prop(&self, o: usize, name: &str) -> Option<&'d Property> {
        let p = self.obj(o).props.iter().rev().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    fn warn(&mut self, loc: &Loc, message: impl Into<String>) {
        let w = self.doc.warning(loc, message);
        self.warnings.push(w);
    }

    fn float(&self, o: usize, name: &str, default: f64) -> Result<f64> {
        match self.prop(o, name) {
            None => Ok(default),
            Some(p) => match &p.value {
                Value::Float(x) => Ok(*x),
                Value::Integer(i) => Ok(*i as f64),
                _ => Err(self.doc.expected(p, "a float")),
            },
        }
    }

    fn positive(&self, o: usize, name: &str, default: f64) -> Result<f64> {
        let x = self.float(o, name, default)?;
        if x > 0.0 {
            return Ok(x);
        }
        let p = self.prop(o, name).unwrap();
        Err(self
            .doc
            .error(&p.loc, format!("expected `{name}` > 0, found {x}")))
    }

    fn integer(&self, o: usize, name: &str, default: i64) -> Result<i64> {
        match self.prop(o, name) {
            None => Ok(default),
            Some(p) => match &p.value {
                Value::Integer(i) => Ok(*i),
                _ => Err(self.doc.expected(p, "an integer")),
            },
        }
    }

    fn boolean(&self, o: usize, name: &str, default: bool) -> Result<bool> {
        match self.prop(o, name) {
            None => Ok(default),
            Some(p) => match &p.value {
                Value::Boolean(b) => Ok(*b),
                _ => Err(self.doc.expected(p, "a boolean")),
            },
        }
    }

    fn string(&self, o: usize, name: &str) -> Result<Option<(&'d str, &'d Loc)>> {
        match self.prop(o, name) {
            None => Ok(None),
            Some(p) => match &p.value {
                Value::String(s) => Ok(Some((s.as_str(), &p.loc))),
                _ => Err(self.doc.expected(p, "a string")),
            },
        }
    }

    fn vector(&self, o: usize, name: &str, default: Vec3) -> Result<Vec3> {
        match self.prop(o, name) {
            None => Ok(default),
            Some(p) => match &p.value {
                Value::Vector(v) => Ok(*v),
                _ => Err(self.doc.expected(p, "a point or vector")),
            },
        }
    }

    fn to_world(&self, o: usize) -> Result<Transform> {
        match self.prop(o, "to_world") {
            None => Ok(Transform::IDENTITY),
            Some(p) => match &p.value {
                Value::Transform(m) => Transform::from_matrix(*m)
                    .ok_or_else(|| self.doc.error(&p.loc, "the transform is singular")),
                _ => Err(self.doc.expected(p, "a transform")),
            },
        }
    }

    /// The nested or referenced plugins of `o` whose element is `tag`, in order.
    fn children(&self, o: usize, tag: &str) -> Result<Vec<(usize, &'d Property)>> {
        let mut out = Vec::new();
        for p in &self.obj(o).props {
            if let Some(c) = self.doc.object_of(p)? {
                if self.obj(c).tag == tag {
                    p.used.set(true);
                    out.push((c, p));
                }
            }
        }
        Ok(out)
    }

    /// A name for something placed: its id, or its plugin and a count.
    fn name(&mut self, o: usize) -> String {
        self.count += 1;
        let ob = self.obj(o);
        ob.id
            .clone()
            .unwrap_or_else(|| format!("{} {}", ob.plugin, self.count))
    }

    // ---- Colours, spectra, textures ----

    /// A reflectance-like parameter: a float, rgb, spectrum or texture.
    fn spectral(
        &mut self,
        o: usize,
        name: &str,
        default: f64,
        kind: SpectrumKind,
    ) -> Result<SpectralTexture> {
        let Some(p) = self.prop(o, name) else {
            return Ok(SpectralTexture::constant(Color::gray(default), kind));
        };
        Ok(match &p.value {
            Value::Float(x) => SpectralTexture::constant(Color::gray(*x), kind),
            Value::Integer(i) => SpectralTexture::constant(Color::gray(*i as f64), kind),
            Value::Rgb([r, g, b]) => SpectralTexture::constant(Color::new(*r, *g, *b), kind),
            Value::Spectrum(s) => match self.spectrum(p, s, false)? {
                Ok(s) => SpectralTexture::Constant(SpectrumValue::new(s, kind)),
                Err(v) => SpectralTexture::constant(Color::gray(v), kind),
            },
            Value::Object(_) | Value::Ref(_) => {
                let t = self.texture_of(p)?;
                SpectralTexture::from_texture(t, kind)
            }
            _ => return Err(self.doc.expected(p, "a colour, spectrum or texture")),
        })
    }

    /// A spectrum as written: `Ok(spectrum)` for pairs, `Err(value)` for one value.
    fn spectrum(
        &self,
        p: &Property,
        s: &SpectrumData,
        illuminant: bool,
    ) -> Result<std::result::Result<Spectrum, f64>> {
        match s {
            SpectrumData::Constant(v) => Ok(Err(*v)),
            SpectrumData::Pairs(pairs) => {
                let s = if illuminant {
                    Spectrum::piecewise_illuminant(pairs)
                } else {
                    Spectrum::piecewise(pairs)
                };
                s.map(Ok).map_err(|e| self.doc.error(&p.loc, e))
            }
        }
    }

    /// Emitted radiance (or intensity, irradiance): an RGB value, and the spectrum it
    /// stands for when one was written.
    fn emission(&mut self, o: usize, name: &str) -> Result<(Color, Option<Spectrum>)> {
        let Some(p) = self.prop(o, name) else {
            return Ok((Color::WHITE, None));
        };
        let c = match &p.value {
            Value::Float(x) => Color::gray(*x),
            Value::Integer(i) => Color::gray(*i as f64),
            Value::Rgb([r, g, b]) => Color::new(*r, *g, *b),
            Value::Spectrum(s) => match self.spectrum(p, s, true)? {
                Ok(s) => {
                    let [r, g, b] = s.to_rgb_illuminant();
                    return Ok((Color::new(r, g, b), Some(s)));
                }
                Err(v) => Color::gray(v),
            },
            Value::Object(_) | Value::Ref(_) => {
                let c = self.doc.object_of(p)?.unwrap();
                let ob = self.obj(c);
                if ob.tag == "texture" && ob.plugin == "blackbody" {
                    self.read.push(c);
                    let t = self.positive(c, "temperature", 6504.0)?;
                    let s = Spectrum::blackbody(t, 1.0);
                    let [r, g, b] = s.to_rgb_illuminant();
                    self.warn(
                        &p.loc,
                        "a blackbody's absolute scale is Planck's law in Mitsuba; Plenum normalises it to peak 1",
                    );
                    return Ok((Color::new(r, g, b), Some(s)));
                }
                self.warn(
                    &p.loc,
                    format!(
                        "a textured emitter (`{}`) is not supported: emitting white instead",
                        ob.plugin
                    ),
                );
                Color::WHITE
            }
            _ => return Err(self.doc.expected(p, "a colour or spectrum")),
        };
        if c.r < 0.0 || c.g < 0.0 || c.b < 0.0 {
            return Err(self
                .doc
                .error(&p.loc, format!("expected `{name}` ≥ 0 in every channel")));
        }
        Ok((c, None))
    }

    /// A constant colour (float or rgb) for a texture's parameters.
    fn color(&self, o: usize, name: &str, default: f64) -> Result<Color> {
        match self.prop(o, name) {
            None => Ok(Color::gray(default)),
            Some(p) => match &p.value {
                Value::Float(x) => Ok(Color::gray(*x)),
                Value::Rgb([r, g, b]) => Ok(Color::new(*r, *g, *b)),
                _ => Err(self.doc.expected(p, "a float or rgb colour")),
            },
        }
    }

    /// The texture a property holds or refers to.
    fn texture_of(&mut self, p: &Property) -> Result<Texture> {
        let t = self.doc.object_of(p)?.unwrap();
        let ob = self.obj(t);
        if ob.tag != "texture" {
            return Err(self
                .doc
                .error(&p.loc, format!("expected a texture, found a <{}>", ob.tag)));
        }
        self.read.push(t);
        let scale = self.uv_scale(t)?;
        match ob.plugin.as_str() {
            "bitmap" => {
                let (file, floc) = self
                    .string(t, "filename")?
                    .ok_or_else(|| self.doc.error(&ob.loc, "a bitmap needs a `filename`"))?;
                let path = self.doc.base_dir(floc.file).join(file);
                // `raw`: the values as stored (data such as normals), not sRGB-decoded.
                let texels = match self.boolean(t, "raw", false)? {
                    true => plenum_image::read_data_texture(&path),
                    false => plenum_image::read_texture(&path),
                }
                .map_err(|e| self.doc.error(floc, e.to_string()))?;
                if let Some((v, l)) = self.string(t, "filter_type")? {
                    if v != "bilinear" {
                        self.warn(
                            l,
                            format!("filter_type `{v}` is not supported: using bilinear"),
                        );
                    }
                }
                let wrap = match self.string(t, "wrap_mode")? {
                    None | Some(("repeat", _)) => Wrap::Repeat,
                    Some(("mirror", _)) => Wrap::Mirror,
                    Some(("clamp", _)) => Wrap::Clamp,
                    Some((v, l)) => {
                        return Err(self.doc.error(
                            l,
                            format!("unknown wrap_mode `{v}`: expected repeat, mirror or clamp"),
                        ))
                    }
                };
                let (width, height) = (texels.width, texels.height);
                let texels = texels
                    .rgb
                    .iter()
                    .map(|p| Color::new(p[0] as f64, p[1] as f64, p[2] as f64))
                    .collect();
                let image = ImageTexture::new(width, height, texels, scale)
                    .ok_or_else(|| self.doc.error(floc, "the image is empty"))?;
                Ok(Texture::Image(Arc::new(image.with_wrap([wrap; 2]))))
            }
            "checkerboard" => {
                // Mitsuba: color0 where u and v are on the same side of ½ in each unit
                // square, Plenum's even squares at twice the frequency.
                let even = self.color(t, "color0", 0.4)?;
                let odd = self.color(t, "color1", 0.2)?;
                Ok(Texture::Checker2d {
                    even,
                    odd,
                    scale: 2.0 * scale[0],
                })
            }
            other => {
                let message = format!("the `{other}` texture is not supported: using grey 0.5");
                let l = ob.loc.clone();
                self.warn(&l, message);
                Ok(Texture::Constant(Color::gray(0.5)))
            }
        }
    }

    /// A texture's `to_uv` as repeats in u and v (scale only; anything else warns).
    fn uv_scale(&mut self, t: usize) -> Result<[f64; 2]> {
        let Some(p) = self.prop(t, "to_uv") else {
            return Ok([1.0, 1.0]);
        };
        let Value::Transform(m) = &p.value else {
            return Err(self.doc.expected(p, "a transform"));
        };
        let m = m.0;
        let (su, sv) = (m[0][0], m[1][1]);
        let extra = m[0][1] != 0.0 || m[1][0] != 0.0 || m[0][3] != 0.0 || m[1][3] != 0.0;
        if extra || su <= 0.0 || sv <= 0.0 {
            self.warn(
                &p.loc,
                "`to_uv`: only a positive scale of u and v is supported; its rotation, offset or mirroring is ignored",
            );
        }
        Ok([su.abs().max(1e-9), sv.abs().max(1e-9)])
    }

    /// A `normalmap`'s image (its texture named `normalmap`: tangent-space normals, which
    /// Mitsuba reads with `raw` set) or a `bumpmap`'s height texture times its `scale`.
    /// `None` where the surface stays smooth (a constant height, warned otherwise).
    fn bump_map(&mut self, o: usize, normal: bool) -> Result<Option<Bump>> {
        let textures = self.children(o, "texture")?;
        let ob = self.obj(o);
        let found = match normal {
            true => textures.iter().find(|(_, p)| p.name == "normalmap"),
            false => textures.first(),
        };
        let Some(&(_, p)) = found else {
            let what = if normal {
                "a texture named `normalmap`"
            } else {
                "a texture"
            };
            return Err(self
                .doc
                .error(&ob.loc, format!("a {} needs {what}", ob.plugin)));
        };
        let texture = self.texture_of(p)?;
        if normal {
            return Ok(match texture {
                Texture::Image(image) => Some(Bump::NormalMap {
                    image,
                    scale: 1.0,
                    bitangent: Bitangent::NormalCrossU,
                }),
                _ => {
                    let l = p.loc.clone();
                    self.warn(
                        &l,
                        "a normal map other than a bitmap: the surface is smooth",
                    );
                    None
                }
            });
        }
        let scale = self.float(o, "scale", 1.0)?;
        Ok(match texture {
            Texture::Constant(_) => None,
            height => Some(Bump::HeightMap {
                height: FloatTexture::Texture(height),
                scale,
            }),
        })
    }

    /// A roughness α: a float or a texture.
    fn alpha(&mut self, o: usize, name: &str, default: f64) -> Result<FloatTexture> {
        let Some(p) = self.prop(o, name) else {
            return Ok(FloatTexture::Constant(default));
        };
        match &p.value {
            Value::Float(x) if *x >= 0.0 => Ok(FloatTexture::Constant(*x)),
            Value::Float(x) => Err(self
                .doc
                .error(&p.loc, format!("expected `{name}` ≥ 0, found {x}"))),
            Value::Object(_) | Value::Ref(_) => Ok(match self.texture_of(p)? {
                Texture::Constant(c) => FloatTexture::Constant((c.r + c.g + c.b) / 3.0),
                t => FloatTexture::Texture(t),
            }),
            _ => Err(self.doc.expected(p, "a float or texture")),
        }
    }

    /// A rough BSDF's microfacet roughness (`alpha`, or `alpha_u` and `alpha_v`).
    fn roughness(&mut self, o: usize) -> Result<Roughness> {
        if let Some((d, loc)) = self.string(o, "distribution")? {
            match d {
                "ggx" => {}
                "beckmann" => self.warn(
                    loc,
                    "the Beckmann distribution is not supported: using GGX with the same α",
                ),
                other => {
                    return Err(self.doc.error(
                        loc,
                        format!("unknown distribution `{other}`: expected ggx or beckmann"),
                    ))
                }
            }
        } else {
            let l = self.obj(o).loc.clone();
            self.warn(
                &l,
                "Mitsuba's default distribution is Beckmann, which Plenum lacks: using GGX with the same α",
            );
        }
        self.prop(o, "sample_visible");
        let (u, v) = if self.prop(o, "alpha_u").is_some() || self.prop(o, "alpha_v").is_some() {
            (
                self.alpha(o, "alpha_u", 0.1)?,
                self.alpha(o, "alpha_v", 0.1)?,
            )
        } else {
            let a = self.alpha(o, "alpha", 0.1)?;
            (a.clone(), a)
        };
        Ok(Roughness { u, v, remap: false })
    }

    /// An index of refraction: a number or one of Mitsuba's names.
    fn ior(&self, o: usize, name: &str, default: f64) -> Result<f64> {
        let Some(p) = self.prop(o, name) else {
            return Ok(default);
        };
        match &p.value {
            Value::Float(x) if *x > 0.0 => Ok(*x),
            Value::String(s) => IORS
                .iter()
                .find(|(n, _)| n == s)
                .map(|(_, v)| *v)
                .ok_or_else(|| {
                    let e = self.doc.error(&p.loc, format!("unknown material `{s}`"));
                    match did_you_mean(s, IORS.iter().map(|(n, _)| *n)) {
                        Some(m) => e.with_help(format!("did you mean `{m}`?")),
                        None => {
                            e.with_help("expected a number or a name such as bk7, water, diamond")
                        }
                    }
                }),
            _ => Err(self.doc.expected(p, "a positive float or a material name")),
        }
    }

    /// The relative index of a dielectric interface, interior over exterior.
    fn eta(&self, o: usize, int_default: f64) -> Result<SpectrumValue> {
        let int = self.ior(o, "int_ior", int_default)?;
        let ext = self.ior(o, "ext_ior", 1.00028)?;
        Ok(SpectrumValue::new(
            Spectrum::Constant(int / ext),
            SpectrumKind::Unbounded,
        ))
    }

    /// Warns when a tint Plenum's BSDF lacks is given and is not 1.
    fn unit_tint(&mut self, o: usize, name: &str) -> Result<()> {
        if let Some(p) = self.prop(o, name) {
            let one = match &p.value {
                Value::Float(x) => *x == 1.0,
                Value::Rgb(c) => c.iter().all(|x| *x == 1.0),
                Value::Spectrum(SpectrumData::Constant(x)) => *x == 1.0,
                _ => false,
            };
            if !one {
                self.warn(
                    &p.loc,
                    format!("`{name}` other than 1 is not supported: using 1"),
                );
            }
        }
        Ok(())
    }

    // ---- BSDFs ----

    /// The material of BSDF object `o`, added once.
    /// A BSDF without an id is named after `owner` (the shape it is written in), if any.
    fn material(&mut self, o: usize, owner: Option<&str>) -> Result<MaterialId> {
        if let Some(&id) = self.materials.get(&o) {
            return Ok(id);
        }
        if self.in_progress.contains(&o) {
            return Err(self.doc.error(
                &self.obj(o).loc,
                "this BSDF contains itself (through a <ref>)",
            ));
        }
        self.in_progress.push(o);
        let b = self.bsdf(o, 0);
        self.in_progress.pop();
        let b = b?;
        let name = match (&self.obj(o).id, owner) {
            (Some(id), _) => id.clone(),
            (None, Some(owner)) => owner.to_string(),
            (None, None) => format!("{} {}", self.obj(o).plugin, self.materials.len() + 1),
        };
        let id = self.builder.add_material(name, b.material);
        if !b.two_sided {
            self.builder.set_one_sided(id);
        }
        if let Some(bump) = self.bumps.get(&o).cloned() {
            self.builder.set_bump(id, bump);
        }
        self.materials.insert(o, id);
        Ok(id)
    }

    fn nested_bsdfs(&self, o: usize) -> Result<Vec<(usize, &'d Property)>> {
        self.children(o, "bsdf")
    }

    fn bsdf(&mut self, o: usize, depth: usize) -> Result<Bsdf> {
        let ob = self.obj(o);
        if depth > crate::limits::MAX_NESTING {
            return Err(self
                .doc
                .error(&ob.loc, "BSDFs nested too deep (a cycle of references?)"));
        }
        self.read.push(o);
        let one_sided = |material| Bsdf {
            material,
            two_sided: false,
        };
        Ok(match ob.plugin.as_str() {
            "diffuse" => one_sided(Material::Diffuse(DiffuseMaterial {
                reflectance: self.spectral(o, "reflectance", 0.5, SpectrumKind::Albedo)?,
            })),
            "dielectric" | "roughdielectric" => {
                self.unit_tint(o, "specular_reflectance")?;
                self.unit_tint(o, "specular_transmittance")?;
                let roughness = if ob.plugin == "roughdielectric" {
                    self.roughness(o)?
                } else {
                    Roughness::SMOOTH
                };
                Bsdf {
                    material: Material::Dielectric(DielectricMaterial {
                        eta: self.eta(o, 1.5046)?,
                        roughness,
                    }),
                    two_sided: true,
                }
            }
            "thindielectric" => {
                self.unit_tint(o, "specular_reflectance")?;
                self.unit_tint(o, "specular_transmittance")?;
                Bsdf {
                    material: Material::ThinDielectric(ThinDielectricMaterial {
                        eta: self.eta(o, 1.5046)?,
                    }),
                    two_sided: true,
                }
            }
            "conductor" | "roughconductor" => {
                self.unit_tint(o, "specular_reflectance")?;
                let roughness = if ob.plugin == "roughconductor" {
                    self.roughness(o)?
                } else {
                    Roughness::SMOOTH
                };
                let spec = self.conductor(o)?;
                one_sided(Material::Conductor(ConductorMaterial { spec, roughness }))
            }
            "plastic" | "roughplastic" => {
                self.unit_tint(o, "specular_reflectance")?;
                self.boolean(o, "nonlinear", false)?;
                let roughness = if ob.plugin == "roughplastic" {
                    self.roughness(o)?
                } else {
                    Roughness::SMOOTH
                };
                let l = ob.loc.clone();
                self.warn(
                    &l,
                    format!("`{}` is read as Plenum's coateddiffuse (a dielectric coat over a diffuse base, pbrt-v4's layered model): close to Mitsuba's, not equal", ob.plugin),
                );
                one_sided(Material::CoatedDiffuse(CoatedDiffuseMaterial {
                    reflectance: self.spectral(
                        o,
                        "diffuse_reflectance",
                        0.5,
                        SpectrumKind::Albedo,
                    )?,
                    roughness,
                    thickness: 0.01,
                    eta: self.eta(o, 1.49)?,
                    albedo: SpectralTexture::constant(Color::BLACK, SpectrumKind::Albedo),
                    g: 0.0,
                    max_depth: 10,
                    samples: 1,
                }))
            }
            "twosided" => {
                let nested = self.nested_bsdfs(o)?;
                let Some(&(front, _)) = nested.first() else {
                    return Err(self
                        .doc
                        .error(&ob.loc, "a twosided BSDF needs a BSDF inside"));
                };
                if let Some((_, p)) = nested.get(1) {
                    let l = p.loc.clone();
                    self.warn(&l, "a different BSDF for the back is not supported: the front one is used on both sides");
                }
                let material = self.bsdf(front, depth + 1)?.material;
                if let Some(opacity) = self.opacities.get(&front).cloned() {
                    self.opacities.insert(o, opacity);
                }
                if let Some(bump) = self.bumps.get(&front).cloned() {
                    self.bumps.insert(o, bump);
                }
                Bsdf {
                    material,
                    two_sided: true,
                }
            }
            "blendbsdf" => {
                let nested = self.nested_bsdfs(o)?;
                if nested.len() != 2 {
                    return Err(self.doc.error(
                        &ob.loc,
                        format!("a blendbsdf needs two BSDFs, found {}", nested.len()),
                    ));
                }
                let amount = self.alpha(o, "weight", 0.5)?;
                if let FloatTexture::Constant(w) = amount {
                    if w > 1.0 {
                        let p = self.prop(o, "weight").unwrap();
                        return Err(self.doc.error(
                            &p.loc,
                            format!("expected a weight between 0 and 1, found {w}"),
                        ));
                    }
                }
                let a = self.material(nested[0].0, None)?;
                let b = self.material(nested[1].0, None)?;
                let two_sided = !(self.builder_one_sided(a) && self.builder_one_sided(b));
                Bsdf {
                    material: Material::Mix {
                        materials: [a, b],
                        amount,
                    },
                    two_sided,
                }
            }
            "mask" | "bumpmap" | "normalmap" => {
                let nested = self.nested_bsdfs(o)?;
                let Some(&(inner, _)) = nested.first() else {
                    return Err(self
                        .doc
                        .error(&ob.loc, format!("a {} needs a BSDF inside", ob.plugin)));
                };
                if ob.plugin == "mask" {
                    // The opacity becomes a cut-out of the shapes that use this BSDF.
                    let opacity = self.alpha(o, "opacity", 0.5)?;
                    if let FloatTexture::Constant(a) = opacity {
                        if a > 1.0 {
                            let p = self.prop(o, "opacity").unwrap();
                            return Err(self.doc.error(
                                &p.loc,
                                format!("expected an opacity between 0 and 1, found {a}"),
                            ));
                        }
                    }
                    self.opacities.insert(o, opacity);
                } else if let Some(bump) = self.bump_map(o, ob.plugin == "normalmap")? {
                    self.bumps.insert(o, bump);
                }
                self.prop(o, "_arg_0");
                for p in &self.obj(o).props {
                    if matches!(p.value, Value::Object(_) | Value::Ref(_)) {
                        p.used.set(true);
                    }
                }
                let inner_bsdf = self.bsdf(inner, depth + 1)?;
                // A map inside a mask (or a map in a map: the outer one is used).
                if let Some(bump) = self.bumps.get(&inner).cloned() {
                    self.bumps.entry(o).or_insert(bump);
                }
                // A mask around a mask: their opacities multiply, but only constants are
                // multiplied here.
                if let Some(inner_opacity) = self.opacities.get(&inner).cloned() {
                    let outer = self.opacities.get(&o).cloned();
                    let both = match (outer, inner_opacity) {
                        (None, x) => x,
                        (Some(FloatTexture::Constant(a)), FloatTexture::Constant(b)) => {
                            FloatTexture::Constant(a * b)
                        }
                        (Some(x), _) => {
                            let l = ob.loc.clone();
                            self.warn(
                                &l,
                                "a mask inside a mask, with textures: the outer opacity is used",
                            );
                            x
                        }
                    };
                    self.opacities.insert(o, both);
                }
                inner_bsdf
            }
            other => {
                let l = ob.loc.clone();
                self.warn(
                    &l,
                    format!("the `{other}` BSDF is not supported: using diffuse 0.5"),
                );
                for p in &self.obj(o).props {
                    p.used.set(true);
                }
                one_sided(Material::Diffuse(DiffuseMaterial {
                    reflectance: SpectralTexture::constant(Color::gray(0.5), SpectrumKind::Albedo),
                }))
            }
        })
    }

    fn builder_one_sided(&self, id: MaterialId) -> bool {
        self.materials
            .iter()
            .find(|(_, m)| **m == id)
            .is_some_and(|(&o, _)| {
                !matches!(
                    self.obj(o).plugin.as_str(),
                    "twosided" | "dielectric" | "roughdielectric" | "thindielectric"
                )
            })
    }

    fn conductor(&mut self, o: usize) -> Result<ConductorSpec> {
        let unbounded = SpectrumKind::Unbounded;
        if self.prop(o, "eta").is_some() || self.prop(o, "k").is_some() {
            if let Some((_, l)) = self.string(o, "material")? {
                return Err(self
                    .doc
                    .error(l, "give either `material` or `eta` and `k`, not both"));
            }
            return Ok(ConductorSpec::EtaK {
                eta: self.spectral(o, "eta", 0.0, unbounded)?,
                k: self.spectral(o, "k", 1.0, unbounded)?,
            });
        }
        let metal = match self.string(o, "material")? {
            None => "none",
            Some((m, l)) => {
                if m == "none" || METALS.contains(&m) {
                    m
                } else if OTHER_METALS.contains(&m) {
                    self.warn(
                        l,
                        format!("no measured η and k for `{m}` in Plenum: using chromium (Cr)"),
                    );
                    "Cr"
                } else {
                    let e = self.doc.error(l, format!("unknown conductor `{m}`"));
                    let all = METALS.iter().chain(OTHER_METALS).copied().chain(["none"]);
                    return Err(match did_you_mean(m, all) {
                        Some(s) => e.with_help(format!("did you mean `{s}`?")),
                        None => e.with_help("see Mitsuba's conductor documentation for the names"),
                    });
                }
            }
        };
        if metal == "none" {
            // Mitsuba's default: a perfect mirror.
            return Ok(ConductorSpec::Reflectance(SpectralTexture::constant(
                Color::WHITE,
                SpectrumKind::Albedo,
            )));
        }
        let part = |p: &str| {
            let s = plenum_spectrum::named(&format!("metal-{metal}-{p}"))
                .expect("every metal listed has tables");
            SpectralTexture::Constant(SpectrumValue::new(s, unbounded))
        };
        Ok(ConductorSpec::EtaK {
            eta: part("eta"),
            k: part("k"),
        })
    }

    // ---- The scene ----

    fn scene(&mut self) -> Result<()> {
        let root = 0;
        self.read.push(root);
        let mut sensor = None;
        let mut integrator = None;
        let props: Vec<&Property> = self.obj(root).props.iter().collect();
        for p in props {
            let Some(c) = self.doc.object_of(p)? else {
                continue;
            };
            p.used.set(true);
            match self.obj(c).tag.as_str() {
                "shape" => self.shape(c)?,
                "emitter" => self.emitter(c)?,
                "sensor" => {
                    if sensor.is_some() {
                        let l = self.obj(c).loc.clone();
                        self.warn(&l, "a second sensor: Plenum renders the first");
                    } else {
                        sensor = Some(c);
                    }
                }
                "integrator" => integrator = Some(c),
                // Read when a shape uses them.
                "bsdf" | "texture" => {}
                tag => {
                    let l = self.obj(c).loc.clone();
                    self.warn(&l, format!("<{tag}> is not supported: ignored"));
                }
            }
        }
        match sensor {
            Some(s) => self.sensor(s)?,
            None => {
                let l = self.obj(root).loc.clone();
                self.warn(
                    &l,
                    "no sensor: Mitsuba's default camera (at the origin, looking along +z)",
                );
                self.builder.camera = CameraSettings {
                    position: Vec3::ZERO,
                    look_at: Vec3::Z,
                    up: Vec3::Y,
                    fov_degrees: vertical_fov(45.0, "x", 768, 576),
                    ..CameraSettings::default()
                };
                self.defaults.width = 768;
                self.defaults.height = 576;
            }
        }
        match integrator {
            Some(i) => self.integrator(i)?,
            None => self.defaults.max_depth = 100,
        }
        Ok(())
    }

    /// The material a shape scatters with: its BSDF, or Mitsuba's default.
    fn shape_material(&mut self, o: usize, emits: bool) -> Result<MaterialId> {
        let bsdfs = self.children(o, "bsdf")?;
        if let Some((_, p)) = bsdfs.get(1) {
            return Err(self.doc.error(&p.loc, "a shape has one BSDF"));
        }
        if let Some(&(b, _)) = bsdfs.first() {
            return self.material(b, self.obj(o).id.as_deref());
        }
        self.default_material(emits)
    }

    /// The cut-out of a shape whose BSDF is (or holds) a `mask`: its opacity, as coverage.
    fn shape_cut_out(&self, o: usize) -> Result<Option<Alpha>> {
        let bsdfs = self.children(o, "bsdf")?;
        Ok(bsdfs
            .first()
            .and_then(|(b, _)| self.opacities.get(b))
            .map(|opacity| Alpha::stochastic(opacity.clone())))
    }

    /// Mitsuba's BSDF for a shape without one.
    fn default_material(&mut self, emits: bool) -> Result<MaterialId> {
        if emits {
            // Mitsuba gives an emitter without a BSDF a black diffuse one.
            return Ok(self.builder.black_material());
        }
        if let Some(id) = self.default_diffuse {
            return Ok(id);
        }
        let id = self.builder.add_material(
            "default (diffuse 0.5)",
            Material::Diffuse(DiffuseMaterial {
                reflectance: SpectralTexture::constant(Color::gray(0.5), SpectrumKind::Albedo),
            }),
        );
        self.builder.set_one_sided(id);
        self.default_diffuse = Some(id);
        Ok(id)
    }

    fn shape(&mut self, o: usize) -> Result<()> {
        self.read.push(o);
        let ob = self.obj(o);
        let to_world = self.to_world(o)?;
        let flip = self.boolean(o, "flip_normals", false)?;
        let flip_unsupported = |s: &mut Self| {
            if flip {
                let l = s.prop(o, "flip_normals").unwrap().loc.clone();
                s.warn(&l, "`flip_normals` is not supported on this shape: ignored");
            }
        };
        let square = [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ];
        let shape = match ob.plugin.as_str() {
            "rectangle" => {
                // Two triangles with Mitsuba's (u, v): (0, 0) at (−1, −1), u along x, v
                // along y, and v down the image, so Plenum's v (up the image) is 1 − v.
                let uvs = vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];
                let triangles = match flip {
                    false => vec![[0, 1, 2], [0, 2, 3]],
                    true => vec![[0, 2, 1], [0, 3, 2]],
                };
                let mesh = TriangleMesh::new(square.to_vec(), triangles, vec![], uvs)
                    .expect("a square is a mesh");
                Shape::Mesh(Arc::new(mesh))
            }
            "disk" => {
                let n = if flip { -Vec3::Z } else { Vec3::Z };
                Shape::Disk(Disk::new(Vec3::ZERO, n, 1.0).with_uv_map(UvMap::Mitsuba))
            }
            "sphere" => {
                flip_unsupported(self);
                let center = self.vector(o, "center", Vec3::ZERO)?;
                let radius = self.positive(o, "radius", 1.0)?;
                Shape::Sphere(Sphere::new(center, radius).with_uv_map(UvMap::Mitsuba))
            }
            "cube" => {
                flip_unsupported(self);
                Shape::Cuboid(Cuboid::new(Vec3::splat(-1.0), Vec3::splat(1.0)))
            }
            "cylinder" => {
                flip_unsupported(self);
                let p0 = self.vector(o, "p0", Vec3::ZERO)?;
                let p1 = self.vector(o, "p1", Vec3::Z)?;
                let radius = self.positive(o, "radius", 1.0)?;
                let axis = p1 - p0;
                let height = axis.length();
                let z = axis / height;
                let (x, y) = z.orthonormal_basis();
                let Some(frame) = Transform::frame(p0, x, y, z).filter(|_| height > 0.0) else {
                    return Err(self
                        .doc
                        .error(&ob.loc, "the cylinder's p0 and p1 are the same point"));
                };
                // Mitsuba's cylinder is open at both ends.
                let cylinder = Cylinder::new(radius, height, false).with_uv_map(UvMap::Mitsuba);
                let shape = Shape::Cylinder(cylinder);
                return self.place(o, shape, to_world.after(&frame));
            }
            "obj" | "ply" => {
                flip_unsupported(self);
                let (file, loc) = self.string(o, "filename")?.ok_or_else(|| {
                    self.doc.error(
                        &ob.loc,
                        format!("an {} shape needs a `filename`", ob.plugin),
                    )
                })?;
                let path = self.doc.base_dir(loc.file).join(file);
                let mesh = crate::load_mesh(&path).map_err(|e| {
                    self.doc
                        .error(loc, format!("cannot read the mesh: {}", e.message))
                })?;
                if !self.boolean(o, "flip_tex_coords", true)? {
                    let l = self.prop(o, "flip_tex_coords").unwrap().loc.clone();
                    self.warn(&l, "`flip_tex_coords = false` is not supported: textures are looked up with v up");
                }
                // Mitsuba shades a mesh smoothly: its own normals, or ones it computes, or
                // with `face_normals` none at all.
                let face_normals = self.boolean(o, "face_normals", false)?;
                let mesh = match (face_normals, mesh.normals().is_empty()) {
                    (false, false) => mesh,
                    (true, true) => mesh,
                    (flat, _) => {
                        let (positions, triangles) = mesh.indexed();
                        let normals = match flat {
                            true => Vec::new(),
                            false => angle_weighted_normals(&positions, &triangles),
                        };
                        let uvs = mesh.uvs().to_vec();
                        TriangleMesh::new(positions, triangles, normals, uvs)
                            .map_err(|e| self.doc.error(loc, e.to_string()))?
                    }
                };
                Shape::Mesh(Arc::new(mesh))
            }
            "serialized" => {
                flip_unsupported(self);
                let (file, loc) = self.string(o, "filename")?.ok_or_else(|| {
                    self.doc
                        .error(&ob.loc, "a serialized shape needs a `filename`")
                })?;
                let path = self.doc.base_dir(loc.file).join(file);
                let index = self.integer(o, "shape_index", 0)?;
                let index = u32::try_from(index).map_err(|_| {
                    let p = self.prop(o, "shape_index").unwrap();
                    self.doc
                        .error(&p.loc, format!("expected a shape_index ≥ 0, found {index}"))
                })?;
                let bytes = std::fs::read(&path)
                    .map_err(|e| self.doc.error(loc, format!("cannot read the mesh: {e}")))?;
                let m = serialized::parse(&bytes, index)
                    .map_err(|e| self.doc.error(loc, format!("{}: {e}", path.display())))?;
                let face_normals = self.boolean(o, "face_normals", false)? || m.face_normals;
                // Mitsuba shades a mesh without normals smoothly, unless told otherwise.
                let normals = match (face_normals, m.normals.is_empty()) {
                    (true, _) => Vec::new(),
                    (false, true) => angle_weighted_normals(&m.positions, &m.triangles),
                    (false, false) => m.normals,
                };
                // Mitsuba's v runs down the image, Plenum's up.
                let uvs = m.uvs.iter().map(|&[u, v]| [u, 1.0 - v]).collect();
                let mesh = TriangleMesh::new(m.positions, m.triangles, normals, uvs)
                    .map_err(|e| self.doc.error(loc, format!("{}: {e}", path.display())))?;
                Shape::Mesh(Arc::new(mesh))
            }
            other => {
                let l = ob.loc.clone();
                self.warn(&l, format!("the `{other}` shape is not supported: skipped"));
                for p in &ob.props {
                    p.used.set(true);
                }
                return Ok(());
            }
        };
        self.place(o, shape, to_world)
    }

    /// Places a shape, emitting if it holds an area emitter.
    fn place(&mut self, o: usize, shape: Shape, to_world: Transform) -> Result<()> {
        let emitters = self.children(o, "emitter")?;
        if let Some((_, p)) = emitters.get(1) {
            return Err(self.doc.error(&p.loc, "a shape has one emitter"));
        }
        let name = self.name(o);
        let Some(&(e, ep)) = emitters.first() else {
            let material = self.shape_material(o, false)?;
            self.builder.add_object(name, shape, to_world, material);
            if let Some(alpha) = self.shape_cut_out(o)? {
                self.builder.set_last_alpha(alpha);
            }
            return Ok(());
        };
        self.read.push(e);
        if self.obj(e).plugin != "area" {
            return Err(self.doc.error(
                &ep.loc,
                format!(
                    "a shape's emitter must be `area`, found `{}`",
                    self.obj(e).plugin
                ),
            ));
        }
        // A texture for radiance (a bitmap, a checkerboard) varies it over the surface.
        let texture = match self.prop(e, "radiance") {
            Some(p) if matches!(p.value, Value::Object(_) | Value::Ref(_)) => {
                let t = self.doc.object_of(p)?.unwrap();
                match self.obj(t).plugin.as_str() {
                    "blackbody" => None,
                    _ => Some(self.texture_of(p)?),
                }
            }
            _ => None,
        };
        let (radiance, spectrum) = match texture {
            Some(_) => (Color::WHITE, None),
            None => self.emission(e, "radiance")?,
        };
        let material = self.shape_material(o, true)?;
        if self.shape_cut_out(o)?.is_some() {
            let l = ep.loc.clone();
            self.warn(
                &l,
                "a mask on an emitting shape is not supported: the light is whole",
            );
        }
        let added = self
            .builder
            .add_emissive_object(name, shape, to_world, material, radiance, false, 1);
        if !added {
            let l = ep.loc.clone();
            self.warn(
                &l,
                format!(
                    "a {} cannot be an area light in Plenum: placed without emitting",
                    self.obj(o).plugin
                ),
            );
        } else if let Some(s) = spectrum {
            self.builder.set_last_light_spectrum(s, 1.0);
        } else if let Some(t) = texture {
            self.builder.set_last_light_texture(t);
        }
        Ok(())
    }

    fn emitter(&mut self, o: usize) -> Result<()> {
        self.read.push(o);
        let ob = self.obj(o);
        let name = self.name(o);
        let to_world = self.to_world(o)?;
        let light = match ob.plugin.as_str() {
            "point" => {
                let (intensity, spectrum) = self.emission(o, "intensity")?;
                let at = to_world.point(Vec3::ZERO);
                let position = self.vector(o, "position", at)?;
                self.add_light(
                    name,
                    Light::Point {
                        position,
                        intensity,
                        attenuation: Attenuation::default(),
                    },
                    spectrum,
                );
                return Ok(());
            }
            "spot" => {
                let (intensity, spectrum) = self.emission(o, "intensity")?;
                let cutoff = self.positive(o, "cutoff_angle", 20.0)?;
                let beam = self.float(o, "beam_width", cutoff * 0.75)?;
                let l = ob.loc.clone();
                self.warn(&l, "a spot light fades smoothly (in the cosine) between beam_width and cutoff_angle in Plenum, linearly in the angle in Mitsuba");
                if self.prop(o, "texture").is_some() {
                    let l = self.prop(o, "texture").unwrap().loc.clone();
                    self.warn(&l, "a projected texture is not supported: ignored");
                }
                Light::Spot {
                    position: to_world.point(Vec3::ZERO),
                    direction: to_world.vector(Vec3::Z).normalized(),
                    cos_inner: beam.clamp(0.0, cutoff).to_radians().cos(),
                    cos_outer: cutoff.min(180.0).to_radians().cos(),
                    intensity,
                    attenuation: Attenuation::default(),
                }
                .with_spectrum(spectrum)
            }
            "directional" => {
                let (irradiance, spectrum) = self.emission(o, "irradiance")?;
                let along = to_world.vector(Vec3::Z);
                let direction = self.vector(o, "direction", along)?;
                if direction.length_squared() == 0.0 {
                    return Err(self.doc.error(&ob.loc, "the light's direction is zero"));
                }
                Light::Directional {
                    direction: direction.normalized(),
                    intensity: irradiance,
                }
                .with_spectrum(spectrum)
            }
            "constant" => {
                let (radiance, spectrum) = self.emission(o, "radiance")?;
                Light::Infinite { radiance }.with_spectrum(spectrum)
            }
            "envmap" => {
                let light = self.envmap(o, &to_world)?;
                (light, None)
            }
            "area" => {
                return Err(self
                    .doc
                    .error(&ob.loc, "an area emitter belongs inside a <shape>"))
            }
            other => {
                let l = ob.loc.clone();
                self.warn(
                    &l,
                    format!("the `{other}` emitter is not supported: skipped"),
                );
                for p in &ob.props {
                    p.used.set(true);
                }
                return Ok(());
            }
        };
        self.add_light(name, light.0, light.1);
        Ok(())
    }

    fn add_light(&mut self, name: String, light: Light, spectrum: Option<Spectrum>) {
        self.builder.add_light(name, light);
        if let Some(s) = spectrum {
            self.builder.set_last_light_spectrum(s, 1.0);
        }
    }

    /// Mitsuba's `envmap`: a latitude–longitude image whose pole is its local +y, looked up
    /// at u = atan2(x, −z)/2π, v = acos(y)/π of the direction in its local frame.
    fn envmap(&mut self, o: usize, to_world: &Transform) -> Result<Light> {
        use plenum_core::environment::{EnvironmentLayout, EnvironmentMap};
        let ob = self.obj(o);
        let (file, loc) = self
            .string(o, "filename")?
            .ok_or_else(|| self.doc.error(&ob.loc, "an envmap needs a `filename`"))?;
        let path = self.doc.base_dir(loc.file).join(file);
        let image = plenum_image::read_float_image(&path)
            .map_err(|e| self.doc.error(loc, e.to_string()))?;
        let scale = self.float(o, "scale", 1.0)?;
        if scale < 0.0 {
            return Err(self.doc.error(&ob.loc, "expected a scale ≥ 0"));
        }
        // Plenum's latitude–longitude frame: z the pole, φ = atan2(y, x) from x. Mitsuba's
        // local +y is the pole and φ = atan2(x, −z): so z = to_world(+y), x = to_world(−z),
        // y = to_world(+x) (a left-handed frame, which lookups do not mind).
        let axis = |v: Vec3| to_world.vector(v).normalized();
        let frame = plenum_core::sampling::Frame {
            x: axis(-Vec3::Z),
            y: axis(Vec3::X),
            z: axis(Vec3::Y),
        };
        let orthonormal = (frame.x.dot(frame.y)).abs() < 1e-6
            && (frame.y.dot(frame.z)).abs() < 1e-6
            && (frame.x.dot(frame.z)).abs() < 1e-6;
        if !orthonormal {
            let l = ob.loc.clone();
            self.warn(
                &l,
                "the envmap's to_world is not a rotation: its shear is ignored",
            );
        }
        let map = EnvironmentMap::new(
            image.width as usize,
            image.height as usize,
            image.pixels,
            EnvironmentLayout::LatLongPoles,
            frame,
            scale,
        )
        .map_err(|e| self.doc.error(loc, e))?;
        let [r, g, b] = map.average();
        Ok(Light::Environment {
            map: plenum_core::light::EnvironmentLight {
                map: Arc::new(map),
                file: path.display().to_string(),
                scale,
            },
            radiance: Color::new(r, g, b),
        })
    }

    fn sensor(&mut self, o: usize) -> Result<()> {
        self.read.push(o);
        let ob = self.obj(o);
        let films = self.children(o, "film")?;
        let (width, height) = match films.first() {
            Some(&(f, _)) => self.film(f)?,
            None => (768, 576),
        };
        if let Some(&(s, _)) = self.children(o, "sampler")?.first() {
            self.sampler(s)?;
        }
        let m = self.to_world(o)?;
        let position = m.point(Vec3::ZERO);
        let forward = m.vector(Vec3::Z).normalized();
        let up = m.vector(Vec3::Y).normalized();
        // Mitsuba's image x runs along −x of the sensor's frame, which a look-at points to
        // up × forward; a transform that turns it the other way mirrors the picture.
        let left_handed = m.vector(Vec3::X).dot(up.cross(forward)) < 0.0;
        let fov = match (
            self.prop(o, "fov").is_some(),
            self.string(o, "focal_length")?,
        ) {
            (true, Some((_, l))) => {
                return Err(self
                    .doc
                    .error(l, "give either `fov` or `focal_length`, not both"))
            }
            (true, None) => {
                let fov = self.float(o, "fov", 0.0)?;
                if !(fov > 0.0 && fov < 180.0) {
                    let p = self.prop(o, "fov").unwrap();
                    return Err(self.doc.error(
                        &p.loc,
                        format!("expected a fov strictly between 0 and 180 degrees, found {fov}"),
                    ));
                }
                let axis = match self.string(o, "fov_axis")? {
                    None => "x",
                    Some((a, l)) => match a.to_ascii_lowercase().as_str() {
                        "x" => "x",
                        "y" => "y",
                        "diagonal" => "diagonal",
                        "smaller" => "smaller",
                        "larger" => "larger",
                        _ => {
                            return Err(self.doc.error(l, format!("unknown fov_axis `{a}`: expected x, y, diagonal, smaller or larger")))
                        }
                    },
                };
                vertical_fov(fov, axis, width, height)
            }
            (false, f) => {
                let text = f.map_or("50mm", |(t, _)| t);
                let value = text
                    .trim_end_matches("mm")
                    .trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|v| *v > 0.0);
                let Some(mm) = value else {
                    let (_, l) = f.unwrap();
                    return Err(self.doc.error(
                        l,
                        format!("expected a focal length such as 50mm, found `{text}`"),
                    ));
                };
                let diagonal = 2.0
                    * ((36.0f64 * 36.0 + 24.0 * 24.0).sqrt() / (2.0 * mm))
                        .atan()
                        .to_degrees();
                vertical_fov(diagonal, "diagonal", width, height)
            }
        };
        for (key, default) in [("near_clip", 0.01), ("far_clip", 10000.0)] {
            let v = self.float(o, key, default)?;
            if v != default {
                let l = self.prop(o, key).unwrap().loc.clone();
                self.warn(
                    &l,
                    format!("`{key}` is not supported: Plenum does not clip"),
                );
            }
        }
        // Mitsuba's orthographic sensor sees [−1, 1] across x of its frame and the film's
        // aspect along y, scaled by its transform.
        let orthographic = (ob.plugin == "orthographic")
            .then(|| 2.0 * height as f64 / width as f64 * m.vector(Vec3::Y).length());
        let lens = match ob.plugin.as_str() {
            "perspective" | "orthographic" => Lens::default(),
            "thinlens" => {
                let Some(_) = self.prop(o, "aperture_radius") else {
                    return Err(self
                        .doc
                        .error(&ob.loc, "a thinlens sensor needs an `aperture_radius`"));
                };
                let radius = self.float(o, "aperture_radius", 0.0)?.max(0.0);
                Lens {
                    radius,
                    focus_distance: self.positive(o, "focus_distance", 10000.0)?,
                    ..Lens::default()
                }
            }
            other => {
                let l = ob.loc.clone();
                self.warn(
                    &l,
                    format!("the `{other}` sensor is not supported: using a pinhole"),
                );
                Lens::default()
            }
        };
        self.builder.camera = CameraSettings {
            position,
            look_at: position + forward,
            up,
            fov_degrees: fov,
            lens,
            left_handed,
            orthographic,
            ..CameraSettings::default()
        };
        self.defaults.width = width;
        self.defaults.height = height;
        Ok(())
    }

    fn film(&mut self, f: usize) -> Result<(u32, u32)> {
        self.read.push(f);
        let ob = self.obj(f);
        if ob.plugin != "hdrfilm" && ob.plugin != "specfilm" {
            let l = ob.loc.clone();
            self.warn(
                &l,
                format!("the `{}` film is read as an hdrfilm", ob.plugin),
            );
        }
        let size = |s: &Self, key: &str, default: i64| -> Result<u32> {
            let v = s.integer(f, key, default)?;
            if !(1..=1 << 16).contains(&v) {
                let p = s.prop(f, key).unwrap();
                return Err(s.doc.error(
                    &p.loc,
                    format!("expected `{key}` from 1 to 65536, found {v}"),
                ));
            }
            Ok(v as u32)
        };
        let (w, h) = (size(self, "width", 768)?, size(self, "height", 576)?);
        // How the image is stored: Plenum chooses by the output's extension.
        for key in [
            "pixel_format",
            "component_format",
            "file_format",
            "banner",
            "high_quality_edges",
            "sample_border",
        ] {
            self.prop(f, key);
        }
        if let Some(&(r, _)) = self.children(f, "rfilter")?.first() {
            self.rfilter(r)?;
        } else {
            // Mitsuba's default reconstruction filter.
            self.defaults.filter = FilterKind::Gaussian;
            self.defaults.filter_radius = Some(2.0);
        }
        Ok((w, h))
    }

    fn rfilter(&mut self, r: usize) -> Result<()> {
        self.read.push(r);
        let ob = self.obj(r);
        let (kind, radius) = match ob.plugin.as_str() {
            "box" => (FilterKind::Box, self.positive(r, "radius", 0.5)?),
            "tent" => (FilterKind::Tent, self.positive(r, "radius", 1.0)?),
            "gaussian" => {
                let sigma = self.positive(r, "stddev", 0.5)?;
                if sigma != 0.5 {
                    let l = self.prop(r, "stddev").unwrap().loc.clone();
                    self.warn(&l, "Plenum's Gaussian has σ = 0.5 pixel: the given stddev sets only its radius (4σ)");
                }
                (FilterKind::Gaussian, 4.0 * sigma)
            }
            "mitchell" | "catmullrom" => {
                let (b, c) = if ob.plugin == "mitchell" {
                    (
                        self.float(r, "B", 1.0 / 3.0)?,
                        self.float(r, "C", 1.0 / 3.0)?,
                    )
                } else {
                    (0.0, 0.5)
                };
                if (b - 1.0 / 3.0).abs() > 1e-6 || (c - 1.0 / 3.0).abs() > 1e-6 {
                    let l = ob.loc.clone();
                    self.warn(&l, format!("Plenum's Mitchell filter has B = C = 1/3: B = {b}, C = {c} not supported"));
                }
                (FilterKind::Mitchell, 2.0)
            }
            "lanczos" => (
                FilterKind::Lanczos,
                self.integer(r, "lobes", 3)?.clamp(1, 16) as f64,
            ),
            other => {
                let l = ob.loc.clone();
                self.warn(
                    &l,
                    format!("the `{other}` filter is not supported: using a box"),
                );
                (FilterKind::Box, 0.5)
            }
        };
        self.defaults.filter = kind;
        self.defaults.filter_radius = (radius != kind.default_radius()).then_some(radius);
        Ok(())
    }

    fn sampler(&mut self, s: usize) -> Result<()> {
        self.read.push(s);
        let ob = self.obj(s);
        let n = self.integer(s, "sample_count", 4)?;
        if !(1..=65536).contains(&n) {
            let p = self.prop(s, "sample_count").unwrap();
            return Err(self.doc.error(
                &p.loc,
                format!("expected a sample_count from 1 to 65536, found {n}"),
            ));
        }
        self.defaults.spp = n as u32;
        // The seed moves the noise, not the image.
        self.prop(s, "seed");
        self.prop(s, "jitter");
        self.prop(s, "scramble_type");
        self.defaults.sampler = match ob.plugin.as_str() {
            "independent" => SamplerKind::Random,
            "stratified" | "multijitter" | "orthogonal" => SamplerKind::Jittered,
            "ldsampler" | "sobol" => SamplerKind::Sobol,
            other => {
                let l = ob.loc.clone();
                self.warn(&l, format!("the `{other}` sampler is not supported: using independent (random) samples"));
                SamplerKind::Random
            }
        };
        if self.defaults.sampler == SamplerKind::Jittered {
            let root = (n as f64).sqrt().round() as i64;
            if root * root != n {
                let l = ob.loc.clone();
                self.warn(
                    &l,
                    format!(
                        "Plenum's jittered sampler takes a square count: {n} becomes {}",
                        root * root
                    ),
                );
            }
        }
        Ok(())
    }

    fn integrator(&mut self, i: usize) -> Result<()> {
        self.read.push(i);
        let ob = self.obj(i);
        // Mitsuba's depth counts path segments: 2 is direct light only, Plenum's 0.
        let depth = self.integer(i, "max_depth", -1)?;
        let rr = self.integer(i, "rr_depth", 5)?;
        let kind = match ob.plugin.as_str() {
            "path" | "volpath" | "volpathmis" | "prb" | "prb_basic" | "direct_projective"
            | "prb_projective" => {
                if ob.plugin != "path" {
                    let l = ob.loc.clone();
                    self.warn(&l, format!("`{}` is read as a path tracer (participating media and differentiation are not supported)", ob.plugin));
                }
                IntegratorKind::Path
            }
            "direct" => {
                for key in ["emitter_samples", "bsdf_samples"] {
                    if let Some(p) = self.prop(i, key) {
                        let l = p.loc.clone();
                        self.warn(&l, format!("`{key}`: Plenum takes one light and one BSDF sample per pixel sample"));
                    }
                }
                self.defaults.integrator = Some(IntegratorKind::Path);
                self.defaults.max_depth = 0;
                self.hide_emitters(i)?;
                return Ok(());
            }
            "ptracer" => IntegratorKind::Light,
            "bdpt" => IntegratorKind::Bdpt,
            "sppm" => IntegratorKind::Sppm,
            "photonmapper" => IntegratorKind::Photon,
            "aov" | "moment" | "stokes" | "depth" => {
                let l = ob.loc.clone();
                let inner = self.children(i, "integrator")?;
                self.warn(
                    &l,
                    format!(
                        "the `{}` integrator is not supported: rendering {}",
                        ob.plugin,
                        if inner.is_empty() {
                            "with a path tracer"
                        } else {
                            "the integrator inside it"
                        }
                    ),
                );
                if let Some(&(n, _)) = inner.first() {
                    return self.integrator(n);
                }
                IntegratorKind::Path
            }
            other => {
                let l = ob.loc.clone();
                self.warn(
                    &l,
                    format!("the `{other}` integrator is not supported: using a path tracer"),
                );
                IntegratorKind::Path
            }
        };
        self.defaults.integrator = Some(kind);
        self.defaults.max_depth = match depth {
            -1 => 100,
            d if d < 2 => {
                let l = self.prop(i, "max_depth").unwrap().loc.clone();
                self.warn(&l, format!("max_depth {d} (no light reflected at all) is not supported: using 2, direct light"));
                0
            }
            d => (d - 2).min(100) as u32,
        };
        if rr < 0 {
            let p = self.prop(i, "rr_depth").unwrap();
            return Err(self.doc.error(&p.loc, "expected an rr_depth ≥ 0"));
        }
        self.defaults.rr_depth = (rr - 2).max(0) as u32;
        self.hide_emitters(i)?;
        for key in ["samples_per_pass", "timeout"] {
            self.prop(i, key);
        }
        Ok(())
    }

    fn hide_emitters(&mut self, i: usize) -> Result<()> {
        if self.boolean(i, "hide_emitters", false)? {
            let l = self.prop(i, "hide_emitters").unwrap().loc.clone();
            self.warn(&l, "`hide_emitters` is not supported: emitters are seen");
        }
        Ok(())
    }

    /// A warning for every property of a mapped object that nothing read.
    fn report_unread(&mut self) {
        let mut seen = std::collections::HashSet::new();
        let read = std::mem::take(&mut self.read);
        for o in read {
            if !seen.insert(o) {
                continue;
            }
            let ob = self.obj(o);
            for p in &ob.props {
                if !p.used.get() {
                    let what = format!(
                        "`{}` of the {} `{}` is not supported: ignored",
                        p.name, ob.tag, ob.plugin
                    );
                    let w = self.doc.warning(&p.loc, what);
                    self.warnings.push(w);
                }
            }
        }
    }
}

/// Mitsuba's field of view on `axis` as Plenum's vertical one.
fn vertical_fov(fov: f64, axis: &str, width: u32, height: u32) -> f64 {
    let aspect = width as f64 / height as f64;
    let axis = match axis {
        "smaller" if aspect > 1.0 => "y",
        "smaller" => "x",
        "larger" if aspect > 1.0 => "x",
        "larger" => "y",
        a => a,
    };
    let t = (0.5 * fov.to_radians()).tan();
    let tan_v = match axis {
        "x" => t / aspect,
        "y" => t,
        _ => t / (1.0 + aspect * aspect).sqrt(),
    };
    2.0 * tan_v.atan().to_degrees()
}

trait WithSpectrum: Sized {
    fn with_spectrum(self, s: Option<Spectrum>) -> (Self, Option<Spectrum>) {
        (self, s)
    }
}

impl WithSpectrum for Light {}

/// Per-vertex normals as Mitsuba computes them for a mesh that has none: each triangle's
/// normal weighted by its angle at the vertex (Thürmer and Wüthrich 1998).
fn angle_weighted_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in triangles {
        let p = t.map(|i| positions[i as usize]);
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        if n.length_squared() == 0.0 {
            continue;
        }
        let n = n.normalized();
        for k in 0..3 {
            let (a, b) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
            let cos = a.dot(b) / (a.length() * b.length());
            normals[t[k] as usize] += n * cos.clamp(-1.0, 1.0).acos();
        }
    }
    normals
        .into_iter()
        .map(|n| {
            if n.length_squared() > 0.0 {
                n.normalized()
            } else {
                n
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_of_view_convert_between_axes() {
        // A square image: every axis but the diagonal is the vertical one.
        for axis in ["x", "y", "smaller", "larger"] {
            assert!((vertical_fov(40.0, axis, 256, 256) - 40.0).abs() < 1e-12);
        }
        // 2:1: the horizontal half-angle's tangent is twice the vertical one's.
        let v = vertical_fov(90.0, "x", 200, 100);
        assert!(((0.5 * v).to_radians().tan() - 0.5).abs() < 1e-12);
        assert!((vertical_fov(30.0, "smaller", 200, 100) - 30.0).abs() < 1e-12);
        // The diagonal of a square is √2 times its side.
        let d = vertical_fov(90.0, "diagonal", 100, 100);
        assert!(((0.5 * d).to_radians().tan() - 1.0 / 2f64.sqrt()).abs() < 1e-12);
    }
    #[test]
    fn serialized_meshes_are_read_by_index_with_mitsubas_uv_and_normals() {
        // Two squares in one file; the second, at z = 2.5, with (u, v) = (x, y) in Mitsuba's
        // convention, so Plenum's v is 1 − y. Without normals in the file, Mitsuba's
        // smooth ones are computed (a flat square: +z); `face_normals` keeps it flat.
        let square = |z: f64| {
            (
                vec![[0.0, 0.0, z], [1.0, 0.0, z], [1.0, 1.0, z], [0.0, 1.0, z]],
                vec![[0, 1, 2], [0, 2, 3]],
                vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
            )
        };
        let file = serialized::tests::write(&[square(0.0), square(2.5)], false, 4);
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("two.serialized"), &file).unwrap();
        let scene = |shape: &str| {
            let text = format!(
                r#"<scene version="3.0.0"><emitter type="constant"/>
<shape type="serialized">{shape}</shape>
</scene>"#
            );
            std::fs::write(dir.path().join("scene.xml"), text).unwrap();
            crate::load_scene(&dir.path().join("scene.xml"))
        };
        let l = scene(
            r#"<string name="filename" value="two.serialized"/><integer name="shape_index" value="1"/>"#,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let Shape::Mesh(m) = &l.scene.geometry.primitives[0].shape else {
            panic!("expected a mesh");
        };
        let (positions, _) = m.indexed();
        assert!(positions.iter().all(|p| p.z == 2.5), "{positions:?}");
        assert_eq!(m.uvs()[2], [1.0, 0.0]);
        assert!(
            m.normals().iter().all(|n| *n == Vec3::Z),
            "{:?}",
            m.normals()
        );
        let flat = scene(
            r#"<string name="filename" value="two.serialized"/><boolean name="face_normals" value="true"/>"#,
        )
        .unwrap();
        let Shape::Mesh(m) = &flat.scene.geometry.primitives[0].shape else {
            panic!("expected a mesh");
        };
        assert!(m.normals().is_empty());
        // A shape_index beyond the file, and a damaged file: located errors.
        let error = |shape: &str| match scene(shape) {
            Ok(_) => panic!("expected an error"),
            Err(e) => e,
        };
        let e = error(
            r#"<string name="filename" value="two.serialized"/><integer name="shape_index" value="2"/>"#,
        );
        assert!(
            e.to_string().contains("holds 2 meshes") && e.to_string().contains(":2:"),
            "{e}"
        );
        std::fs::write(dir.path().join("bad.serialized"), &file[..20]).unwrap();
        let e = error(r#"<string name="filename" value="bad.serialized"/>"#);
        assert!(e.to_string().contains("mesh's stream"), "{e}");
    }

    #[test]
    fn normals_are_weighted_by_angle() {
        // A corner of a cube: three faces meeting at the origin, each with a right angle
        // there, give the normal along (−1, −1, −1)/√3 at the corner.
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        let triangles = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2]];
        let n = angle_weighted_normals(&positions, &triangles);
        let want = Vec3::new(-1.0, -1.0, -1.0).normalized();
        assert!((n[0] - want).length() < 1e-12, "{:?}", n[0]);
        assert!((n[1] - Vec3::new(0.0, -1.0, -1.0).normalized()).length() < 1e-12);
    }
}
