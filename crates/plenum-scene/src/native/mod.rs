//! Plenum's native scene format: TOML, documented field by field in docs/scene-format.md.
//!
//! `parse` reads the top-level tables in order and hands each to its module: `settings`
//! (`[render]`, `[camera]`), `materials` (and `physical`, the typed ones), `objects` (with
//! `[meshes.NAME]`), `lights`. What they share (colours, textures, transforms, a `type`
//! among several) is here.

use crate::diagnostics::{did_you_mean, SceneError};
use crate::reader::{Fields, Result, Source, Value};
use crate::RenderDefaults;
use plenum_core::color::Color;
use plenum_core::geometry::TriangleMesh;
use plenum_core::material::FloatTexture;
use plenum_core::math::{Matrix4, Transform, Vec3};
use plenum_core::scene::{MaterialId, SceneBuilder};
use plenum_core::texture::noise::MAX_OCTAVES;
use plenum_core::texture::{ImageTexture, Mapping, Noise, Texture, Wrap};
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
mod lights;
mod materials;
mod objects;
mod physical;
mod settings;

const COMMON: [&str; 7] = [
    "type",
    "name",
    "material",
    "transform",
    "transform_close",
    "alpha",
    "alpha_cutoff",
];

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

    /// A number in [0, 1] or a texture, read as a grey value (a colour's mean): `what`
    /// names it in the error.
    fn fraction(&self, v: &Value<'s>, what: &str) -> Result<FloatTexture> {
        Ok(match self.texture(v)? {
            Texture::Constant(c) => {
                let a = (c.r + c.g + c.b) / 3.0;
                if !(0.0..=1.0).contains(&a) {
                    return Err(self.src.error(
                        v.span(),
                        format!("expected {what} between 0 and 1, found {a}"),
                    ));
                }
                FloatTexture::Constant(a)
            }
            t => FloatTexture::Texture(t),
        })
    }

    /// An image's `wrap`: one mode for u and v, or `[u, v]`.
    fn wrap(&self, v: &Value<'s>) -> Result<[Wrap; 2]> {
        let one = |w: &Value<'s>| -> Result<Wrap> {
            Ok(match self.src.string(w)? {
                "repeat" => Wrap::Repeat,
                "clamp" => Wrap::Clamp,
                "mirror" => Wrap::Mirror,
                "black" => Wrap::Black,
                other => {
                    return Err(self.src.error(
                        w.span(),
                        format!("unknown wrap `{other}`: expected repeat, clamp, mirror or black"),
                    ))
                }
            })
        };
        match v.get_ref() {
            DeValue::Array(_) => match self.src.array(v, "[u, v] wrap modes")? {
                [u, w] => Ok([one(u)?, one(w)?]),
                list => Err(self.src.error(
                    v.span(),
                    format!("expected two wrap modes [u, v], found {}", list.len()),
                )),
            },
            _ => Ok([one(v)?; 2]),
        }
    }

    fn texture(&self, v: &Value<'s>) -> Result<Texture> {
        let DeValue::Table(_) = v.get_ref() else {
            return Ok(Texture::Constant(self.color(v)?));
        };
        let kind = {
            let f = self.src.table(
                v,
                "a texture",
                &[
                    "texture",
                    "even",
                    "odd",
                    "scale",
                    "file",
                    "channel",
                    "encoding",
                    "corners",
                    "textures",
                    "amount",
                    "wrap",
                    "omega",
                    "octaves",
                    "variation",
                    "inside",
                    "outside",
                    "direction",
                    "mapping",
                    "transform",
                    "delta",
                    "axes",
                    "of",
                ],
            )?;
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
                let f = self.src.table(
                    v,
                    "an image texture",
                    &["texture", "file", "scale", "channel", "encoding", "wrap"],
                )?;
                let file = f.required("file")?;
                // "linear": 8-bit values as stored, for data (heights, normals).
                let linear = match f.get("encoding") {
                    None => false,
                    Some(e) => match self.src.string(e)? {
                        "srgb" => false,
                        "linear" => true,
                        other => {
                            return Err(self.src.error(
                                e.span(),
                                format!(
                                    "unknown encoding `{other}`: expected \"srgb\" or \"linear\""
                                ),
                            ))
                        }
                    },
                };
                let path = self.base_dir.join(self.src.string(file)?);
                let texels = match linear {
                    true => plenum_image::read_data_texture(&path),
                    false => plenum_image::read_texture(&path),
                }
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
                // The colour, or the alpha channel as grey (a cut-out's coverage).
                let alpha = match f.get("channel") {
                    None => false,
                    Some(c) => match self.src.string(c)? {
                        "rgb" => false,
                        "alpha" if texels.alpha.is_some() => true,
                        "alpha" => {
                            return Err(self.src.error(c.span(), "the image has no alpha channel"))
                        }
                        other => {
                            return Err(self.src.error(
                                c.span(),
                                format!("unknown channel `{other}`: expected \"rgb\" or \"alpha\""),
                            ))
                        }
                    },
                };
                let texels = match (&texels.alpha, alpha) {
                    (Some(a), true) => a.iter().map(|&a| Color::gray(a as f64)).collect(),
                    _ => texels
                        .rgb
                        .iter()
                        .map(|p| Color::new(p[0] as f64, p[1] as f64, p[2] as f64))
                        .collect(),
                };
                let image = ImageTexture::new(width, height, texels, scale)
                    .ok_or_else(|| self.src.error(file.span(), "the image is empty"))?;
                let wrap = match f.get("wrap") {
                    None => [Wrap::Repeat; 2],
                    Some(w) => self.wrap(w)?,
                };
                Ok(Texture::Image(Arc::new(image.with_wrap(wrap))))
            }
            "bilerp" => {
                let f = self
                    .src
                    .table(v, "a bilerp texture", &["texture", "corners", "scale"])?;
                let corners = f.required("corners")?;
                let list = self
                    .src
                    .array(corners, "four colours [c00, c10, c01, c11]")?;
                let [c00, c10, c01, c11] = list else {
                    return Err(self.src.error(
                        corners.span(),
                        format!(
                            "expected four colours [c00, c10, c01, c11], found {}",
                            list.len()
                        ),
                    ));
                };
                let corners = [c00, c10, c01, c11].map(|c| self.color(c));
                let [c00, c10, c01, c11] = corners;
                let scale = match f.get("scale") {
                    None => [1.0, 1.0],
                    Some(s) => self.src.numbers::<2>(s, "[u, v] repeats")?,
                };
                Ok(Texture::Bilerp(Arc::new(([c00?, c10?, c01?, c11?], scale))))
            }
            "scale" | "mix" => {
                let keys: &[&str] = match kind.0.as_str() {
                    "scale" => &["texture", "textures"],
                    _ => &["texture", "textures", "amount"],
                };
                let f = self.src.table(v, "a texture", keys)?;
                let [a, b] = self.texture_pair(&f)?;
                let combined = match kind.0.as_str() {
                    "scale" => Texture::Scale(Arc::new([a, b])),
                    _ => {
                        let amount = match f.get("amount") {
                            None => Texture::Constant(Color::gray(0.5)),
                            Some(t) => self.texture(t)?,
                        };
                        Texture::Mix(Arc::new([a, b, amount]))
                    }
                };
                Ok(combined
                    .constant_value()
                    .map_or(combined, Texture::Constant))
            }
            "fbm" | "wrinkled" | "windy" | "marble" => {
                let keys: &[&str] = match kind.0.as_str() {
                    "windy" => &["texture"],
                    "marble" => &["texture", "omega", "octaves", "scale", "variation"],
                    _ => &["texture", "omega", "octaves"],
                };
                let f = self.src.table(v, "a noise texture", keys)?;
                let omega = f.number_or("omega", 0.5)?;
                let octaves = f.count("octaves")?.unwrap_or(8);
                if octaves > MAX_OCTAVES {
                    return Err(self.src.error(
                        f.required("octaves")?.span(),
                        format!("expected at most {MAX_OCTAVES} octaves (finer ones are below f64's precision), found {octaves}"),
                    ));
                }
                Ok(Texture::Noise(Arc::new(match kind.0.as_str() {
                    "fbm" => Noise::Fbm { omega, octaves },
                    "wrinkled" => Noise::Wrinkled { omega, octaves },
                    "windy" => Noise::Windy,
                    _ => Noise::Marble {
                        omega,
                        octaves,
                        scale: f.number_or("scale", 1.0)?,
                        variation: f.number_or("variation", 0.2)?,
                    },
                })))
            }
            "dots" => {
                let f = self
                    .src
                    .table(v, "a dots texture", &["texture", "inside", "outside"])?;
                let part = |key: &str, default: Color| {
                    f.get(key)
                        .map_or(Ok(Texture::Constant(default)), |t| self.texture(t))
                };
                let (inside, outside) = (
                    part("inside", Color::WHITE)?,
                    part("outside", Color::BLACK)?,
                );
                Ok(match (&inside, &outside) {
                    (Texture::Constant(Color::WHITE), Texture::Constant(Color::BLACK)) => {
                        Texture::Dots
                    }
                    _ => Texture::Mix(Arc::new([outside, inside, Texture::Dots])),
                })
            }
            "directionmix" => {
                let f = self.src.table(
                    v,
                    "a directionmix texture",
                    &["texture", "textures", "direction"],
                )?;
                let pair = self.texture_pair(&f)?;
                let d = f.direction("direction", None)?.normalized();
                Ok(Texture::DirectionMix(Arc::new((d, pair))))
            }
            "mapped" => self.mapped_texture(v),
            other => {
                let e = self.src.error(kind.1, format!("unknown texture `{other}`"));
                let kinds = [
                    "checker",
                    "checker3d",
                    "image",
                    "bilerp",
                    "scale",
                    "mix",
                    "directionmix",
                    "fbm",
                    "wrinkled",
                    "windy",
                    "marble",
                    "dots",
                    "mapped",
                ];
                Err(match did_you_mean(other, kinds) {
                    Some(s) => e.with_help(format!("did you mean `{s}`?")),
                    None => e.with_help(format!("expected one of: {}", kinds.join(", "))),
                })
            }
        }
    }

    /// A texture's `textures = [a, b]`: two textures or colours.
    fn texture_pair(&self, f: &Fields<'_, 's>) -> Result<[Texture; 2]> {
        let textures = f.required("textures")?;
        let list = self.src.array(textures, "two textures or colours")?;
        let [a, b] = list else {
            return Err(self.src.error(
                textures.span(),
                format!("expected two textures or colours, found {}", list.len()),
            ));
        };
        Ok([self.texture(a)?, self.texture(b)?])
    }

    /// A texture looked up through a mapping: `{ texture = "mapped", mapping = …, of = T }`,
    /// the mapping's space placed by `transform` (texture space to world).
    fn mapped_texture(&self, v: &Value<'s>) -> Result<Texture> {
        let f = self.src.table(
            v,
            "a mapped texture",
            &[
                "texture",
                "mapping",
                "transform",
                "scale",
                "delta",
                "axes",
                "of",
            ],
        )?;
        let inner = self.texture(f.required("of")?)?;
        let mapping_value = f.required("mapping")?;
        let kind = self.src.string(mapping_value)?;
        let to_texture = match f.get("transform") {
            None => Transform::IDENTITY,
            Some(t) => self.transform(t)?.inverted(),
        };
        let pair = |key: &str, default: [f64; 2]| -> Result<[f64; 2]> {
            f.get(key)
                .map_or(Ok(default), |p| self.src.numbers::<2>(p, "two numbers"))
        };
        // Only the keys a mapping reads.
        let allowed: &[&str] = match kind {
            "uv" => &["scale", "delta"],
            "planar" => &["transform", "axes", "delta"],
            _ => &["transform"],
        };
        for key in ["transform", "scale", "delta", "axes"] {
            if let Some(given) = f.get(key).filter(|_| !allowed.contains(&key)) {
                return Err(self.src.error(
                    given.span(),
                    format!("the `{kind}` mapping takes no `{key}`"),
                ));
            }
        }
        let mapping = match kind {
            "uv" => Mapping::Uv {
                scale: pair("scale", [1.0, 1.0])?,
                delta: pair("delta", [0.0, 0.0])?,
            },
            "spherical" => Mapping::Spherical(to_texture),
            "cylindrical" => Mapping::Cylindrical(to_texture),
            "solid" => Mapping::Solid(to_texture),
            "planar" => {
                let axes = match f.get("axes") {
                    None => [Vec3::X, Vec3::Y],
                    Some(a) => match self.src.array(a, "two vectors [s, t]")? {
                        [s, t] => [self.src.vec3(s)?, self.src.vec3(t)?],
                        list => {
                            return Err(self.src.error(
                                a.span(),
                                format!("expected two vectors [s, t], found {}", list.len()),
                            ))
                        }
                    },
                };
                Mapping::Planar {
                    to_texture,
                    axes,
                    delta: pair("delta", [0.0, 0.0])?,
                }
            }
            other => {
                let kinds = ["uv", "spherical", "cylindrical", "planar", "solid"];
                return Err(self
                    .src
                    .error(mapping_value.span(), format!("unknown mapping `{other}`"))
                    .with_help(format!("expected one of: {}", kinds.join(", "))));
            }
        };
        Ok(Texture::Mapped(Arc::new((mapping, inner))))
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
