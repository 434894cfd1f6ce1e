//! The `.ray` format's materials: a named `material { … }`, one inline, and their texture
//! maps.

use super::lex::Tok;
use super::{zero_material, Parser};
use crate::diagnostics::{did_you_mean, SceneError};
use plenum_core::color::Color;
use plenum_core::material::PhongMaterial;
use plenum_core::texture::{ImageTexture, Texture};
use std::sync::Arc;

impl<'s> Parser<'s> {
    /// `{ … }`, a name, or a string naming a material.
    pub(super) fn material_value(&mut self) -> Result<PhongMaterial, SceneError> {
        let span = self.span();
        match self.peek() {
            Some(Tok::Punct('{')) => self.material_block(),
            Some(Tok::Word(n)) | Some(Tok::Str(n)) => {
                let n = n.clone();
                self.pos += 1;
                self.named.get(&n).cloned().ok_or_else(|| {
                    let e = self.error(span, format!("no material named `{n}` is defined"));
                    match did_you_mean(&n, self.named.keys().map(String::as_str)) {
                        Some(s) => e.with_help(format!("did you mean `{s}`?")),
                        None => e,
                    }
                })
            }
            _ => Err(self.expected("a material: `{ … }` or a material name")),
        }
    }

    /// A material block; registers it when it has a name.
    pub(super) fn material_block(&mut self) -> Result<PhongMaterial, SceneError> {
        const KNOWN: &[&str] = &[
            "emissive",
            "ambient",
            "diffuse",
            "specular",
            "reflective",
            "transmissive",
            "shininess",
            "index",
            "name",
        ];
        self.punct('{')?;
        // (B) starts from the current default material; (A) from zeros.
        let mut block = MaterialBlock {
            material: if self.classic {
                zero_material()
            } else {
                self.current.clone()
            },
            reflective_given: false,
        };
        let mut name = None;
        while !self.eat('}') {
            let (field, span) = self.word()?;
            match field.as_str() {
                "emissive" | "ambient" | "diffuse" | "specular" | "reflective" | "transmissive" => {
                    let t = self.field(Self::texture)?;
                    let m = &mut block.material;
                    match field.as_str() {
                        "emissive" => m.emissive = t,
                        "ambient" => m.ambient = t,
                        "diffuse" => m.diffuse = t,
                        "specular" => m.specular = t,
                        "reflective" => {
                            m.reflective = t;
                            block.reflective_given = true;
                        }
                        _ => m.transmissive = t,
                    }
                }
                "shininess" => {
                    let s = self.span();
                    let n = self.field(Self::number)?;
                    if n < 0.0 {
                        return Err(self.error(s, "expected a shininess ≥ 0"));
                    }
                    // The OpenGL convention: fractions of 128.
                    block.material.shininess = if n <= 1.0 { n * 128.0 } else { n };
                }
                "index" => {
                    let s = self.span();
                    let n = self.field(Self::number)?;
                    if n.is_nan() || n <= 0.0 {
                        return Err(self.error(s, "expected an index of refraction > 0"));
                    }
                    block.material.ior = n;
                }
                "name" => {
                    self.punct('=')?;
                    name = match self.peek() {
                        Some(Tok::Word(n)) | Some(Tok::Str(n)) => Some(n.clone()),
                        _ => return Err(self.expected("a material name")),
                    };
                    self.pos += 1;
                    self.eat(';');
                }
                _ => self.unknown_field(&field, span, KNOWN)?,
            }
        }
        if self.classic && !block.reflective_given {
            block.material.reflective = block.material.specular.clone();
        }
        if let Some(n) = name.filter(|n| !n.is_empty()) {
            self.named.insert(n, block.material.clone());
        }
        Ok(block.material)
    }

    /// A colour `(r, g, b)`, or an image: `map(file)` or, in dialect A, a quoted file name.
    fn texture(&mut self) -> Result<Texture, SceneError> {
        let span = self.span();
        let file = match self.peek() {
            Some(Tok::Punct('(')) => return Ok(Texture::Constant(self.color()?)),
            Some(Tok::Word(w)) if w == "map" => {
                self.pos += 1;
                self.punct('(')?;
                let f = match self.peek() {
                    Some(Tok::Word(f)) | Some(Tok::Str(f)) => f.clone(),
                    _ => return Err(self.expected("an image file name")),
                };
                self.pos += 1;
                self.punct(')')?;
                f
            }
            Some(Tok::Str(f)) => {
                let f = f.clone();
                self.pos += 1;
                f
            }
            _ => return Err(self.expected("a colour `(r, g, b)` or `map(file)`")),
        };
        // Texture maps are decoration in this format, and the course's sample sets ship
        // scenes without their images: a map that cannot be read is a warning, mid-grey.
        let texels = match plenum_image::read_texture(&self.base_dir.join(&file)) {
            Ok(t) => t,
            Err(e) => {
                let w = self.error(span, format!("{e}; using mid-grey instead"));
                self.warnings
                    .push(w.to_string().replacen("error:", "warning:", 1));
                return Ok(Texture::Constant(Color::gray(0.5)));
            }
        };
        let rgb = texels
            .rgb
            .iter()
            .map(|p| Color::new(p[0] as f64, p[1] as f64, p[2] as f64))
            .collect();
        let image = ImageTexture::new(texels.width, texels.height, rgb, [1.0, 1.0])
            .ok_or_else(|| self.error(span, "the image is empty"))?;
        Ok(Texture::Image(Arc::new(image)))
    }
}

/// A material block as written, before the dialect's defaults are applied.
struct MaterialBlock {
    material: PhongMaterial,
    reflective_given: bool,
}
