//! The course ray tracer's `.ray` format ("SBT-raytracer 1.0"), both dialects of its reference
//! parsers (notes: shared/design/formats/ray.md): the classic reader (A) and the token
//! parser (B). Differences handled:
//! - k_r defaults to k_s in dialect A and to 0 in B. The dialect is read from the file: a
//!   top-level named `material { … }`, `quaternion`, `gennormals = …` or a camera
//!   `focaldistance` mean A; otherwise B.
//! - Shininess ≤ 1 is a fraction of 128 (the OpenGL convention), larger values are exponents.
//! - Point-light attenuation: a light that gives no coefficient has no falloff (A files
//!   never give them; the reference program set them in its interface); one that gives some
//!   takes B's defaults a = 0, b = 0, c = 1 for the others.
//! - `polymesh` = `trimesh`, `colour` = `color`, `quaternian` = `quaternion`, `gennormals;`
//!   or `gennormals = true;`, numbers like `.5` and `1e-005`, CRLF, `//` and `/* */` comments.
//!
//! Shapes are the unit shapes of the format, placed by nested `translate`, `scale`,
//! `rotate` (radians) and row-major `transform` nodes, composed outside-in. The file has no
//! resolution: 512 pixels wide, the height from the camera's aspect ratio.
//!
//! `lex` makes the tokens; the parser here reads statements and hands each to its module:
//! `lights` (with the camera), `materials`, `shapes`.

mod lex;
mod lights;
mod materials;
mod shapes;
#[cfg(test)]
mod tests;

use crate::diagnostics::{did_you_mean, SceneError};
use crate::RenderDefaults;
use lex::{lex, Tok};
use plenum_core::camera::CameraSettings;
use plenum_core::color::Color;
use plenum_core::material::PhongMaterial;
use plenum_core::math::{Transform, Vec3};
use plenum_core::scene::SceneBuilder;
use plenum_core::texture::Texture;
use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;

/// Parses `.ray` text. Returns the scene, its render defaults, and warnings for fields
/// that were read past.
pub fn parse(
    path: &Path,
    text: &str,
    base_dir: &Path,
) -> Result<(SceneBuilder, RenderDefaults, Vec<String>), SceneError> {
    let tokens = lex(path, text)?;
    let classic = tokens.windows(2).enumerate().any(|(i, w)| {
        // Top level: right after the header, or after a closed statement.
        let at_top = |j: usize| j <= 2 || matches!(tokens[j - 1].0, Tok::Punct('}' | ')' | ';'));
        match (&w[0].0, &w[1].0) {
            (Tok::Word(a), Tok::Punct('{')) if a == "material" && at_top(i) => true,
            (Tok::Word(a), _) if a == "quaternion" || a == "focaldistance" => true,
            (Tok::Word(a), Tok::Punct('=')) if a == "gennormals" => true,
            _ => false,
        }
    });
    let mut p = Parser {
        path,
        text,
        base_dir,
        tokens,
        pos: 0,
        classic,
        builder: SceneBuilder::default(),
        named: HashMap::new(),
        current: zero_material(),
        warnings: Vec::new(),
        objects: 0,
        lights: 0,
        aspect: 1.0,
        depth: 0,
    };
    p.builder.camera = CameraSettings {
        position: Vec3::ZERO,
        look_at: -Vec3::Z,
        up: Vec3::Y,
        fov_degrees: 2.0 * 0.5f64.atan().to_degrees(),
        ..CameraSettings::default()
    };
    p.header()?;
    while p.pos < p.tokens.len() {
        p.statement()?;
    }
    let width = 512;
    let height = ((width as f64 / p.aspect).round() as u32).max(1);
    let defaults = RenderDefaults {
        width,
        height,
        ..RenderDefaults::default()
    };
    Ok((p.builder, defaults, p.warnings))
}

struct Parser<'s> {
    path: &'s Path,
    text: &'s str,
    base_dir: &'s Path,
    tokens: Vec<(Tok, Range<usize>)>,
    pos: usize,
    /// Dialect A, the classic reader.
    classic: bool,
    builder: SceneBuilder,
    named: HashMap<String, PhongMaterial>,
    /// The default material (dialect B's top-level `material = …`).
    current: PhongMaterial,
    warnings: Vec<String>,
    objects: usize,
    lights: usize,
    aspect: f64,
    /// Groups and transforms open around the current statement.
    depth: usize,
}

pub(super) fn zero_material() -> PhongMaterial {
    let black = || Texture::Constant(Color::BLACK);
    PhongMaterial {
        emissive: black(),
        ambient: black(),
        diffuse: black(),
        specular: black(),
        shininess: 0.0,
        reflective: black(),
        transmissive: black(),
        ior: 1.0,
        fresnel: false,
        gloss: None,
    }
}

impl<'s> Parser<'s> {
    fn error(&self, span: Range<usize>, message: impl Into<String>) -> SceneError {
        SceneError::at(self.path, self.text, span, message)
    }

    fn span(&self) -> Range<usize> {
        match self.tokens.get(self.pos) {
            Some((_, s)) => s.clone(),
            None => self.text.len()..self.text.len(),
        }
    }

    fn peek(&self) -> Option<&Tok> {
        self.tokens.get(self.pos).map(|t| &t.0)
    }

    fn describe(&self) -> String {
        match self.peek() {
            None => "the end of the file".into(),
            Some(Tok::Num(_)) => format!("the number `{}`", &self.text[self.span()]),
            Some(Tok::Word(w)) => format!("`{w}`"),
            Some(Tok::Str(s)) => format!("the string \"{s}\""),
            Some(Tok::Punct(c)) => format!("`{c}`"),
        }
    }

    fn expected(&self, what: &str) -> SceneError {
        self.error(
            self.span(),
            format!("expected {what}, found {}", self.describe()),
        )
    }

    fn punct(&mut self, c: char) -> Result<(), SceneError> {
        if self.peek() == Some(&Tok::Punct(c)) {
            self.pos += 1;
            Ok(())
        } else {
            Err(self.expected(&format!("`{c}`")))
        }
    }

    fn eat(&mut self, c: char) -> bool {
        let hit = self.peek() == Some(&Tok::Punct(c));
        if hit {
            self.pos += 1;
        }
        hit
    }

    fn number(&mut self) -> Result<f64, SceneError> {
        match self.peek() {
            Some(Tok::Num(v)) => {
                let v = *v;
                self.pos += 1;
                Ok(v)
            }
            _ => Err(self.expected("a number")),
        }
    }

    fn word(&mut self) -> Result<(String, Range<usize>), SceneError> {
        let span = self.span();
        match self.peek() {
            Some(Tok::Word(w)) => {
                let w = w.clone();
                self.pos += 1;
                Ok((w, span))
            }
            _ => Err(self.expected("a keyword")),
        }
    }

    /// `( n, n, … )` with exactly N numbers.
    fn tuple<const N: usize>(&mut self) -> Result<[f64; N], SceneError> {
        self.punct('(')?;
        let mut out = [0.0; N];
        for (i, v) in out.iter_mut().enumerate() {
            if i > 0 {
                self.punct(',')?;
            }
            *v = self.number()?;
        }
        self.punct(')')?;
        Ok(out)
    }

    fn vec3(&mut self) -> Result<Vec3, SceneError> {
        Ok(Vec3::from_array(self.tuple::<3>()?))
    }

    /// `= value` after a field name, then an optional `;`.
    fn field<T>(
        &mut self,
        read: impl FnOnce(&mut Self) -> Result<T, SceneError>,
    ) -> Result<T, SceneError> {
        self.punct('=')?;
        let v = read(self)?;
        self.eat(';');
        Ok(v)
    }

    /// Reads past one value of any shape, for unknown fields.
    fn skip_value(&mut self) -> Result<(), SceneError> {
        let mut depth = 0i32;
        loop {
            match self.peek() {
                None => return Err(self.expected("a value")),
                Some(Tok::Punct('(' | '{')) => depth += 1,
                Some(Tok::Punct(')' | '}')) => {
                    depth -= 1;
                    if depth < 0 {
                        return Ok(());
                    }
                }
                Some(Tok::Punct(';')) if depth == 0 => {
                    self.pos += 1;
                    return Ok(());
                }
                _ => {}
            }
            self.pos += 1;
            if depth == 0 && !matches!(self.peek(), Some(Tok::Punct('(' | '{'))) {
                self.eat(';');
                return Ok(());
            }
        }
    }

    fn unknown_field(
        &mut self,
        name: &str,
        span: Range<usize>,
        known: &[&str],
    ) -> Result<(), SceneError> {
        let e = self.error(span, format!("unknown field `{name}`; it is ignored"));
        let e = match did_you_mean(name, known.iter().copied()) {
            Some(s) => e.with_help(format!("did you mean `{s}`?")),
            None => e,
        };
        self.warnings
            .push(e.to_string().replacen("error:", "warning:", 1));
        if self.peek() == Some(&Tok::Punct('=')) {
            self.pos += 1;
        }
        self.skip_value()
    }

    fn header(&mut self) -> Result<(), SceneError> {
        let (w, span) = self
            .word()
            .map_err(|_| self.expected("the header `SBT-raytracer 1.0`"))?;
        if w != "SBT-raytracer" {
            return Err(self.error(span, "expected the header `SBT-raytracer 1.0`"));
        }
        let span = self.span();
        let version = self.number()?;
        if !(0.9..=1.1).contains(&version) {
            return Err(self.error(
                span,
                format!("expected version 1.0 or 1.1, found {version}"),
            ));
        }
        Ok(())
    }

    fn statement(&mut self) -> Result<(), SceneError> {
        if self.eat(';') {
            return Ok(());
        }
        let (w, _) = self.word()?;
        match w.as_str() {
            "camera" => self.camera(),
            "point_light" | "directional_light" | "ambient_light" => self.light(&w),
            "material" => {
                if self.eat('=') {
                    // (B): the default material for what follows.
                    let m = self.material_value()?;
                    self.current = m;
                    self.eat(';');
                    Ok(())
                } else {
                    // (A): a named material definition.
                    self.material_block().map(|_| ())
                }
            }
            _ => {
                self.pos -= 1;
                self.geometry(Transform::IDENTITY)
            }
        }
    }
}
