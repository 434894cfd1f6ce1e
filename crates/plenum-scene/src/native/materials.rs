//! The native format's `[materials.NAME]` tables: the Phong model's, and the physically
//! based ones by their `type` (see `physical`).

use super::Reader;
use crate::reader::{Result, Value};
use plenum_core::color::Color;
use plenum_core::material::{FloatTexture, PhongMaterial};
use plenum_core::scene::{Bitangent, Bump};
use plenum_core::texture::{ImageTexture, Texture};
use std::sync::Arc;
use toml::de::DeValue;

impl<'s> Reader<'s> {
    pub(super) fn material(&mut self, name: &str, v: &Value<'s>) -> Result<()> {
        if let DeValue::Table(t) = v.get_ref() {
            if t.get("type").is_some() {
                let kind = self.kind(
                    v,
                    &format!("material `{name}`"),
                    super::physical::MATERIAL_TYPES,
                )?;
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
                    if let Some(bump) = self.bump(v)? {
                        self.builder.set_bump(id, bump);
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

    /// A physical material's `normal_map` (an image file of tangent-space normals, read
    /// linear, green up the image as in glTF; x and y times `normal_scale`) or `bump`
    /// (heights along the normal in scene units, a number or a texture, times `bump_scale`).
    fn bump(&self, v: &Value<'s>) -> Result<Option<Bump>> {
        let DeValue::Table(t) = v.get_ref() else {
            return Ok(None);
        };
        if let Some(file) = t.get("normal_map") {
            if let Some(b) = t.get("bump") {
                return Err(self
                    .src
                    .error(b.span(), "give a `normal_map` or a `bump`, not both"));
            }
            let path = self.base_dir.join(self.src.string(file)?);
            let texels = plenum_image::read_data_texture(&path)
                .map_err(|e| self.src.error(file.span(), e.to_string()))?;
            let rgb = texels.rgb.iter();
            let colors = rgb.map(|p| Color::new(p[0] as f64, p[1] as f64, p[2] as f64));
            let image =
                ImageTexture::new(texels.width, texels.height, colors.collect(), [1.0, 1.0])
                    .ok_or_else(|| self.src.error(file.span(), "the image is empty"))?;
            let scale = match t.get("normal_scale") {
                Some(s) => self.src.number(s)?,
                None => 1.0,
            };
            return Ok(Some(Bump::NormalMap {
                image: Arc::new(image),
                scale,
                bitangent: Bitangent::AlongV,
            }));
        }
        let scale = match t.get("bump_scale") {
            Some(s) => self.src.number(s)?,
            None => 1.0,
        };
        for key in ["normal_scale", "bump_scale"] {
            let other = if key == "normal_scale" {
                "normal_map"
            } else {
                "bump"
            };
            if let (Some(k), None) = (t.get(key), t.get(other)) {
                return Err(self
                    .src
                    .error(k.span(), format!("`{key}` without a `{other}`")));
            }
        }
        Ok(match t.get("bump") {
            None => None,
            Some(b) => match self.texture(b)? {
                Texture::Constant(_) => None,
                height => Some(Bump::HeightMap {
                    height: FloatTexture::Texture(height),
                    scale,
                }),
            },
        })
    }
}
