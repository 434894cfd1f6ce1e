//! The native format's `[materials.NAME]` tables: the Phong model's, and the physically
//! based ones by their `type` (see `physical`).

use super::Reader;
use crate::reader::{Result, Value};
use plenum_core::color::Color;
use plenum_core::material::PhongMaterial;
use plenum_core::texture::Texture;
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
}
