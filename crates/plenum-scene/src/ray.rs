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

use crate::diagnostics::{did_you_mean, SceneError};
use crate::limits::MAX_NESTING;
use crate::RenderDefaults;
use plenum_core::camera::CameraSettings;
use plenum_core::color::Color;
use plenum_core::geometry::{Cone, Cuboid, Cylinder, Polygon, Shape, Sphere, TriangleMesh};
use plenum_core::light::{Attenuation, Light};
use plenum_core::material::PhongMaterial;
use plenum_core::math::{Matrix4, Transform, Vec3};
use plenum_core::scene::SceneBuilder;
use plenum_core::texture::{ImageTexture, Texture};
use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;
use std::sync::Arc;

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Num(f64),
    Word(String),
    Str(String),
    Punct(char),
}

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

fn zero_material() -> PhongMaterial {
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

/// A material block as written, before the dialect's defaults are applied.
struct MaterialBlock {
    material: PhongMaterial,
    reflective_given: bool,
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

    fn camera(&mut self) -> Result<(), SceneError> {
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

    fn color(&mut self) -> Result<Color, SceneError> {
        let s = self.span();
        let [r, g, b] = self.tuple::<3>()?;
        if r < 0.0 || g < 0.0 || b < 0.0 {
            return Err(self.error(s, "expected colour components ≥ 0"));
        }
        Ok(Color::new(r, g, b))
    }

    fn light(&mut self, kind: &str) -> Result<(), SceneError> {
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

    /// `{ … }`, a name, or a string naming a material.
    fn material_value(&mut self) -> Result<PhongMaterial, SceneError> {
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
    fn material_block(&mut self) -> Result<PhongMaterial, SceneError> {
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

    /// A primitive, a transform node or a `{ … }` group, placed by `to_world`. Nesting is
    /// bounded: each level is a call, and a file of thousands would overflow the stack.
    fn geometry(&mut self, to_world: Transform) -> Result<(), SceneError> {
        if self.depth >= MAX_NESTING {
            return Err(self.error(
                self.span(),
                format!("groups and transforms nest deeper than {MAX_NESTING} levels here"),
            ));
        }
        self.depth += 1;
        let placed = self.placed(to_world);
        self.depth -= 1;
        placed
    }

    fn placed(&mut self, to_world: Transform) -> Result<(), SceneError> {
        if self.eat('{') {
            while !self.eat('}') {
                if self.eat(';') {
                    continue;
                }
                if self.peek() == Some(&Tok::Word("material".into())) {
                    self.pos += 1;
                    self.punct('=')?;
                    self.current = self.material_value()?;
                    self.eat(';');
                    continue;
                }
                self.geometry(to_world)?;
            }
            return Ok(());
        }
        let (w, span) = self.word()?;
        match w.as_str() {
            "translate" | "scale" | "rotate" | "transform" => {
                self.punct('(')?;
                let local = match w.as_str() {
                    "translate" => {
                        let v = self.numbers_then_comma(3)?;
                        Transform::translate(Vec3::new(v[0], v[1], v[2]))
                    }
                    "scale" => {
                        let mut v = vec![self.number()?];
                        self.punct(',')?;
                        if matches!(self.peek(), Some(Tok::Num(_))) {
                            v.push(self.number()?);
                            self.punct(',')?;
                            v.push(self.number()?);
                            self.punct(',')?;
                        }
                        let s = if v.len() == 3 {
                            Vec3::new(v[0], v[1], v[2])
                        } else {
                            Vec3::splat(v[0])
                        };
                        Transform::scale(s).ok_or_else(|| {
                            self.error(span.clone(), "a scale by zero cannot be inverted")
                        })?
                    }
                    "rotate" => {
                        let v = self.numbers_then_comma(4)?;
                        Transform::rotate(Vec3::new(v[0], v[1], v[2]), v[3].to_degrees())
                            .ok_or_else(|| {
                                self.error(span.clone(), "a rotation needs a non-zero axis")
                            })?
                    }
                    _ => {
                        let mut rows = [[0.0; 4]; 4];
                        for row in &mut rows {
                            *row = self.tuple::<4>()?;
                            self.punct(',')?;
                        }
                        let m = Matrix4(rows);
                        Transform::from_matrix(m).ok_or_else(|| {
                            self.error(
                                span.clone(),
                                "this transform matrix is singular or not affine",
                            )
                        })?
                    }
                };
                self.geometry(to_world.after(&local))?;
                self.punct(')')?;
                self.eat(';');
                Ok(())
            }
            "sphere" | "box" | "square" | "cylinder" | "cone" => self.primitive(&w, span, to_world),
            "trimesh" | "polymesh" => self.mesh(span, to_world),
            _ => {
                let e = self.error(span, format!("unknown statement `{w}`"));
                let known = [
                    "camera",
                    "point_light",
                    "directional_light",
                    "ambient_light",
                    "material",
                    "sphere",
                    "box",
                    "square",
                    "cylinder",
                    "cone",
                    "trimesh",
                    "polymesh",
                    "translate",
                    "scale",
                    "rotate",
                    "transform",
                ];
                Err(match did_you_mean(&w, known) {
                    Some(s) => e.with_help(format!("did you mean `{s}`?")),
                    None => e,
                })
            }
        }
    }

    /// `n, n, …, ` (N numbers, each followed by a comma).
    fn numbers_then_comma(&mut self, n: usize) -> Result<Vec<f64>, SceneError> {
        let mut v = Vec::with_capacity(n);
        for _ in 0..n {
            v.push(self.number()?);
            self.punct(',')?;
        }
        Ok(v)
    }

    /// A name for the next object of the file: its kind and its position.
    fn next_name(&mut self, kind: &str) -> String {
        self.objects += 1;
        format!("{kind} {}", self.objects)
    }

    fn add(&mut self, name: &str, shape: Shape, to_world: Transform, material: PhongMaterial) {
        let id = self.builder.add_material(name, material);
        self.builder.add_object(name, shape, to_world, id);
    }

    fn primitive(
        &mut self,
        kind: &str,
        span: Range<usize>,
        to_world: Transform,
    ) -> Result<(), SceneError> {
        const KNOWN: &[&str] = &[
            "material",
            "name",
            "height",
            "bottom_radius",
            "top_radius",
            "capped",
        ];
        self.punct('{')?;
        let mut material = None;
        let (mut height, mut bottom, mut top, mut capped) = (1.0, 1.0, 0.0, true);
        while !self.eat('}') {
            let (field, fspan) = self.word()?;
            match (field.as_str(), kind) {
                ("material", _) => material = Some(self.field(Self::material_value)?),
                ("name", _) => {
                    self.punct('=')?;
                    self.pos += 1;
                    self.eat(';');
                }
                ("height", "cone") => height = self.field(Self::number)?,
                ("bottom_radius", "cone") => bottom = self.field(Self::number)?,
                ("top_radius", "cone") => top = self.field(Self::number)?,
                ("capped", "cone") => {
                    capped = self.field(|p| match p.peek() {
                        Some(Tok::Word(b)) if b == "true" || b == "false" => {
                            let v = b == "true";
                            p.pos += 1;
                            Ok(v)
                        }
                        _ => Err(p.expected("true or false")),
                    })?
                }
                _ => self.unknown_field(&field, fspan, KNOWN)?,
            }
        }
        let material = match material {
            Some(m) => m,
            None if self.classic => {
                return Err(self.error(
                    span,
                    format!("a {kind} needs a material in this dialect of the format"),
                ))
            }
            None => self.current.clone(),
        };
        let shape = match kind {
            "sphere" => Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0)),
            "box" => Shape::Cuboid(Cuboid::new(Vec3::splat(-0.5), Vec3::splat(0.5))),
            "square" => {
                let square = Polygon::new(vec![
                    Vec3::new(-0.5, -0.5, 0.0),
                    Vec3::new(0.5, -0.5, 0.0),
                    Vec3::new(0.5, 0.5, 0.0),
                    Vec3::new(-0.5, 0.5, 0.0),
                ])
                .map_err(|e| self.error(span.clone(), e.to_string()))?;
                Shape::Polygon(Box::new(square))
            }
            "cylinder" => Shape::Cylinder(Cylinder::new(1.0, 1.0, true)),
            _ => {
                if height.is_nan()
                    || height <= 0.0
                    || bottom < 0.0
                    || top < 0.0
                    || bottom + top == 0.0
                {
                    return Err(self.error(
                        span,
                        "expected a cone with height > 0 and radii ≥ 0, not both zero",
                    ));
                }
                Shape::Cone(Cone {
                    radius0: bottom,
                    radius1: top,
                    height,
                    capped,
                    inside_only: false,
                })
            }
        };
        let name = self.next_name(kind);
        self.add(&name, shape, to_world, material);
        Ok(())
    }

    fn points(&mut self) -> Result<Vec<Vec3>, SceneError> {
        self.punct('(')?;
        let mut v = Vec::new();
        if self.eat(')') {
            return Ok(v);
        }
        loop {
            v.push(self.vec3()?);
            if self.eat(')') {
                return Ok(v);
            }
            self.punct(',')?;
        }
    }

    fn mesh(&mut self, span: Range<usize>, to_world: Transform) -> Result<(), SceneError> {
        const KNOWN: &[&str] = &[
            "points",
            "faces",
            "normals",
            "materials",
            "gennormals",
            "material",
            "name",
        ];
        self.punct('{')?;
        let (mut points, mut normals, mut faces) = (Vec::new(), Vec::new(), Vec::new());
        let mut materials: Vec<PhongMaterial> = Vec::new();
        let mut material = None;
        let mut gennormals = false;
        while !self.eat('}') {
            let (field, fspan) = self.word()?;
            match field.as_str() {
                "points" => points = self.field(Self::points)?,
                "normals" => normals = self.field(Self::points)?,
                "faces" => {
                    faces = self.field(|p| {
                        p.punct('(')?;
                        let mut faces = Vec::new();
                        while !p.eat(')') {
                            let fs = p.span();
                            p.punct('(')?;
                            let mut face = vec![];
                            loop {
                                let s = p.span();
                                let i = p.number()?;
                                if i < 0.0 || i.fract() != 0.0 {
                                    return Err(p.error(s, "expected a vertex index ≥ 0"));
                                }
                                face.push((i as u32, s));
                                if p.eat(')') {
                                    break;
                                }
                                p.punct(',')?;
                            }
                            if face.len() < 3 {
                                return Err(p.error(fs, "expected a face of at least 3 indices"));
                            }
                            faces.push(face);
                            p.eat(',');
                        }
                        Ok(faces)
                    })?
                }
                "materials" => {
                    materials = self.field(|p| {
                        p.punct('(')?;
                        let mut list = Vec::new();
                        while !p.eat(')') {
                            list.push(p.material_value()?);
                            p.eat(',');
                        }
                        Ok(list)
                    })?
                }
                "gennormals" => {
                    gennormals = true;
                    if self.eat('=') {
                        self.pos += 1;
                    }
                    self.eat(';');
                }
                "material" => material = Some(self.field(Self::material_value)?),
                "name" => {
                    self.punct('=')?;
                    self.pos += 1;
                    self.eat(';');
                }
                _ => self.unknown_field(&field, fspan, KNOWN)?,
            }
        }
        let mut triangles = Vec::new();
        for face in &faces {
            for (i, s) in face {
                if *i as usize >= points.len() {
                    return Err(self.error(
                        s.clone(),
                        format!(
                            "vertex index {i} is out of range: there are {} points",
                            points.len()
                        ),
                    ));
                }
            }
            for k in 1..face.len() - 1 {
                triangles.push([face[0].0, face[k].0, face[k + 1].0]);
            }
        }
        // Degenerate triangles are dropped, as the reference parser does.
        triangles.retain(|t| {
            let [a, b, c] = t.map(|i| points[i as usize]);
            (b - a).cross(c - a).length_squared() > 0.0
        });
        if triangles.is_empty() {
            self.warnings.push(format!(
                "warning: {}: a mesh with no triangles is skipped",
                self.path.display()
            ));
            return Ok(());
        }
        if gennormals && normals.is_empty() {
            normals = vec![Vec3::ZERO; points.len()];
            for t in &triangles {
                let [a, b, c] = t.map(|i| points[i as usize]);
                let n = (b - a).cross(c - a);
                for &i in t {
                    normals[i as usize] += n;
                }
            }
            for n in &mut normals {
                *n = n.normalized();
            }
        }
        for (what, n) in [("normals", normals.len()), ("materials", materials.len())] {
            if n != 0 && n != points.len() {
                return Err(self.error(
                    span.clone(),
                    format!("{n} {what} for {} points: give one per point", points.len()),
                ));
            }
        }
        let base = material.unwrap_or_else(|| {
            if self.classic {
                zero_material()
            } else {
                self.current.clone()
            }
        });
        let name = self.next_name("mesh");
        if materials.is_empty() {
            let mesh = TriangleMesh::new(points, triangles, normals, Vec::new())
                .map_err(|e| self.error(span.clone(), e.to_string()))?;
            self.add(&name, Shape::Mesh(Arc::new(mesh)), to_world, base);
            return Ok(());
        }
        // Per-vertex materials, blended across each triangle; each distinct one is added once.
        let mut ids: HashMap<String, u32> = HashMap::new();
        let mut vertex_materials = Vec::with_capacity(materials.len());
        for (i, m) in materials.iter().enumerate() {
            let key = format!("{m:?}");
            let id = match ids.get(&key) {
                Some(&id) => id,
                None => {
                    let id = self
                        .builder
                        .add_material(format!("{name} vertex {i}"), m.clone());
                    ids.insert(key, id);
                    id
                }
            };
            vertex_materials.push(id);
        }
        let mesh = TriangleMesh::new_keeping_indices(points, triangles, normals, Vec::new())
            .map_err(|e| self.error(span.clone(), e.to_string()))?;
        self.builder.add_mesh_with_vertex_materials(
            name,
            Arc::new(mesh),
            to_world,
            vertex_materials,
        );
        Ok(())
    }
}

/// Rotates `v` by the unit quaternion (r, i, j, k).
fn quaternion_rotate(q: [f64; 4], v: Vec3) -> Vec3 {
    let len = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    let [w, x, y, z] = q.map(|c| c / len.max(f64::MIN_POSITIVE));
    let u = Vec3::new(x, y, z);
    v * (w * w - u.dot(u)) + u * (2.0 * u.dot(v)) + u.cross(v) * (2.0 * w)
}

/// Tokens with their byte spans.
fn lex(path: &Path, text: &str) -> Result<Vec<(Tok, Range<usize>)>, SceneError> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            let end = text[i + 2..]
                .find("*/")
                .ok_or_else(|| SceneError::at(path, text, i..i + 2, "unterminated comment"))?;
            i += end + 4;
        } else if c.is_ascii_digit()
            || c == b'.'
            || ((c == b'-' || c == b'+')
                && i + 1 < b.len()
                && (b[i + 1].is_ascii_digit() || b[i + 1] == b'.'))
        {
            let start = i;
            i += 1;
            while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
                i += 1;
            }
            if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
                i += 1;
                if i < b.len() && (b[i] == b'-' || b[i] == b'+') {
                    i += 1;
                }
                while i < b.len() && b[i].is_ascii_digit() {
                    i += 1;
                }
            }
            let s = &text[start..i];
            let v: f64 = s.parse().map_err(|_| {
                SceneError::at(
                    path,
                    text,
                    start..i,
                    format!("expected a number, found `{s}`"),
                )
            })?;
            if !v.is_finite() {
                return Err(SceneError::at(
                    path,
                    text,
                    start..i,
                    format!("expected a finite number, found `{s}`"),
                ));
            }
            out.push((Tok::Num(v), start..i));
        } else if c.is_ascii_alphabetic() || c == b'_' {
            let start = i;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_' || b[i] == b'-') {
                i += 1;
            }
            out.push((Tok::Word(text[start..i].to_string()), start..i));
        } else if c == b'"' {
            let start = i;
            let end = text[i + 1..].find(['"', '\n']).map(|e| i + 1 + e);
            match end {
                Some(e) if b[e] == b'"' => {
                    out.push((Tok::Str(text[i + 1..e].to_string()), start..e + 1));
                    i = e + 1;
                }
                _ => {
                    return Err(SceneError::at(
                        path,
                        text,
                        start..start + 1,
                        "unterminated string",
                    ))
                }
            }
        } else if b"(){},=;".contains(&c) {
            out.push((Tok::Punct(c as char), i..i + 1));
            i += 1;
        } else {
            let ch = text[i..].chars().next().unwrap_or('?');
            return Err(SceneError::at(
                path,
                text,
                i..i + ch.len_utf8(),
                format!("unexpected character `{ch}`"),
            ));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use plenum_core::scene::Scene;

    fn read(text: &str) -> Result<(Scene, RenderDefaults, Vec<String>), SceneError> {
        parse(Path::new("t.ray"), text, Path::new(".")).map(|(b, d, w)| (b.build(), d, w))
    }

    fn constant(t: &Texture) -> Color {
        match t {
            Texture::Constant(c) => *c,
            _ => panic!("constant expected"),
        }
    }

    #[test]
    fn lexical_rules() {
        let text = "SBT-raytracer 1.0\r\n/* block\r\ncomment */ // line\r\ncamera { position = (.5, -0.0, 1e-005); aspectratio = 2; }\r\n";
        let (scene, defaults, _) = read(text).unwrap();
        assert_eq!(scene.camera.position, Vec3::new(0.5, 0.0, 1e-5));
        assert_eq!((defaults.width, defaults.height), (512, 256));
        assert!(read("SBT-raytracer 2.0\n")
            .unwrap_err()
            .message
            .contains("version"));
        assert!(read("camera {}\n").unwrap_err().message.contains("header"));
        let e = read("SBT-raytracer 1.0\nsphere { material = { diffuse = (1, 1, 1) } } @\n")
            .unwrap_err();
        assert_eq!((e.line, e.column), (2, 47));
    }

    #[test]
    fn dialects_differ_in_reflective_default_and_attenuation() {
        // B: reflective defaults to zero; missing coefficients are 0, 0, 1.
        let b = "SBT-raytracer 1.0\npoint_light { position = (0, 0, 1); colour = (1, 1, 1); constant_attenuation_coeff = 0.25; }\nsphere { material = { specular = (0.5, 0.5, 0.5); shininess = 0.5; }; }\n";
        let (scene, _, _) = read(b).unwrap();
        assert_eq!(
            constant(&scene.materials[0].phong().unwrap().reflective),
            Color::BLACK
        );
        assert_eq!(scene.materials[0].phong().unwrap().shininess, 64.0);
        match &scene.lights[0] {
            Light::Point { attenuation, .. } => assert_eq!(
                (
                    attenuation.constant,
                    attenuation.linear,
                    attenuation.quadratic
                ),
                (0.25, 0.0, 1.0)
            ),
            _ => panic!(),
        }
        // A (a named top-level material): reflective = specular; lights without falloff.
        let a = "SBT-raytracer 1.0\nmaterial { name = \"shiny\"; specular = (0.5, 0.5, 0.5); shininess = 76.8; }\npoint_light { position = (0, 0, 1); color = (1, 1, 1); }\nsphere { material = shiny; }\n";
        let (scene, _, _) = read(a).unwrap();
        assert_eq!(
            constant(&scene.materials[0].phong().unwrap().reflective),
            Color::gray(0.5)
        );
        assert_eq!(scene.materials[0].phong().unwrap().shininess, 76.8);
        match &scene.lights[0] {
            Light::Point { attenuation, .. } => assert_eq!(*attenuation, Attenuation::default()),
            _ => panic!(),
        }
        // A requires a material on every primitive.
        let e = read("SBT-raytracer 1.0\nmaterial { name = m; }\nbox { }\n").unwrap_err();
        assert!(e.message.contains("needs a material"), "{}", e.message);
    }

    #[test]
    fn transforms_nest_outside_in_with_radians() {
        let text = "SBT-raytracer 1.0\ntranslate(10, 0, 0, rotate(0, 0, 1, 1.5707963267948966, scale(2, 1, 1, sphere { })))\n";
        let (scene, _, _) = read(text).unwrap();
        let b = scene.geometry.bounds();
        // Scaled along x to 2, turned onto y, then moved: x in [9, 11], y in [-2, 2].
        assert!(
            (b.min.x - 9.0).abs() < 1e-9 && (b.max.y - 2.0).abs() < 1e-9,
            "{b:?}"
        );
        let m = "SBT-raytracer 1.0\ntransform((1,0,0,5),(0,1,0,0),(0,0,1,0),(0,0,0,1), box { });\n";
        let (scene, _, _) = read(m).unwrap();
        assert!((scene.geometry.bounds().min.x - 4.5).abs() < 1e-12);
    }

    #[test]
    fn meshes_quaternions_and_warnings() {
        let text = "SBT-raytracer 1.0\ncamera { quaternian = (0.7071067811865476, 0, 0.7071067811865476, 0); focus = 3; }\npolymesh { points = ((0,0,0),(1,0,0),(1,1,0),(0,1,0)); faces = ((0,1,2,3)); gennormals; }\n";
        let (scene, _, warnings) = read(text).unwrap();
        // A quarter turn about y: the default −z view becomes −x.
        let view = (scene.camera.look_at - scene.camera.position).normalized();
        assert!((view - -Vec3::X).length() < 1e-9, "{view:?}");
        assert_eq!(warnings.len(), 1);
        assert!(warnings[0].contains("unknown field `focus`"));
        match &scene.geometry.primitives[0].shape {
            Shape::Mesh(m) => assert_eq!(m.triangle_count(), 2),
            _ => panic!(),
        }
        let e = read("SBT-raytracer 1.0\ntrimesh { points = ((0,0,0),(1,0,0),(1,1,0)); faces = ((0,1,3)); }\n").unwrap_err();
        assert!(e.message.contains("out of range"));
        assert_eq!((e.line, e.column), (2, 61));
    }

    #[test]
    fn deep_nesting_is_a_located_error_not_a_stack_overflow() {
        // 100 000 levels overflowed the stack before nesting was bounded.
        for (open, close) in [("translate(0,0,0,", ")"), ("{", "}")] {
            let n = 100_000;
            let text = format!(
                "SBT-raytracer 1.0\nscale(1,{}sphere {{}}{})\n",
                open.repeat(n),
                close.repeat(n)
            );
            let e = read(&text).unwrap_err();
            assert!(e.message.contains("deeper than 256"), "{}", e.message);
            assert_eq!(e.line, 2);
            assert_eq!(e.column, "scale(1,".len() + 255 * open.len() + 1);
        }
        // As deep as allowed still reads.
        let text = format!(
            "SBT-raytracer 1.0\n{}sphere {{}}{}\n",
            "translate(1,0,0,".repeat(MAX_NESTING - 1),
            ")".repeat(MAX_NESTING - 1)
        );
        let (scene, _, _) = read(&text).unwrap();
        assert_eq!(scene.geometry.primitives.len(), 1);
    }
}
