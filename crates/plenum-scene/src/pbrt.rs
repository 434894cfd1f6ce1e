//! `plenum render scene.pbrt`: pbrt-v4's scene format (pbrt.org/fileformat-v4, and
//! ../shared/design/formats/pbrt.md). The statements are read in order with pbrt's graphics
//! state (the current transformation, material, area light and orientation, pushed and popped
//! by `AttributeBegin`/`End`); shapes, materials, lights, textures and the camera map onto
//! Plenum's as docs/pbrt.md tabulates. pbrt's camera space is left-handed: the camera is
//! `left_handed`, so images are not mirrored. Every parameter nothing reads gets a located
//! warning, as does every directive or type Plenum lacks.

use crate::diagnostics::{did_you_mean, SceneError};
use crate::limits::MAX_NESTING;
use crate::RenderDefaults;
use plenum_core::camera::{CameraSettings, Lens};
use plenum_core::color::Color;
use plenum_core::geometry::{Cylinder, Disk, Partial, Shape, Sphere, TriangleMesh, UvMap};
use plenum_core::integrator::IntegratorKind;
use plenum_core::light::{Attenuation, Light, Profile};
use plenum_core::material::{
    CoatedDiffuseMaterial, ConductorMaterial, ConductorSpec, DielectricMaterial, DiffuseMaterial,
    DiffuseTransmissionMaterial, FloatTexture, Material, Roughness, SpectralTexture, SpectrumKind,
    SpectrumValue, ThinDielectricMaterial,
};
use plenum_core::math::{Matrix4, Transform, Vec3};
use plenum_core::sampling::{FilterKind, Frame, SamplerKind};
use plenum_core::scene::{Alpha, Bitangent, Bump, MaterialId, SceneBuilder};
use plenum_core::texture::noise::MAX_OCTAVES;
use plenum_core::texture::{ImageTexture, Mapping, Noise, Texture, Wrap};
use plenum_spectrum::Spectrum;
use std::cell::Cell;
use std::collections::HashMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

type Result<T> = std::result::Result<T, SceneError>;

/// The deepest `Include` chain, and the most files a scene may read (a file that includes
/// another twice, which includes another twice, … would otherwise read 2^depth files).
const MAX_INCLUDE_DEPTH: usize = 32;
const MAX_FILES: usize = 4096;

/// Parses a pbrt-v4 scene: the scene, its render defaults, and warnings.
pub fn parse(path: &Path, text: String) -> Result<(SceneBuilder, RenderDefaults, Vec<String>)> {
    let mut p = Parser {
        sources: Vec::new(),
        builder: SceneBuilder::default(),
        defaults: RenderDefaults {
            integrator: Some(IntegratorKind::Path),
            max_depth: 4,
            spp: 16,
            sampler: SamplerKind::Sobol,
            filter: FilterKind::Gaussian,
            filter_radius: Some(1.5),
            width: 1280,
            height: 720,
            ..RenderDefaults::default()
        },
        warnings: Vec::new(),
        state: State::default(),
        stack: Vec::new(),
        named_materials: HashMap::new(),
        textures: HashMap::new(),
        coordinate_systems: HashMap::new(),
        objects: HashMap::new(),
        recording: None,
        camera: None,
        transform_times: (0.0, 1.0),
        film_size: None,
        default_material: None,
        count: 0,
        include_depth: 0,
        include_stack: vec![std::fs::canonicalize(path).ok()],
    };
    p.file(path.to_path_buf(), text)?;
    if !p.stack.is_empty() {
        let w = format!(
            "warning: {}: {} AttributeBegin without its AttributeEnd",
            path.display(),
            p.stack.len()
        );
        p.warnings.push(w);
    }
    p.finish();
    Ok((p.builder, p.defaults, p.warnings))
}

struct Source {
    path: PathBuf,
    text: String,
}

/// Where a token was written: a file of `sources` and a byte range.
#[derive(Clone, Debug)]
struct Loc {
    file: usize,
    span: Range<usize>,
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Word(String),
    Str(String),
    Num(f64),
    Open,
    Close,
}

/// A parameter: `"type name" values`.
#[derive(Clone)]
struct Param {
    ty: String,
    name: String,
    nums: Vec<f64>,
    strs: Vec<String>,
    bools: Vec<bool>,
    loc: Loc,
    used: Cell<bool>,
    /// Given by an `Attribute` directive, not the statement: a default that statements
    /// which have no use for it pass over without a warning.
    inherited: bool,
}

struct Params {
    list: Vec<Param>,
}

impl Params {
    fn get(&self, name: &str) -> Option<&Param> {
        let p = self.list.iter().rev().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }
}

/// The kinds of statement `Attribute` gives defaults for.
const ATTRIBUTE_KINDS: [&str; 5] = ["shape", "light", "material", "medium", "texture"];

/// pbrt's graphics state: what `AttributeBegin` saves and `AttributeEnd` restores.
#[derive(Clone, Default)]
struct State {
    /// The current transformation at the shutter-open time (`TransformTimes`' start).
    ctm: Option<Matrix4>,
    /// At the end time, where it differs (motion blur); else as `ctm`.
    ctm_end: Option<Matrix4>,
    /// Which of the two the transformation directives change (`ActiveTransform`).
    active: Active,
    /// `Attribute` defaults by the kind of statement they are for (`shape`, `light`,
    /// `material`, `medium`, `texture`), in the order given.
    attributes: HashMap<String, Vec<Param>>,
    material: Option<MaterialId>,
    area_light: Option<AreaLight>,
    reverse_orientation: bool,
}

/// `ActiveTransform`'s choice.
#[derive(Clone, Copy, Default, PartialEq, Eq)]
enum Active {
    #[default]
    All,
    Start,
    End,
}

#[derive(Clone)]
struct AreaLight {
    radiance: Color,
    spectrum: Option<(Spectrum, f64)>,
    two_sided: bool,
    /// An image over the surface's (u, v) (`filename`), in place of `L`.
    image: Option<Texture>,
    /// The power in watts the light is scaled to emit (`power`).
    power: Option<f64>,
}

/// A shape recorded between `ObjectBegin` and `ObjectEnd`.
#[derive(Clone)]
struct Recorded {
    name: String,
    shape: Shape,
    to_world: Matrix4,
    /// At the end time.
    to_world_end: Matrix4,
    material: MaterialId,
    alpha: Option<Alpha>,
}

struct Parser {
    sources: Vec<Source>,
    builder: SceneBuilder,
    defaults: RenderDefaults,
    warnings: Vec<String>,
    state: State,
    stack: Vec<(State, Loc)>,
    named_materials: HashMap<String, MaterialId>,
    /// Textures by name: spectrum and float textures share a namespace here, as a texture
    /// parameter names one of either kind.
    textures: HashMap<String, Texture>,
    /// Named coordinate systems: the transformations at the start and end times.
    coordinate_systems: HashMap<String, [Matrix4; 2]>,
    objects: HashMap<String, Vec<Recorded>>,
    recording: Option<(String, Vec<Recorded>)>,
    /// The camera statement: its camera-from-world matrices (start and end time),
    /// parameters and where.
    camera: Option<([Matrix4; 2], Params, String, Loc)>,
    /// `TransformTimes`: the times of the start and end transformations.
    transform_times: (f64, f64),
    film_size: Option<(u32, u32)>,
    default_material: Option<MaterialId>,
    count: usize,
    include_depth: usize,
    /// The files being read, outermost first, to refuse one that includes itself.
    include_stack: Vec<Option<PathBuf>>,
}

impl Parser {
    fn ctm(&self) -> Matrix4 {
        self.state.ctm.unwrap_or(Matrix4::IDENTITY)
    }

    /// The current transformation at the end time.
    fn ctm_end(&self) -> Matrix4 {
        self.state.ctm_end.unwrap_or(self.ctm())
    }

    /// Applies `f` to the current transformations `ActiveTransform` chose.
    fn set_ctm(&mut self, f: impl Fn(&Matrix4) -> Matrix4) {
        let (start, end) = (self.ctm(), self.ctm_end());
        // Both kept: an end left as it was must not follow a changed start.
        if self.state.active != Active::End {
            self.state.ctm = Some(f(&start));
        }
        self.state.ctm_end = Some(if self.state.active != Active::Start {
            f(&end)
        } else {
            end
        });
    }

    fn error(&self, loc: &Loc, message: impl Into<String>) -> SceneError {
        let s = &self.sources[loc.file];
        SceneError::at(&s.path, &s.text, loc.span.clone(), message)
    }

    /// A path written in file `file`, relative to that file's folder.
    fn path_in(&self, file: usize, name: &str) -> PathBuf {
        let base = self.sources[file].path.parent().unwrap_or(Path::new("."));
        base.join(name)
    }

    /// "unknown `what` `name`", with the nearest of `known` suggested.
    fn unknown(&self, loc: &Loc, what: &str, name: &str, known: &[&str]) -> SceneError {
        let e = self.error(loc, format!("unknown {what} `{name}`"));
        match did_you_mean(name, known.iter().copied()) {
            Some(s) => e.with_help(format!("did you mean `{s}`?")),
            None => e,
        }
    }

    fn warn(&mut self, loc: &Loc, message: impl Into<String>) {
        let w = self.error(loc, message).as_warning();
        self.warnings.push(w);
    }

    // ---- Tokens ----

    fn tokenize(&self, file: usize) -> Result<Vec<(Tok, Loc)>> {
        let text = &self.sources[file].text;
        let b = text.as_bytes();
        let mut out = Vec::new();
        let mut i = 0;
        let loc = |s: usize, e: usize| Loc { file, span: s..e };
        while i < b.len() {
            let c = b[i];
            if c.is_ascii_whitespace() {
                i += 1;
            } else if c == b'#' {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            } else if c == b'[' || c == b']' {
                out.push((
                    if c == b'[' { Tok::Open } else { Tok::Close },
                    loc(i, i + 1),
                ));
                i += 1;
            } else if c == b'"' {
                let start = i;
                i += 1;
                while i < b.len() && b[i] != b'"' && b[i] != b'\n' {
                    i += 1;
                }
                if i >= b.len() || b[i] != b'"' {
                    return Err(
                        self.error(&loc(start, start + 1), "a string without its closing quote")
                    );
                }
                out.push((Tok::Str(text[start + 1..i].to_string()), loc(start, i + 1)));
                i += 1;
            } else {
                let start = i;
                while i < b.len()
                    && !b[i].is_ascii_whitespace()
                    && !matches!(b[i], b'[' | b']' | b'"' | b'#')
                {
                    i += 1;
                }
                let word = &text[start..i];
                let first = word.as_bytes()[0];
                if first.is_ascii_digit() || matches!(first, b'-' | b'+' | b'.') {
                    match word.parse::<f64>() {
                        Ok(x) if x.is_finite() => out.push((Tok::Num(x), loc(start, i))),
                        _ => {
                            return Err(self.error(
                                &loc(start, i),
                                format!("expected a number, found `{word}`"),
                            ))
                        }
                    }
                } else {
                    out.push((Tok::Word(word.to_string()), loc(start, i)));
                }
            }
        }
        Ok(out)
    }

    fn file(&mut self, path: PathBuf, text: String) -> Result<()> {
        let file = self.sources.len();
        self.sources.push(Source { path, text });
        let toks = self.tokenize(file)?;
        let mut i = 0;
        while i < toks.len() {
            let (tok, loc) = &toks[i];
            let Tok::Word(directive) = tok else {
                return Err(self.error(loc, "expected a directive such as Shape or LightSource"));
            };
            i += 1;
            // Its arguments: every token up to the next directive (a bare true or false is a
            // value; `ActiveTransform` takes a bare word).
            let mut args: Vec<(Tok, Loc)> = Vec::new();
            if directive == "ActiveTransform" {
                if let Some((Tok::Word(_), _)) = toks.get(i) {
                    args.push(toks[i].clone());
                    i += 1;
                }
            }
            while i < toks.len() {
                if matches!(&toks[i].0, Tok::Word(w) if w != "true" && w != "false") {
                    break;
                }
                args.push(toks[i].clone());
                i += 1;
            }
            let (positional, params_start) = split_positional(directive, &args);
            let params = self.params(&args[params_start..])?;
            self.statement(directive, loc, &positional, params)?;
        }
        Ok(())
    }

    /// A parameter list: `"type name" value` or `"type name" [ values ]`.
    fn params(&self, toks: &[(Tok, Loc)]) -> Result<Params> {
        let mut list = Vec::new();
        let mut i = 0;
        while i < toks.len() {
            let (tok, loc) = &toks[i];
            let Tok::Str(decl) = tok else {
                return Err(self.error(loc, "expected a parameter such as \"float radius\""));
            };
            let mut words = decl.split_whitespace();
            let (Some(ty), Some(name), None) = (words.next(), words.next(), words.next()) else {
                return Err(self.error(loc, format!("expected \"type name\", found \"{decl}\"")));
            };
            i += 1;
            let mut values: Vec<(Tok, Loc)> = Vec::new();
            match toks.get(i) {
                Some((Tok::Open, _)) => {
                    i += 1;
                    while i < toks.len() && toks[i].0 != Tok::Close {
                        values.push(toks[i].clone());
                        i += 1;
                    }
                    if i >= toks.len() {
                        return Err(self.error(loc, "a `[` without its `]`"));
                    }
                    i += 1;
                }
                Some((Tok::Num(_) | Tok::Str(_) | Tok::Word(_), _)) => {
                    values.push(toks[i].clone());
                    i += 1;
                }
                _ => return Err(self.error(loc, format!("the parameter \"{decl}\" has no value"))),
            }
            let (mut nums, mut strs, mut bools) = (Vec::new(), Vec::new(), Vec::new());
            for (v, vloc) in &values {
                match v {
                    Tok::Num(x) => nums.push(*x),
                    Tok::Str(s) if ty == "bool" => bools.push(self.boolean(s, vloc)?),
                    Tok::Word(s) if ty == "bool" => bools.push(self.boolean(s, vloc)?),
                    Tok::Str(s) => strs.push(s.clone()),
                    _ => return Err(self.error(vloc, format!("unexpected value in \"{decl}\""))),
                }
            }
            let numeric = matches!(
                ty,
                "integer"
                    | "float"
                    | "point2"
                    | "vector2"
                    | "point3"
                    | "vector3"
                    | "normal3"
                    | "normal"
                    | "point"
                    | "vector"
                    | "rgb"
                    | "color"
                    | "blackbody"
            );
            let stringy = matches!(ty, "string" | "texture");
            let ok = (numeric && strs.is_empty() && !nums.is_empty())
                || (stringy && nums.is_empty() && !strs.is_empty())
                || (ty == "bool" && !bools.is_empty())
                || (ty == "spectrum"
                    && (strs.len() == 1 && nums.is_empty() || strs.is_empty() && !nums.is_empty()));
            if !ok {
                let known = [
                    "integer",
                    "float",
                    "point2",
                    "vector2",
                    "point3",
                    "vector3",
                    "normal3",
                    "normal",
                    "bool",
                    "string",
                    "rgb",
                    "blackbody",
                    "spectrum",
                    "texture",
                ];
                if !known.contains(&ty) && !matches!(ty, "point" | "vector" | "color") {
                    let e = self.error(loc, format!("unknown parameter type `{ty}`"));
                    return Err(match did_you_mean(ty, known) {
                        Some(s) => e.with_help(format!("did you mean `{s}`?")),
                        None => e,
                    });
                }
                return Err(
                    self.error(loc, format!("the values of \"{decl}\" are not {ty} values"))
                );
            }
            let width = match ty {
                "point2" | "vector2" => 2,
                "point3" | "vector3" | "normal3" | "normal" | "point" | "vector" | "rgb"
                | "color" => 3,
                "spectrum" if !nums.is_empty() => 2,
                _ => 1,
            };
            if nums.len() % width != 0 {
                return Err(self.error(
                    loc,
                    format!(
                        "\"{decl}\" takes numbers in groups of {width}, found {}",
                        nums.len()
                    ),
                ));
            }
            list.push(Param {
                ty: ty.to_string(),
                name: name.to_string(),
                nums,
                strs,
                bools,
                loc: loc.clone(),
                used: Cell::new(false),
                inherited: false,
            });
        }
        Ok(Params { list })
    }

    fn boolean(&self, s: &str, loc: &Loc) -> Result<bool> {
        match s {
            "true" => Ok(true),
            "false" => Ok(false),
            _ => Err(self.error(loc, format!("expected true or false, found `{s}`"))),
        }
    }
}

/// Directives that take one quoted positional string and then parameters.
fn takes_one_string(d: &str) -> bool {
    matches!(
        d,
        "Shape"
            | "Material"
            | "LightSource"
            | "AreaLightSource"
            | "Camera"
            | "Film"
            | "Sampler"
            | "PixelFilter"
            | "Integrator"
            | "Accelerator"
            | "MakeNamedMaterial"
            | "MakeNamedMedium"
            | "ColorSpace"
            | "Attribute"
    )
}

fn param_directive(d: &str) -> bool {
    takes_one_string(d) || d == "Texture"
}

/// How many quoted strings come before a directive's parameters.
fn positional_count(d: &str) -> usize {
    match d {
        "Texture" => 3,
        _ if takes_one_string(d) => 1,
        _ => usize::MAX,
    }
}

/// The positional arguments of a directive and where its parameter list starts.
fn split_positional(d: &str, args: &[(Tok, Loc)]) -> (Vec<(Tok, Loc)>, usize) {
    if !param_directive(d) {
        return (args.to_vec(), args.len());
    }
    let n = positional_count(d);
    let mut taken = 0;
    let mut end = 0;
    for (i, (t, _)) in args.iter().enumerate() {
        if taken == n {
            break;
        }
        if matches!(t, Tok::Str(_)) {
            taken += 1;
        }
        end = i + 1;
    }
    (args[..end].to_vec(), end)
}

/// pbrt's matrices are written column by column.
fn column_major(n: &[f64]) -> Matrix4 {
    let mut m = Matrix4::IDENTITY;
    for c in 0..4 {
        for r in 0..4 {
            m.0[r][c] = n[c * 4 + r];
        }
    }
    m
}

/// The names pbrt-v4's `Option` knows.
const PBRT_OPTIONS: [&str; 11] = [
    "disablepixeljitter",
    "disabletexturefiltering",
    "disablewavelengthjitter",
    "displacementedgescale",
    "forcediffuse",
    "msereferenceimage",
    "msereferenceout",
    "pixelstats",
    "rendercoordsys",
    "seed",
    "wavefront",
];

/// The (u, v) pbrt-v4 gives the corners of a triangle without uv.
const PBRT_TRIANGLE_UVS: [[f64; 2]; 3] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]];

/// The orthonormal frame whose axes are the light-space directions `axes` placed by `t`
/// (pbrt-v4 composes a swap or a flip into some lights' transformations).
fn light_frame(t: &Transform, axes: [Vec3; 3]) -> Frame {
    let [x, y, z] = axes.map(|a| t.vector(a));
    let z = z.normalized();
    let x = (x - z * x.dot(z)).normalized();
    // Keep y's side (the frame may be left-handed), square to the others.
    let y = (y - z * y.dot(z) - x * y.dot(x)).normalized();
    Frame { x, y, z }
}

fn finite(v: Vec3) -> bool {
    v.x.is_finite() && v.y.is_finite() && v.z.is_finite()
}

impl Parser {
    // ---- Parameters ----

    fn float(&self, p: &Params, name: &str, default: f64) -> Result<f64> {
        match p.get(name) {
            None => Ok(default),
            Some(q) if matches!(q.ty.as_str(), "float" | "integer") && q.nums.len() == 1 => {
                Ok(q.nums[0])
            }
            Some(q) => Err(self.error(&q.loc, format!("expected one float for `{name}`"))),
        }
    }

    fn positive(&self, p: &Params, name: &str, default: f64) -> Result<f64> {
        let x = self.float(p, name, default)?;
        if x > 0.0 {
            Ok(x)
        } else {
            Err(self.error(
                &p.get(name).unwrap().loc,
                format!("expected `{name}` > 0, found {x}"),
            ))
        }
    }

    fn integer(&self, p: &Params, name: &str, default: i64) -> Result<i64> {
        match p.get(name) {
            None => Ok(default),
            Some(q) if q.ty == "integer" && q.nums.len() == 1 && q.nums[0].fract() == 0.0 => {
                Ok(q.nums[0] as i64)
            }
            Some(q) => Err(self.error(&q.loc, format!("expected one integer for `{name}`"))),
        }
    }

    fn boolean_param(&self, p: &Params, name: &str, default: bool) -> Result<bool> {
        match p.get(name) {
            None => Ok(default),
            Some(q) if q.bools.len() == 1 => Ok(q.bools[0]),
            Some(q) => Err(self.error(&q.loc, format!("expected one bool for `{name}`"))),
        }
    }

    fn string<'p>(&self, p: &'p Params, name: &str) -> Result<Option<(&'p str, Loc)>> {
        match p.get(name) {
            None => Ok(None),
            Some(q) if q.strs.len() == 1 && q.ty == "string" => {
                Ok(Some((q.strs[0].as_str(), q.loc.clone())))
            }
            Some(q) => Err(self.error(&q.loc, format!("expected one string for `{name}`"))),
        }
    }

    fn point(&self, p: &Params, name: &str, default: Vec3) -> Result<Vec3> {
        match p.get(name) {
            None => Ok(default),
            Some(q) if q.nums.len() == 3 => Ok(Vec3::new(q.nums[0], q.nums[1], q.nums[2])),
            Some(q) => Err(self.error(&q.loc, format!("expected one point for `{name}`"))),
        }
    }

    fn vectors(&self, q: &Param) -> Vec<Vec3> {
        q.nums
            .chunks_exact(3)
            .map(|c| Vec3::new(c[0], c[1], c[2]))
            .collect()
    }

    /// A spectrum parameter's spectrum: a name, (λ, value) pairs, or a blackbody.
    fn spectrum(&self, q: &Param) -> Result<Spectrum> {
        if q.ty == "blackbody" {
            if q.nums.len() != 1 || q.nums[0] <= 0.0 {
                return Err(self.error(&q.loc, "expected one temperature in kelvin"));
            }
            return Ok(Spectrum::blackbody(q.nums[0], 1.0));
        }
        if let [name] = q.strs.as_slice() {
            if let Some(s) = plenum_spectrum::named(name) {
                return Ok(s);
            }
            // Otherwise a file of (λ, value) pairs, as pbrt-v4 reads it: numbers separated
            // by white space, `#` to the end of a line a comment.
            let path = self.path_in(q.loc.file, name);
            if let Ok(text) = std::fs::read_to_string(&path) {
                let mut numbers = Vec::new();
                for (i, line) in text.lines().enumerate() {
                    let line = line.split('#').next().unwrap_or_default();
                    for word in line.split_whitespace() {
                        match word.parse::<f64>() {
                            Ok(x) if x.is_finite() => numbers.push(x),
                            _ => {
                                return Err(self.error(
                                    &q.loc,
                                    format!(
                                        "{}:{}: expected a number, found `{word}`",
                                        path.display(),
                                        i + 1
                                    ),
                                ))
                            }
                        }
                    }
                }
                if numbers.len() % 2 != 0 {
                    return Err(self.error(
                        &q.loc,
                        format!(
                            "{}: {} numbers: expected (wavelength, value) pairs",
                            path.display(),
                            numbers.len()
                        ),
                    ));
                }
                let pairs: Vec<(f64, f64)> =
                    numbers.chunks_exact(2).map(|c| (c[0], c[1])).collect();
                return Spectrum::piecewise(&pairs)
                    .map_err(|e| self.error(&q.loc, format!("{}: {e}", path.display())));
            }
            let e = self.error(
                &q.loc,
                format!("unknown spectrum `{name}`: neither a named spectrum nor a readable file"),
            );
            return Err(
                match did_you_mean(name, plenum_spectrum::names().iter().copied()) {
                    Some(s) => e.with_help(format!("did you mean `{s}`?")),
                    None => e.with_help("see docs/spectra.md for the named spectra"),
                },
            );
        }
        let pairs: Vec<(f64, f64)> = q.nums.chunks_exact(2).map(|c| (c[0], c[1])).collect();
        Spectrum::piecewise(&pairs).map_err(|e| self.error(&q.loc, e))
    }

    /// A reflectance-like parameter: rgb, float, spectrum or texture.
    fn spectral(
        &self,
        p: &Params,
        name: &str,
        default: f64,
        kind: SpectrumKind,
    ) -> Result<SpectralTexture> {
        let Some(q) = p.get(name) else {
            return Ok(SpectralTexture::constant(Color::gray(default), kind));
        };
        Ok(match q.ty.as_str() {
            "rgb" | "color" if q.nums.len() == 3 => {
                SpectralTexture::constant(Color::new(q.nums[0], q.nums[1], q.nums[2]), kind)
            }
            "float" if q.nums.len() == 1 => SpectralTexture::constant(Color::gray(q.nums[0]), kind),
            "spectrum" | "blackbody" => {
                SpectralTexture::Constant(SpectrumValue::new(self.spectrum(q)?, kind))
            }
            "texture" => SpectralTexture::from_texture(self.texture_ref(q)?, kind),
            _ => {
                return Err(self.error(
                    &q.loc,
                    format!("expected `{name}` to be an rgb, spectrum or texture"),
                ))
            }
        })
    }

    fn texture_ref(&self, q: &Param) -> Result<Texture> {
        let name = &q.strs[0];
        self.textures.get(name).cloned().ok_or_else(|| {
            let e = self.error(
                &q.loc,
                format!("no texture named `{name}` is defined above"),
            );
            match did_you_mean(name, self.textures.keys().map(String::as_str)) {
                Some(s) => e.with_help(format!("did you mean `{s}`?")),
                None => e,
            }
        })
    }

    /// A float parameter that may be a texture.
    fn float_texture(&self, p: &Params, name: &str, default: f64) -> Result<FloatTexture> {
        match p.get(name) {
            Some(q) if q.ty == "texture" => Ok(match self.texture_ref(q)? {
                Texture::Constant(c) => FloatTexture::Constant((c.r + c.g + c.b) / 3.0),
                t => FloatTexture::Texture(t),
            }),
            _ => Ok(FloatTexture::Constant(self.float(p, name, default)?)),
        }
    }

    /// Emitted light as pbrt-v4 normalises it: an rgb value as written (its spectrum is the
    /// colour space's illuminant, whose luminance pbrt divides out); a spectrum or
    /// blackbody scaled to luminance 1. Then times `scale`.
    /// Gives the area light just placed its image and spectrum, and scales it to its power:
    /// pbrt-v4 divides the power by π, the light's area, its sides and the mean luminance
    /// of its image (not of `L`, whose luminance then still multiplies the power).
    fn finish_area_light(&mut self, a: AreaLight, loc: &Loc) {
        let mut k = 1.0;
        if let (Some(watts), Some(Light::Area { shape, .. })) = (a.power, self.builder.last_light())
        {
            let luminance = a.image.as_ref().map_or(1.0, |t| t.average().luminance());
            let sides = if a.two_sided { 2.0 } else { 1.0 };
            let emitted = std::f64::consts::PI * sides * shape.area() * luminance;
            if emitted > 0.0 {
                k = watts / emitted;
            }
        }
        match (a.image, a.spectrum) {
            (Some(image), _) => {
                self.builder.scale_last_light(k);
                if !self.builder.set_last_light_texture(image) {
                    self.warn(
                        loc,
                        "an image on this shape's light is not supported: white",
                    );
                }
            }
            (None, Some((s, scale))) => self.builder.set_last_light_spectrum(s, scale * k),
            (None, None) => self.builder.scale_last_light(k),
        }
    }

    /// The image at `path` as a texture, each texel through `texel`; 8-bit images decoded
    /// from sRGB unless `linear`. An unreadable image is warned about at `floc`, saying
    /// what is used instead (`fallback`): `None`.
    #[allow(clippy::too_many_arguments)]
    fn image(
        &mut self,
        path: &Path,
        floc: &Loc,
        fallback: &str,
        linear: bool,
        texel: impl Fn(Color) -> Color,
        scale_uv: [f64; 2],
        wrap: Wrap,
    ) -> Result<Option<Texture>> {
        let read = if linear {
            plenum_image::read_data_texture(path)
        } else {
            plenum_image::read_texture(path)
        };
        let texels = match read {
            Ok(t) => t,
            Err(e) => {
                self.warn(floc, format!("{e}: {fallback}"));
                return Ok(None);
            }
        };
        let (width, height) = (texels.width, texels.height);
        let rgb = texels.rgb.iter();
        let texels = rgb.map(|t| texel(Color::new(t[0] as f64, t[1] as f64, t[2] as f64)));
        match ImageTexture::new(width, height, texels.collect(), scale_uv) {
            Some(i) => Ok(Some(Texture::Image(Arc::new(i.with_wrap([wrap; 2]))))),
            None => Err(self.error(floc, "the image is empty")),
        }
    }

    fn emission(&self, p: &Params, name: &str) -> Result<(Color, Option<(Spectrum, f64)>)> {
        let scale = self.float(p, "scale", 1.0)?;
        let Some(q) = p.get(name) else {
            return Ok((Color::WHITE * scale, None));
        };
        match q.ty.as_str() {
            "rgb" | "color" if q.nums.len() == 3 => {
                let c = Color::new(q.nums[0], q.nums[1], q.nums[2]);
                if c.r < 0.0 || c.g < 0.0 || c.b < 0.0 {
                    return Err(self.error(&q.loc, format!("expected `{name}` ≥ 0")));
                }
                Ok((c * scale, None))
            }
            "spectrum" | "blackbody" => {
                let s = self.spectrum(q)?;
                let [r, g, b] = s.to_rgb_illuminant();
                let c = Color::new(r, g, b);
                let y = c.luminance();
                if y.is_nan() || y <= 0.0 {
                    return Err(self.error(&q.loc, "a light spectrum with no luminance"));
                }
                let k = scale / y;
                Ok((c * k, Some((s, k))))
            }
            _ => Err(self.error(
                &q.loc,
                format!("expected `{name}` to be an rgb, spectrum or blackbody"),
            )),
        }
    }

    fn roughness(&self, p: &Params) -> Result<Roughness> {
        let remap = self.boolean_param(p, "remaproughness", true)?;
        let r = self.float_texture(p, "roughness", 0.0)?;
        let u = if p.get("uroughness").is_some() {
            self.float_texture(p, "uroughness", 0.0)?
        } else {
            r.clone()
        };
        let v = if p.get("vroughness").is_some() {
            self.float_texture(p, "vroughness", 0.0)?
        } else {
            r
        };
        Ok(Roughness { u, v, remap })
    }

    fn eta(&self, p: &Params) -> Result<SpectrumValue> {
        let s = match p.get("eta") {
            None => Spectrum::Constant(1.5),
            Some(q) if q.ty == "float" && q.nums.len() == 1 && q.nums[0] > 0.0 => {
                Spectrum::Constant(q.nums[0])
            }
            Some(q) if q.ty == "spectrum" => self.spectrum(q)?,
            Some(q) => {
                return Err(self.error(
                    &q.loc,
                    "expected `eta` to be a positive float or a spectrum",
                ))
            }
        };
        Ok(SpectrumValue::new(s, SpectrumKind::Unbounded))
    }

    // ---- Statements ----

    /// pbrt-v4's `Option "name" value`: a rendering option given in the scene (a type
    /// before the name, as in `"bool disablepixeljitter"`, is read past).
    fn option(&mut self, args: &[(Tok, Loc)], loc: &Loc) -> Result<()> {
        let mut rest = args
            .iter()
            .filter(|(t, _)| !matches!(t, Tok::Open | Tok::Close));
        let Some((Tok::Str(given), name_loc)) = rest.next() else {
            return Err(self.error(
                loc,
                "Option needs a quoted name and a value, as in Option \"seed\" 7",
            ));
        };
        let Some((value, value_loc)) = rest.next() else {
            return Err(self.error(name_loc, format!("Option \"{given}\" needs a value")));
        };
        if let Some((_, extra)) = rest.next() {
            return Err(self.error(extra, "Option takes one value"));
        }
        // pbrt-v4 ignores case, `_` and `-` in option names.
        let name: String = given
            .rsplit(' ')
            .next()
            .unwrap_or_default()
            .chars()
            .filter(|c| *c != '_' && *c != '-')
            .flat_map(char::to_lowercase)
            .collect();
        let kind = match name.as_str() {
            "disablepixeljitter"
            | "disabletexturefiltering"
            | "disablewavelengthjitter"
            | "forcediffuse"
            | "pixelstats"
            | "wavefront" => "bool",
            "seed" => "integer",
            "displacementedgescale" => "float",
            "msereferenceimage" | "msereferenceout" | "rendercoordsys" => "string",
            _ => {
                return Err(self.unknown(name_loc, "option", given, &PBRT_OPTIONS));
            }
        };
        let fits = match (kind, value) {
            ("bool", Tok::Word(_)) => true,
            ("integer", Tok::Num(x)) => x.fract() == 0.0,
            ("float", Tok::Num(_)) => true,
            ("string", Tok::Str(_)) => true,
            _ => false,
        };
        if !fits {
            let expected = match kind {
                "bool" => "true or false",
                "integer" => "a whole number",
                "float" => "a number",
                _ => "a quoted string",
            };
            return Err(self.error(
                value_loc,
                format!("expected {expected} for Option \"{given}\""),
            ));
        }
        let on = matches!(value, Tok::Word(w) if w == "true");
        let ignored = |what: &str| format!("Option \"{given}\" ({what}) is not supported: ignored");
        match name.as_str() {
            // What pbrt-v4 computes in, how it runs, or its seed: the same image.
            "seed" | "wavefront" => {}
            "rendercoordsys" => {
                let Tok::Str(space) = value else {
                    unreachable!()
                };
                if !matches!(space.as_str(), "camera" | "cameraworld" | "world") {
                    return Err(self.error(
                        value_loc,
                        format!("unknown rendering space `{space}`: expected camera, cameraworld or world"),
                    ));
                }
            }
            // Options switched off change nothing.
            "disablepixeljitter"
            | "disabletexturefiltering"
            | "disablewavelengthjitter"
            | "forcediffuse"
            | "pixelstats"
                if !on => {}
            "disablepixeljitter" => self.warn(loc, ignored("samples at pixel centres")),
            "disabletexturefiltering" => self.warn(
                loc,
                ignored("point-sampled textures; Plenum's images are interpolated bilinearly"),
            ),
            "disablewavelengthjitter" => self.warn(loc, ignored("fixed wavelengths")),
            "forcediffuse" => self.warn(loc, ignored("every material made diffuse")),
            "pixelstats" => self.warn(loc, ignored("per-pixel statistics images")),
            "displacementedgescale" => self.warn(loc, ignored("displacement tessellation")),
            _ => self.warn(loc, ignored("an error image against a reference")),
        }
        Ok(())
    }

    fn statement(&mut self, d: &str, loc: &Loc, args: &[(Tok, Loc)], params: Params) -> Result<()> {
        // `Attribute` defaults come first: the statement's own parameters, found later, win.
        let kind = match d {
            "Shape" => Some("shape"),
            "LightSource" | "AreaLightSource" => Some("light"),
            "Material" | "MakeNamedMaterial" => Some("material"),
            "Texture" => Some("texture"),
            "MakeNamedMedium" => Some("medium"),
            _ => None,
        };
        let params = match kind.and_then(|k| self.state.attributes.get(k)) {
            Some(given) => Params {
                list: given.iter().cloned().chain(params.list).collect(),
            },
            None => params,
        };
        let nums: Vec<f64> = args
            .iter()
            .filter_map(|(t, _)| if let Tok::Num(x) = t { Some(*x) } else { None })
            .collect();
        let strs: Vec<String> = args
            .iter()
            .filter_map(|(t, _)| {
                if let Tok::Str(s) = t {
                    Some(s.clone())
                } else {
                    None
                }
            })
            .collect();
        let need_nums = |n: usize| -> Result<()> {
            if nums.len() != n {
                return Err(self.error(loc, format!("{d} takes {n} numbers, found {}", nums.len())));
            }
            Ok(())
        };
        let need_str = |what: &str| -> Result<String> {
            strs.first()
                .cloned()
                .ok_or_else(|| self.error(loc, format!("{d} needs {what}")))
        };
        let ctm = self.ctm();
        // A directive's own transformation, multiplied onto the current ones on the right.
        let checked = |t: Option<Transform>| -> Result<Matrix4> {
            t.map(|t| t.matrix)
                .ok_or_else(|| self.error(loc, format!("a singular {d}")))
        };
        let mut name_of_type = String::new();
        match d {
            "Identity" => self.set_ctm(|_| Matrix4::IDENTITY),
            "Translate" => {
                need_nums(3)?;
                let t = checked(Some(Transform::translate(Vec3::new(
                    nums[0], nums[1], nums[2],
                ))))?;
                self.set_ctm(|c| c.mul(&t));
            }
            "Scale" => {
                need_nums(3)?;
                let t = checked(Transform::scale(Vec3::new(nums[0], nums[1], nums[2])))?;
                self.set_ctm(|c| c.mul(&t));
            }
            "Rotate" => {
                need_nums(4)?;
                let t = checked(Transform::rotate(
                    Vec3::new(nums[1], nums[2], nums[3]),
                    nums[0],
                ))?;
                self.set_ctm(|c| c.mul(&t));
            }
            "LookAt" => {
                need_nums(9)?;
                let eye = Vec3::new(nums[0], nums[1], nums[2]);
                let look = Vec3::new(nums[3], nums[4], nums[5]);
                let up = Vec3::new(nums[6], nums[7], nums[8]);
                // pbrt's camera frame: right = up × dir, up' = dir × right (left-handed).
                let dir = (look - eye).normalized();
                let right = up.normalized().cross(dir).normalized();
                let new_up = dir.cross(right);
                if !(finite(dir) && finite(right) && right.length() > 0.5) {
                    return Err(self.error(
                        loc,
                        "a LookAt whose target is its eye, or whose up is along the view",
                    ));
                }
                let world_from_camera = Transform::frame(eye, right, new_up, dir);
                let t = checked(world_from_camera.map(|t| t.inverted()))?;
                self.set_ctm(|c| c.mul(&t));
            }
            "Transform" | "ConcatTransform" => {
                need_nums(16)?;
                let m = column_major(&nums);
                if Transform::from_matrix(m).is_none() {
                    return Err(
                        self.error(loc, format!("{d}: the matrix is singular, or not affine"))
                    );
                }
                if d == "Transform" {
                    self.set_ctm(|_| m);
                } else {
                    self.set_ctm(|c| c.mul(&m));
                }
            }
            "CoordinateSystem" => {
                let name = need_str("a name")?;
                let both = [ctm, self.ctm_end()];
                self.coordinate_systems.insert(name, both);
            }
            "CoordSysTransform" => {
                let name = need_str("a name")?;
                match self.coordinate_systems.get(&name).copied() {
                    Some([start, end]) => {
                        self.state.ctm = Some(start);
                        self.state.ctm_end = Some(end);
                    }
                    None => self.warn(
                        loc,
                        format!(
                            "no coordinate system named `{name}`: the transformation is unchanged"
                        ),
                    ),
                }
            }
            "ActiveTransform" => {
                // A bare word (or, leniently, a quoted one).
                let word = args.iter().find_map(|(t, _)| match t {
                    Tok::Word(w) | Tok::Str(w) => Some(w.clone()),
                    _ => None,
                });
                let Some(word) = word else {
                    return Err(self.error(loc, "ActiveTransform needs StartTime, EndTime or All"));
                };
                self.state.active = match word.as_str() {
                    "StartTime" => Active::Start,
                    "EndTime" => Active::End,
                    "All" => Active::All,
                    other => {
                        return Err(self.unknown(
                            loc,
                            "ActiveTransform",
                            other,
                            &["StartTime", "EndTime", "All"],
                        ))
                    }
                };
            }
            "TransformTimes" => {
                need_nums(2)?;
                if !(nums[0].is_finite() && nums[1].is_finite() && nums[1] > nums[0]) {
                    return Err(self.error(
                        loc,
                        format!(
                            "TransformTimes: expected an end time after the start, not {} and {}",
                            nums[0], nums[1]
                        ),
                    ));
                }
                self.transform_times = (nums[0], nums[1]);
            }
            "ReverseOrientation" => {
                self.state.reverse_orientation = !self.state.reverse_orientation
            }
            "AttributeBegin" | "TransformBegin" => {
                if d == "TransformBegin" {
                    self.warn(
                        loc,
                        "TransformBegin is deprecated in pbrt-v4: read as AttributeBegin",
                    );
                }
                if self.stack.len() >= MAX_NESTING {
                    return Err(self.error(loc, format!("{d} nested deeper than {MAX_NESTING}")));
                }
                self.stack.push((self.state.clone(), loc.clone()));
            }
            "AttributeEnd" | "TransformEnd" => match self.stack.pop() {
                Some((state, _)) => {
                    if d == "TransformEnd" {
                        self.state.ctm = state.ctm;
                        self.state.ctm_end = state.ctm_end;
                    } else {
                        self.state = state;
                    }
                }
                None => return Err(self.error(loc, format!("{d} without a matching begin"))),
            },
            "WorldBegin" => {
                self.state.ctm = Some(Matrix4::IDENTITY);
                self.state.ctm_end = None;
                self.coordinate_systems
                    .insert("world".into(), [Matrix4::IDENTITY; 2]);
            }
            "WorldEnd" => self.warn(loc, "WorldEnd is pbrt-v3's: ignored"),
            "Attribute" => {
                let kind = need_str("shape, light, material, medium or texture")?;
                if !ATTRIBUTE_KINDS.contains(&kind.as_str()) {
                    return Err(self.unknown(loc, "Attribute kind", &kind, &ATTRIBUTE_KINDS));
                }
                let given = self.state.attributes.entry(kind).or_default();
                for q in &params.list {
                    q.used.set(true);
                    given.push(Param {
                        used: Cell::new(false),
                        inherited: true,
                        ..q.clone()
                    });
                }
            }
            "Option" => self.option(args, loc)?,
            "MakeNamedMedium" | "MediumInterface" => {
                self.warn(loc, format!("{d} is not supported: ignored"));
                params.list.iter().for_each(|p| p.used.set(true));
            }
            "ColorSpace" => {
                let name = need_str("a colour space")?;
                if name != "srgb" {
                    self.warn(
                        loc,
                        format!("the colour space `{name}` is not supported: sRGB is used"),
                    );
                }
            }
            "Accelerator" => params.list.iter().for_each(|p| p.used.set(true)),
            "Camera" => {
                name_of_type = need_str("a type")?;
                let both = [ctm, self.ctm_end()];
                let mut world_from_camera = [Matrix4::IDENTITY; 2];
                for (w, m) in world_from_camera.iter_mut().zip(both) {
                    *w = Transform::from_matrix(m)
                        .ok_or_else(|| self.error(loc, "the camera's transformation is singular"))?
                        .inverted()
                        .matrix;
                }
                self.coordinate_systems
                    .insert("camera".into(), world_from_camera);
                // Read at the end, when the film's size is known; its parameters are
                // reported then.
                self.camera = Some((both, params, name_of_type, loc.clone()));
                return Ok(());
            }
            "Film" => {
                name_of_type = need_str("a type")?;
                self.film(&name_of_type, &params, loc)?;
            }
            "Sampler" => {
                name_of_type = need_str("a type")?;
                self.sampler(&name_of_type, &params, loc)?;
            }
            "PixelFilter" => {
                name_of_type = need_str("a type")?;
                self.pixel_filter(&name_of_type, &params, loc)?;
            }
            "Integrator" => {
                name_of_type = need_str("a type")?;
                self.integrator(&name_of_type, &params, loc)?;
            }
            "Material" => {
                name_of_type = need_str("a type")?;
                let id = self.material(&name_of_type, None, &params, loc)?;
                self.state.material = Some(id);
            }
            "MakeNamedMaterial" => {
                let name = need_str("a name")?;
                let Some((ty, _)) = self.string(&params, "type")? else {
                    return Err(self.error(
                        loc,
                        format!("the material `{name}` needs a \"string type\""),
                    ));
                };
                let ty = ty.to_string();
                name_of_type = ty.clone();
                let id = self.material(&ty, Some(&name), &params, loc)?;
                self.named_materials.insert(name, id);
            }
            "NamedMaterial" => {
                let name = need_str("a name")?;
                match self.named_materials.get(&name) {
                    Some(&id) => self.state.material = Some(id),
                    None => {
                        let e =
                            self.error(loc, format!("no material named `{name}` is defined above"));
                        return Err(
                            match did_you_mean(
                                &name,
                                self.named_materials.keys().map(String::as_str),
                            ) {
                                Some(s) => e.with_help(format!("did you mean `{s}`?")),
                                None => e,
                            },
                        );
                    }
                }
            }
            "Texture" => {
                if strs.len() < 3 {
                    return Err(self.error(
                        loc,
                        "Texture takes a name, \"spectrum\" or \"float\", and a class",
                    ));
                }
                name_of_type = strs[2].clone();
                let t = self.texture(&strs[1], &strs[2], &params, loc)?;
                self.textures.insert(strs[0].clone(), t);
            }
            "LightSource" => {
                name_of_type = need_str("a type")?;
                self.light(&name_of_type, &params, loc)?;
            }
            "AreaLightSource" => {
                name_of_type = need_str("a type")?;
                if name_of_type != "diffuse" {
                    return Err(self.error(
                        loc,
                        format!("unknown area light `{name_of_type}`: pbrt-v4 has \"diffuse\""),
                    ));
                }
                let (radiance, spectrum) = self.emission(&params, "L")?;
                let two_sided = self.boolean_param(&params, "twosided", false)?;
                // An image's RGB, read linear (8-bit decoded from sRGB) and clamped at its
                // edges as pbrt-v4's `BilerpChannel` does, is the radiance, times `scale`.
                let image = match self.string(&params, "filename")? {
                    None => None,
                    Some(_) if params.get("L").is_some() => {
                        return Err(self.error(
                            loc,
                            "both \"L\" and \"filename\" given for a diffuse area light",
                        ))
                    }
                    Some((file, floc)) => {
                        let path = self.path_in(floc.file, file);
                        let fallback = "the light emits white instead";
                        let clamp = Wrap::Clamp;
                        self.image(&path, &floc, fallback, false, |c| c, [1.0, 1.0], clamp)?
                    }
                };
                let power = match params.get("power") {
                    None => None,
                    Some(_) => Some(self.float(&params, "power", -1.0)?).filter(|&w| w > 0.0),
                };
                if let Some(q) = params.get("alpha") {
                    let l = q.loc.clone();
                    self.warn(&l, "`alpha` of an area light is not supported: ignored");
                }
                self.state.area_light = Some(AreaLight {
                    radiance,
                    spectrum,
                    two_sided,
                    image,
                    power,
                });
            }
            "Shape" => {
                name_of_type = need_str("a type")?;
                self.shape(&name_of_type, &params, loc)?;
            }
            "ObjectBegin" => {
                let name = need_str("a name")?;
                if self.recording.is_some() {
                    return Err(self.error(loc, "ObjectBegin inside another object"));
                }
                self.stack.push((self.state.clone(), loc.clone()));
                self.recording = Some((name, Vec::new()));
            }
            "ObjectEnd" => {
                let Some((name, shapes)) = self.recording.take() else {
                    return Err(self.error(loc, "ObjectEnd without ObjectBegin"));
                };
                self.objects.insert(name, shapes);
                if let Some((state, _)) = self.stack.pop() {
                    self.state = state;
                }
            }
            "ObjectInstance" => {
                let name = need_str("a name")?;
                let Some(shapes) = self.objects.get(&name).cloned() else {
                    let e = self.error(loc, format!("no object named `{name}` is defined above"));
                    return Err(
                        match did_you_mean(&name, self.objects.keys().map(String::as_str)) {
                            Some(s) => e.with_help(format!("did you mean `{s}`?")),
                            None => e,
                        },
                    );
                };
                let ctm_end = self.ctm_end();
                for r in shapes {
                    let singular = || self.error(loc, "a singular instance transformation");
                    let t = Transform::from_matrix(ctm.mul(&r.to_world)).ok_or_else(singular)?;
                    let t_end = Transform::from_matrix(ctm_end.mul(&r.to_world_end))
                        .ok_or_else(singular)?;
                    self.builder
                        .add_object(format!("{name}/{}", r.name), r.shape, t, r.material);
                    if let Some(alpha) = r.alpha {
                        self.builder.set_last_alpha(alpha);
                    }
                    if t_end != t {
                        self.builder.set_last_motion(t_end);
                    }
                }
            }
            "Include" | "Import" => {
                let name = need_str("a file name")?;
                if self.include_depth >= MAX_INCLUDE_DEPTH {
                    return Err(self.error(
                        loc,
                        format!("includes nested deeper than {MAX_INCLUDE_DEPTH} files"),
                    ));
                }
                if self.sources.len() >= MAX_FILES {
                    return Err(self.error(loc, format!("more than {MAX_FILES} files included")));
                }
                let path = self.path_in(loc.file, &name);
                let canonical = std::fs::canonicalize(&path).ok();
                if canonical.is_some() && self.include_stack.contains(&canonical) {
                    return Err(self.error(loc, format!("{} includes itself", path.display())));
                }
                let bytes = std::fs::read(&path)
                    .map_err(|e| self.error(loc, format!("cannot read {}: {e}", path.display())))?;
                let (text, _) = crate::text::lenient(&path, bytes);
                self.include_depth += 1;
                self.include_stack.push(canonical);
                let r = self.file(path, text);
                self.include_stack.pop();
                self.include_depth -= 1;
                r?;
            }
            other => {
                const ALL: &[&str] = &[
                    "Identity",
                    "Translate",
                    "Scale",
                    "Rotate",
                    "LookAt",
                    "Transform",
                    "ConcatTransform",
                    "CoordinateSystem",
                    "CoordSysTransform",
                    "TransformTimes",
                    "ActiveTransform",
                    "ReverseOrientation",
                    "AttributeBegin",
                    "AttributeEnd",
                    "TransformBegin",
                    "TransformEnd",
                    "WorldBegin",
                    "Option",
                    "Attribute",
                    "ColorSpace",
                    "Camera",
                    "Film",
                    "Sampler",
                    "PixelFilter",
                    "Integrator",
                    "Accelerator",
                    "Material",
                    "MakeNamedMaterial",
                    "NamedMaterial",
                    "Texture",
                    "LightSource",
                    "AreaLightSource",
                    "Shape",
                    "ObjectBegin",
                    "ObjectEnd",
                    "ObjectInstance",
                    "Include",
                    "Import",
                    "MakeNamedMedium",
                    "MediumInterface",
                ];
                return Err(self.unknown(loc, "directive", other, ALL));
            }
        }
        self.report_unused(d, &name_of_type, &params);
        Ok(())
    }

    fn report_unused(&mut self, d: &str, ty: &str, params: &Params) {
        for q in &params.list {
            if !q.used.get() && !q.inherited {
                let what = if ty.is_empty() {
                    d.to_string()
                } else {
                    format!("{d} \"{ty}\"")
                };
                let l = q.loc.clone();
                self.warn(
                    &l,
                    format!(
                        "\"{} {}\" of {what} is not supported: ignored",
                        q.ty, q.name
                    ),
                );
            }
        }
    }
}

impl Parser {
    fn film(&mut self, ty: &str, p: &Params, loc: &Loc) -> Result<()> {
        if !matches!(ty, "rgb" | "gbuffer" | "spectral") {
            self.warn(loc, format!("the film `{ty}` is read as \"rgb\""));
        }
        let size = |s: &Self, key: &str, default: i64| -> Result<u32> {
            let v = s.integer(p, key, default)?;
            if !(1..=1 << 16).contains(&v) {
                return Err(s.error(
                    &p.get(key).unwrap().loc,
                    format!("expected `{key}` from 1 to 65536, found {v}"),
                ));
            }
            Ok(v as u32)
        };
        let (w, h) = (
            size(self, "xresolution", 1280)?,
            size(self, "yresolution", 720)?,
        );
        self.defaults.width = w;
        self.defaults.height = h;
        self.film_size = Some((w, h));
        // The output file: Plenum's comes from -o.
        p.get("filename");
        Ok(())
    }

    fn sampler(&mut self, ty: &str, p: &Params, loc: &Loc) -> Result<()> {
        let mut spp = self.integer(p, "pixelsamples", 16)?;
        self.defaults.sampler = match ty {
            "independent" => SamplerKind::Random,
            "stratified" => {
                let (x, y) = (
                    self.integer(p, "xsamples", 4)?,
                    self.integer(p, "ysamples", 4)?,
                );
                self.boolean_param(p, "jitter", true)?;
                spp = x * y;
                SamplerKind::Jittered
            }
            "zsobol" | "sobol" | "paddedsobol" | "halton" | "pmj02bn" => {
                p.get("randomization");
                SamplerKind::Sobol
            }
            other => {
                self.warn(
                    loc,
                    format!("the sampler `{other}` is not supported: using sobol"),
                );
                SamplerKind::Sobol
            }
        };
        p.get("seed");
        if !(1..=65536).contains(&spp) {
            return Err(self.error(
                loc,
                format!("expected from 1 to 65536 samples per pixel, found {spp}"),
            ));
        }
        self.defaults.spp = spp as u32;
        Ok(())
    }

    fn pixel_filter(&mut self, ty: &str, p: &Params, loc: &Loc) -> Result<()> {
        let (kind, default) = match ty {
            "box" => (FilterKind::Box, 0.5),
            "gaussian" => (FilterKind::Gaussian, 1.5),
            "triangle" => (FilterKind::Tent, 2.0),
            "mitchell" => (FilterKind::Mitchell, 2.0),
            "sinc" => (FilterKind::Lanczos, 4.0),
            other => {
                self.warn(
                    loc,
                    format!("the filter `{other}` is not supported: using a Gaussian"),
                );
                (FilterKind::Gaussian, 1.5)
            }
        };
        let (x, y) = (
            self.positive(p, "xradius", default)?,
            self.positive(p, "yradius", default)?,
        );
        if x != y {
            let l = p
                .get("yradius")
                .or(p.get("xradius"))
                .map_or(loc.clone(), |q| q.loc.clone());
            self.warn(
                &l,
                "Plenum's filters are round: using xradius for both axes",
            );
        }
        match ty {
            "gaussian" if self.float(p, "sigma", 0.5)? != 0.5 => {
                let l = p.get("sigma").unwrap().loc.clone();
                self.warn(&l, "Plenum's Gaussian has σ = 0.5 pixel: sigma is ignored");
            }
            "mitchell"
                if self.float(p, "B", 1.0 / 3.0)? != 1.0 / 3.0
                    || self.float(p, "C", 1.0 / 3.0)? != 1.0 / 3.0 =>
            {
                self.warn(
                    loc,
                    "Plenum's Mitchell filter has B = C = 1/3: B and C are ignored",
                );
            }
            "sinc" => {
                p.get("tau");
            }
            _ => {}
        }
        self.defaults.filter = kind;
        self.defaults.filter_radius = (x != kind.default_radius()).then_some(x);
        Ok(())
    }

    fn integrator(&mut self, ty: &str, p: &Params, loc: &Loc) -> Result<()> {
        // pbrt's maxdepth D counts bounces from the camera's first hit: Plenum's D − 1.
        let depth = self.integer(p, "maxdepth", 5)?;
        if depth < 1 {
            return Err(self.error(
                loc,
                format!("expected a maxdepth of 1 or more, found {depth}"),
            ));
        }
        self.defaults.max_depth = ((depth - 1) as u32).min(100);
        let kind = match ty {
            "path" => IntegratorKind::Path,
            "bdpt" => IntegratorKind::Bdpt,
            "sppm" => {
                if let Some(n) = p.get("photonsperiteration") {
                    if n.nums.len() == 1 && n.nums[0] >= 1.0 {
                        self.defaults.photon.sppm_photons = n.nums[0] as u64;
                    }
                }
                if let Some(n) = p.get("iterations") {
                    if n.nums.len() == 1 && n.nums[0] >= 1.0 {
                        self.defaults.spp = (n.nums[0] as u32).min(65536);
                    }
                }
                p.get("radius");
                IntegratorKind::Sppm
            }
            "lightpath" => IntegratorKind::Light,
            other => {
                self.warn(
                    loc,
                    format!("the integrator `{other}` is not in Plenum: using the path tracer"),
                );
                IntegratorKind::Path
            }
        };
        for key in ["regularize", "lightsampler"] {
            if let Some(q) = p.get(key) {
                let l = q.loc.clone();
                self.warn(&l, format!("`{key}` is not supported: ignored"));
            }
        }
        self.defaults.integrator = Some(kind);
        Ok(())
    }

    // ---- Materials and textures ----

    fn material(
        &mut self,
        ty: &str,
        name: Option<&str>,
        p: &Params,
        loc: &Loc,
    ) -> Result<MaterialId> {
        let albedo = SpectrumKind::Albedo;
        let m = match ty {
            "diffuse" => Material::Diffuse(DiffuseMaterial {
                reflectance: self.spectral(p, "reflectance", 0.5, albedo)?,
            }),
            "conductor" | "coatedconductor" => {
                if ty == "coatedconductor" {
                    self.warn(
                        loc,
                        "coatedconductor is read as its conductor (the coat is left out)",
                    );
                    for key in [
                        "interface.roughness",
                        "interface.uroughness",
                        "interface.vroughness",
                        "interface.eta",
                        "thickness",
                        "albedo",
                        "g",
                        "maxdepth",
                        "nsamples",
                    ] {
                        p.get(key);
                    }
                }
                let prefix = if ty == "coatedconductor" {
                    "conductor."
                } else {
                    ""
                };
                let key = |k: &str| format!("{prefix}{k}");
                let spec = if p.get(&key("reflectance")).is_some() {
                    ConductorSpec::Reflectance(self.spectral(
                        p,
                        &key("reflectance"),
                        1.0,
                        albedo,
                    )?)
                } else {
                    let part = |s: &Self, k: &str, metal: &str| -> Result<SpectralTexture> {
                        match p.get(&key(k)) {
                            Some(_) => s.spectral(p, &key(k), 1.0, SpectrumKind::Unbounded),
                            None => Ok(SpectralTexture::Constant(SpectrumValue::new(
                                plenum_spectrum::named(metal).expect("copper's tables"),
                                SpectrumKind::Unbounded,
                            ))),
                        }
                    };
                    ConductorSpec::EtaK {
                        eta: part(self, "eta", "metal-Cu-eta")?,
                        k: part(self, "k", "metal-Cu-k")?,
                    }
                };
                let roughness = if ty == "coatedconductor" {
                    let remap = self.boolean_param(p, "remaproughness", true)?;
                    let r = self.float_texture(p, "conductor.roughness", 0.0)?;
                    let u = if p.get("conductor.uroughness").is_some() {
                        self.float_texture(p, "conductor.uroughness", 0.0)?
                    } else {
                        r.clone()
                    };
                    let v = if p.get("conductor.vroughness").is_some() {
                        self.float_texture(p, "conductor.vroughness", 0.0)?
                    } else {
                        r
                    };
                    Roughness { u, v, remap }
                } else {
                    self.roughness(p)?
                };
                Material::Conductor(ConductorMaterial { spec, roughness })
            }
            "dielectric" => Material::Dielectric(DielectricMaterial {
                eta: self.eta(p)?,
                roughness: self.roughness(p)?,
            }),
            "thindielectric" => {
                Material::ThinDielectric(ThinDielectricMaterial { eta: self.eta(p)? })
            }
            "diffusetransmission" => Material::DiffuseTransmission(DiffuseTransmissionMaterial {
                reflectance: self.spectral(p, "reflectance", 0.25, albedo)?,
                transmittance: self.spectral(p, "transmittance", 0.25, albedo)?,
                scale: self.float(p, "scale", 1.0)?.max(0.0),
            }),
            "coateddiffuse" => {
                let g = self.float(p, "g", 0.0)?;
                if !(-1.0..=1.0).contains(&g) {
                    return Err(self.error(
                        &p.get("g").unwrap().loc,
                        format!("expected g between -1 and 1, found {g}"),
                    ));
                }
                Material::CoatedDiffuse(CoatedDiffuseMaterial {
                    reflectance: self.spectral(p, "reflectance", 0.5, albedo)?,
                    roughness: self.roughness(p)?,
                    thickness: self.positive(p, "thickness", 0.01)?,
                    eta: self.eta(p)?,
                    albedo: self.spectral(p, "albedo", 0.0, albedo)?,
                    g,
                    max_depth: self.integer(p, "maxdepth", 10)?.clamp(1, 100) as u32,
                    samples: self.integer(p, "nsamples", 1)?.clamp(1, 100) as u32,
                })
            }
            "mix" => {
                let Some(q) = p.get("materials") else {
                    return Err(self.error(loc, "a mix needs \"string materials\" [ \"a\" \"b\" ]"));
                };
                if q.strs.len() != 2 {
                    return Err(self.error(&q.loc, "a mix takes two material names"));
                }
                let mut ids = [0; 2];
                for (i, n) in q.strs.iter().enumerate() {
                    ids[i] = *self.named_materials.get(n).ok_or_else(|| {
                        self.error(&q.loc, format!("no material named `{n}` is defined above"))
                    })?;
                }
                let amount = self.float_texture(p, "amount", 0.5)?;
                Material::Mix {
                    materials: ids,
                    amount,
                }
            }
            "interface" | "" | "none" => {
                // An invisible boundary (for media): glass of index 1 lets light through
                // unbent and unreflected.
                Material::Dielectric(DielectricMaterial {
                    eta: SpectrumValue::new(Spectrum::Constant(1.0), SpectrumKind::Unbounded),
                    roughness: Roughness::SMOOTH,
                })
            }
            other => {
                self.warn(
                    loc,
                    format!("the material `{other}` is not supported: using diffuse 0.5"),
                );
                p.list.iter().for_each(|q| q.used.set(true));
                Material::Diffuse(DiffuseMaterial {
                    reflectance: SpectralTexture::constant(Color::gray(0.5), albedo),
                })
            }
        };
        let bump = self.bump(p)?;
        p.get("type");
        self.count += 1;
        let name = name.map_or_else(|| format!("{ty} {}", self.count), str::to_string);
        let id = self.builder.add_material(name, m);
        if let Some(bump) = bump {
            self.builder.set_bump(id, bump);
        }
        Ok(id)
    }

    /// A material's `normalmap` (an image file of tangent-space normals, read linear) or
    /// `displacement` (a float texture: a bump map); a normal map wins where both are
    /// given, as in pbrt-v4.
    fn bump(&mut self, p: &Params) -> Result<Option<Bump>> {
        let displacement = match p.get("displacement") {
            Some(_) => Some(self.float_texture(p, "displacement", 0.0)?),
            None => None,
        };
        if let Some((file, floc)) = self.string(p, "normalmap")? {
            let path = self.path_in(floc.file, file);
            return Ok(match plenum_image::read_data_texture(&path) {
                Ok(t) => {
                    let texels = t
                        .rgb
                        .iter()
                        .map(|c| Color::new(c[0] as f64, c[1] as f64, c[2] as f64));
                    let image = ImageTexture::new(t.width, t.height, texels.collect(), [1.0, 1.0])
                        .ok_or_else(|| self.error(&floc, "the image is empty"))?;
                    if displacement.is_some() {
                        self.warn(
                            &floc,
                            "both a normal map and a displacement: the normal map is used",
                        );
                    }
                    Some(Bump::NormalMap {
                        image: Arc::new(image),
                        scale: 1.0,
                        bitangent: Bitangent::NormalCrossU,
                    })
                }
                Err(e) => {
                    self.warn(&floc, format!("{e}: the surface is smooth"));
                    None
                }
            });
        }
        Ok(displacement.and_then(|height| match height {
            FloatTexture::Constant(_) => None,
            height => Some(Bump::HeightMap { height, scale: 1.0 }),
        }))
    }

    fn texture(&mut self, class: &str, ty: &str, p: &Params, loc: &Loc) -> Result<Texture> {
        if class != "spectrum" && class != "float" && class != "color" {
            return Err(self.error(
                loc,
                format!("expected a \"spectrum\" or \"float\" texture, found \"{class}\""),
            ));
        }
        let constant = |s: &Self, key: &str, default: f64| -> Result<Option<Color>> {
            match p.get(key) {
                None => Ok(Some(Color::gray(default))),
                Some(q) if q.ty == "texture" => Ok(match s.texture_ref(q)? {
                    Texture::Constant(c) => Some(c),
                    _ => None,
                }),
                Some(q) if matches!(q.ty.as_str(), "rgb" | "color") && q.nums.len() == 3 => {
                    Ok(Some(Color::new(q.nums[0], q.nums[1], q.nums[2])))
                }
                Some(q) if q.ty == "float" && q.nums.len() == 1 => Ok(Some(Color::gray(q.nums[0]))),
                Some(q) if q.ty == "spectrum" => {
                    let [r, g, b] = s.spectrum(q)?.to_rgb_illuminant();
                    Ok(Some(Color::new(r, g, b)))
                }
                Some(q) => {
                    Err(s.error(&q.loc, format!("expected `{key}` to be a value or texture")))
                }
            }
        };
        // The texture's space: the transformation current where it is defined.
        let to_world = Transform::from_matrix(self.ctm())
            .ok_or_else(|| self.error(loc, "the texture's transformation is singular"))?;
        let to_texture = to_world.inverted();
        let mapping = |s: &mut Self| -> Result<Mapping> {
            let uv = |s: &mut Self| -> Result<Mapping> {
                Ok(Mapping::Uv {
                    scale: [s.float(p, "uscale", 1.0)?, s.float(p, "vscale", 1.0)?],
                    delta: [s.float(p, "udelta", 0.0)?, s.float(p, "vdelta", 0.0)?],
                })
            };
            Ok(match s.string(p, "mapping")? {
                None | Some(("uv", _)) => uv(s)?,
                Some(("spherical", _)) => Mapping::Spherical(to_texture.clone()),
                Some(("cylindrical", _)) => Mapping::Cylindrical(to_texture.clone()),
                Some(("planar", _)) => Mapping::Planar {
                    to_texture: to_texture.clone(),
                    axes: [s.point(p, "v1", Vec3::X)?, s.point(p, "v2", Vec3::Y)?],
                    delta: [s.float(p, "udelta", 0.0)?, s.float(p, "vdelta", 0.0)?],
                },
                Some((m, l)) => {
                    s.warn(
                        &l,
                        format!("unknown mapping `{m}` (expected uv, spherical, cylindrical or planar): using uv"),
                    );
                    uv(s)?
                }
            })
        };
        // A texture under a mapping: the identity (u, v) mapping is no mapping, and a scale
        // of (u, v) alone is kept by the checker and bilerp textures themselves.
        let mapped = |m: Mapping, t: Texture| match (m, t) {
            (
                Mapping::Uv {
                    scale: [1.0, 1.0],
                    delta: [0.0, 0.0],
                },
                t,
            ) => t,
            (
                Mapping::Uv {
                    scale: [su, sv],
                    delta: [0.0, 0.0],
                },
                Texture::Checker2d {
                    even,
                    odd,
                    scale: 1.0,
                },
            ) if su == sv && su > 0.0 => Texture::Checker2d {
                even,
                odd,
                scale: su,
            },
            (
                Mapping::Uv {
                    scale,
                    delta: [0.0, 0.0],
                },
                Texture::Bilerp(b),
            ) if b.1 == [1.0, 1.0] => Texture::Bilerp(Arc::new((b.0, scale))),
            (m, t) => Texture::Mapped(Arc::new((m, t))),
        };
        // A texture operand: a texture by name, or a value (a constant texture).
        let operand = |s: &Self, key: &str, default: f64| -> Result<Texture> {
            match p.get(key) {
                Some(q) if q.ty == "texture" => s.texture_ref(q),
                _ => Ok(Texture::Constant(
                    constant(s, key, default)?.unwrap_or(Color::gray(default)),
                )),
            }
        };
        // `a` where the pattern is 0, `b` where it is 1.
        let between = |a: Texture, b: Texture, pattern: Texture| {
            let t = Texture::Mix(Arc::new([a, b, pattern]));
            t.constant_value().map_or(t, Texture::Constant)
        };
        let octaves = |s: &mut Self| -> Result<u32> {
            let n = s.integer(p, "octaves", 8)?;
            if n < 0 {
                return Err(s.error(
                    &p.get("octaves").unwrap().loc,
                    format!("expected `octaves` ≥ 0, found {n}"),
                ));
            }
            if n > MAX_OCTAVES as i64 {
                s.warn(
                    &p.get("octaves").unwrap().loc,
                    format!("{n} octaves: the finest beyond {MAX_OCTAVES} are below f64's precision and are left out"),
                );
            }
            Ok((n as u32).min(MAX_OCTAVES))
        };
        let solid = |t: Noise| {
            Texture::Mapped(Arc::new((
                Mapping::Solid(to_texture.clone()),
                Texture::Noise(Arc::new(t)),
            )))
        };
        Ok(match ty {
            "constant" => Texture::Constant(constant(self, "value", 1.0)?.unwrap_or(Color::WHITE)),
            "imagemap" => {
                let Some((file, floc)) = self.string(p, "filename")? else {
                    return Err(self.error(loc, "an imagemap needs a \"string filename\""));
                };
                let path = self.path_in(floc.file, file);
                // A positive scale of (u, v) is the image's own repeat count.
                let (repeats, map) = match mapping(self)? {
                    Mapping::Uv {
                        scale,
                        delta: [0.0, 0.0],
                    } if scale[0] > 0.0 && scale[1] > 0.0 => (scale, None),
                    m => ([1.0, 1.0], Some(m)),
                };
                let scale = self.float(p, "scale", 1.0)?;
                let invert = self.boolean_param(p, "invert", false)?;
                p.get("filter");
                p.get("maxanisotropy");
                let mut linear = false;
                if let Some((e, l)) = self.string(p, "encoding")? {
                    match e {
                        "sRGB" => {}
                        "linear" => linear = true,
                        _ => self.warn(
                            &l,
                            format!(
                                "encoding `{e}` is not supported: 8-bit images are read as sRGB"
                            ),
                        ),
                    }
                }
                let wrap = match self.string(p, "wrap")? {
                    None | Some(("repeat", _)) => Wrap::Repeat,
                    Some(("black", _)) => Wrap::Black,
                    Some(("clamp", _)) => Wrap::Clamp,
                    Some(("octahedralsphere", l)) => {
                        self.warn(&l, "wrap `octahedralsphere` is not supported: repeating");
                        Wrap::Repeat
                    }
                    Some((w, l)) => {
                        return Err(self.error(
                            &l,
                            format!(
                            "unknown wrap `{w}`: expected repeat, black, clamp or octahedralsphere"
                        ),
                        ))
                    }
                };
                let texel = |c: Color| {
                    let c = c * scale;
                    if invert {
                        Color::new(1.0 - c.r, 1.0 - c.g, 1.0 - c.b)
                    } else {
                        c
                    }
                };
                let fallback = "a neutral grey (0.5) instead";
                match self.image(&path, &floc, fallback, linear, texel, repeats, wrap)? {
                    Some(image) => match map {
                        None => image,
                        Some(m) => mapped(m, image),
                    },
                    None => Texture::Constant(Color::gray(0.5)),
                }
            }
            "checkerboard" => {
                let (a, b) = (operand(self, "tex1", 1.0)?, operand(self, "tex2", 0.0)?);
                // Two colours make the checker itself; textures are mixed by its pattern,
                // 0 on tex1's squares and 1 on tex2's.
                let (even, odd, textures) = match (a.constant_value(), b.constant_value()) {
                    (Some(a), Some(b)) => (a, b, None),
                    _ => (Color::BLACK, Color::WHITE, Some((a, b))),
                };
                let pick = |pattern: Texture| match textures {
                    None => pattern,
                    Some((a, b)) => between(a, b, pattern),
                };
                match self.integer(p, "dimension", 2)? {
                    2 => {
                        let squares = Texture::Checker2d {
                            even,
                            odd,
                            scale: 1.0,
                        };
                        pick(mapped(mapping(self)?, squares))
                    }
                    3 => {
                        let cubes = Texture::Checker3d {
                            even,
                            odd,
                            scale: 1.0,
                        };
                        let space = Mapping::Solid(to_texture.clone());
                        pick(Texture::Mapped(Arc::new((space, cubes))))
                    }
                    d => {
                        return Err(self.error(loc, format!("expected dimension 2 or 3, found {d}")))
                    }
                }
            }
            "dots" => {
                let inside = operand(self, "inside", 1.0)?;
                let outside = operand(self, "outside", 0.0)?;
                // pbrt-v4 hands `inside` and `outside` to its dots texture in the other
                // order than that texture takes them: its dots show `outside`, and the
                // plane between them `inside`. Plenum renders what pbrt-v4 renders.
                between(inside, outside, mapped(mapping(self)?, Texture::Dots))
            }
            "fbm" | "wrinkled" => {
                let omega = self.float(p, "roughness", 0.5)?;
                let octaves = octaves(self)?;
                solid(match ty {
                    "fbm" => Noise::Fbm { omega, octaves },
                    _ => Noise::Wrinkled { omega, octaves },
                })
            }
            "windy" => solid(Noise::Windy),
            "marble" => {
                let octaves = octaves(self)?;
                solid(Noise::Marble {
                    omega: self.float(p, "roughness", 0.5)?,
                    octaves,
                    scale: self.float(p, "scale", 1.0)?,
                    variation: self.float(p, "variation", 0.2)?,
                })
            }
            "directionmix" => {
                let d = to_world.vector(self.point(p, "dir", Vec3::Y)?);
                if !(d.length() > 0.0) || !finite(d) {
                    return Err(self.error(
                        &p.get("dir").map_or(loc.clone(), |q| q.loc.clone()),
                        "expected a non-zero `dir`",
                    ));
                }
                let (a, b) = (operand(self, "tex1", 0.0)?, operand(self, "tex2", 1.0)?);
                Texture::DirectionMix(Arc::new((d.normalized(), [a, b])))
            }
            "scale" | "mix" => {
                let (a, b, amount) = match ty {
                    "scale" => (
                        operand(self, "tex", 1.0)?,
                        operand(self, "scale", 1.0)?,
                        None,
                    ),
                    _ => (
                        operand(self, "tex1", 0.0)?,
                        operand(self, "tex2", 1.0)?,
                        Some(operand(self, "amount", 0.5)?),
                    ),
                };
                let combined = match amount {
                    None => Texture::Scale(Arc::new([a, b])),
                    Some(amount) => Texture::Mix(Arc::new([a, b, amount])),
                };
                // Constants are combined here, once.
                combined
                    .constant_value()
                    .map_or(combined, Texture::Constant)
            }
            "bilerp" => {
                let map = mapping(self)?;
                let corner = |s: &Self, key: &str, default: f64| -> Result<Color> {
                    constant(s, key, default)?.ok_or_else(|| {
                        s.error(
                            loc,
                            format!("expected `{key}` to be a value, not a texture"),
                        )
                    })
                };
                let corners = [
                    corner(self, "v00", 0.0)?,
                    corner(self, "v10", 0.0)?,
                    corner(self, "v01", 1.0)?,
                    corner(self, "v11", 1.0)?,
                ];
                mapped(map, Texture::Bilerp(Arc::new((corners, [1.0, 1.0]))))
            }
            other => {
                self.warn(
                    loc,
                    format!("the `{other}` texture is not supported: a neutral grey (0.5)"),
                );
                p.list.iter().for_each(|q| q.used.set(true));
                Texture::Constant(Color::gray(0.5))
            }
        })
    }
}

impl Parser {
    // ---- Lights ----

    fn light(&mut self, ty: &str, p: &Params, loc: &Loc) -> Result<()> {
        let t = Transform::from_matrix(self.ctm())
            .ok_or_else(|| self.error(loc, "the light's transformation is singular"))?;
        if self.ctm_end() != self.ctm() {
            self.warn(
                loc,
                "a moving light is not supported (nor in pbrt-v4): its start-time transformation is used",
            );
        }
        self.count += 1;
        let name = format!("{ty} light {}", self.count);
        let power = |s: &Self, k_e: f64| -> Result<f64> {
            let phi = s.float(p, "power", -1.0)?;
            Ok(if phi > 0.0 { phi / k_e } else { 1.0 })
        };
        let (light, spectrum) = match ty {
            "point" => {
                let (c, s) = self.emission(p, "I")?;
                let k = power(self, 4.0 * std::f64::consts::PI)?;
                let from = self.point(p, "from", Vec3::ZERO)?;
                (
                    Light::Point {
                        position: t.point(from),
                        intensity: c * k,
                        attenuation: Attenuation::default(),
                    },
                    s.map(|(s, x)| (s, x * k)),
                )
            }
            "spot" => {
                let (c, s) = self.emission(p, "I")?;
                let from = self.point(p, "from", Vec3::ZERO)?;
                let to = self.point(p, "to", Vec3::Z)?;
                let cone = self.float(p, "coneangle", 30.0)?.clamp(0.0, 90.0);
                let delta = self.float(p, "conedelta", 5.0)?.clamp(0.0, cone);
                let (cos_end, cos_start) =
                    (cone.to_radians().cos(), (cone - delta).to_radians().cos());
                let k = power(
                    self,
                    2.0 * std::f64::consts::PI * (1.0 - 0.5 * (cos_start + cos_end)),
                )?;
                let direction = t.vector(to - from).normalized();
                if !finite(direction) {
                    return Err(
                        self.error(loc, "the spot light's `from` and `to` are the same point")
                    );
                }
                (
                    Light::Spot {
                        position: t.point(from),
                        direction,
                        cos_inner: cos_start,
                        cos_outer: cos_end,
                        intensity: c * k,
                        attenuation: Attenuation::default(),
                    },
                    s.map(|(s, x)| (s, x * k)),
                )
            }
            "distant" => {
                let (c, s) = self.emission(p, "L")?;
                let from = self.point(p, "from", Vec3::ZERO)?;
                let to = self.point(p, "to", Vec3::Z)?;
                let e = self.float(p, "illuminance", -1.0)?;
                let k = if e > 0.0 { e } else { 1.0 };
                let direction = t.vector(to - from).normalized();
                if !finite(direction) {
                    return Err(self.error(
                        loc,
                        "the distant light's `from` and `to` are the same point",
                    ));
                }
                (
                    Light::Directional {
                        direction,
                        intensity: c * k,
                    },
                    s.map(|(s, x)| (s, x * k)),
                )
            }
            "infinite" => {
                if let Some(q) = p.get("portal") {
                    let l = q.loc.clone();
                    self.warn(&l, "portals are not supported: ignored");
                }
                match self.string(p, "filename")? {
                    Some((file, floc)) => {
                        use plenum_core::environment::{EnvironmentLayout, EnvironmentMap};
                        if let Some(q) = p.get("illuminance") {
                            let l = q.loc.clone();
                            self.warn(&l, "`illuminance` with an image is not supported: the image's own values are used");
                        }
                        let path = self.path_in(floc.file, file);
                        let image = plenum_image::read_float_image(&path)
                            .map_err(|e| self.error(&floc, e.to_string()))?;
                        let scale = self.float(p, "scale", 1.0)?.max(0.0);
                        let axis = |v: Vec3| t.vector(v).normalized();
                        let frame = plenum_core::sampling::Frame {
                            x: axis(Vec3::X),
                            y: axis(Vec3::Y),
                            z: axis(Vec3::Z),
                        };
                        let map = EnvironmentMap::new(image.width as usize, image.height as usize, image.pixels, EnvironmentLayout::EqualArea, frame, scale)
                            .map_err(|e| self.error(&floc, format!("{e} (pbrt-v4 reads environment images in its equal-area square layout)")))?;
                        let [r, g, b] = map.average();
                        let light = Light::Environment {
                            map: plenum_core::light::EnvironmentLight {
                                map: Arc::new(map),
                                file: path.display().to_string(),
                                scale,
                            },
                            radiance: Color::new(r, g, b),
                        };
                        (light, None)
                    }
                    None => {
                        let (c, s) = self.emission(p, "L")?;
                        let e = self.float(p, "illuminance", -1.0)?;
                        // A uniform sky of radiance 1 gives an upward surface π lux.
                        let k = if e > 0.0 {
                            e / std::f64::consts::PI
                        } else {
                            1.0
                        };
                        (
                            Light::Infinite { radiance: c * k },
                            s.map(|(s, x)| (s, x * k)),
                        )
                    }
                }
            }
            "goniometric" => {
                let (c, s) = self.emission(p, "I")?;
                let position = t.point(Vec3::ZERO);
                let Some((file, floc)) = self.string(p, "filename")? else {
                    self.warn(
                        loc,
                        "a goniometric light without a \"filename\": a point light",
                    );
                    let k = power(self, 4.0 * std::f64::consts::PI)?;
                    self.builder.add_light(
                        name,
                        Light::Point {
                            position,
                            intensity: c * k,
                            attenuation: Attenuation::default(),
                        },
                    );
                    if let Some((s, x)) = s {
                        self.builder.set_last_light_spectrum(s, x * k);
                    }
                    return Ok(());
                };
                let path = self.path_in(floc.file, file);
                let texels = plenum_image::read_texture(&path)
                    .map_err(|e| self.error(&floc, e.to_string()))?;
                if texels.width != texels.height {
                    return Err(self.error(
                        &floc,
                        format!(
                            "a goniometric diagram must be square (equal-area), got {} × {}",
                            texels.width, texels.height
                        ),
                    ));
                }
                // pbrt-v4 keeps the mean of the channels, in the frame with y and z swapped.
                let grey = texels.rgb.iter().map(|t| (t[0] + t[1] + t[2]) as f64 / 3.0);
                let frame = light_frame(&t, [Vec3::X, Vec3::Z, Vec3::Y]);
                let profile = Profile::goniometric(texels.width, grey.collect(), frame)
                    .map_err(|e| self.error(&floc, e))?;
                let k = power(self, profile.screen_integral())?;
                (
                    Light::Profiled {
                        position,
                        intensity: c * k,
                        profile: Arc::new(profile),
                    },
                    s.map(|(s, x)| (s, x * k)),
                )
            }
            "projection" => {
                let scale = self.float(p, "scale", 1.0)?;
                let fov = self.float(p, "fov", 90.0)?;
                let Some((file, floc)) = self.string(p, "filename")? else {
                    return Err(self.error(loc, "a projection light needs a \"string filename\""));
                };
                let path = self.path_in(floc.file, file);
                let texels = plenum_image::read_texture(&path)
                    .map_err(|e| self.error(&floc, e.to_string()))?;
                let rgb = texels.rgb.iter();
                let rgb = rgb.map(|t| Color::new(t[0] as f64, t[1] as f64, t[2] as f64));
                // pbrt-v4 turns y over: the image's top row toward the light's +y.
                let frame = light_frame(&t, [Vec3::X, -Vec3::Y, Vec3::Z]);
                let profile =
                    Profile::projection(texels.width, texels.height, rgb.collect(), fov, frame)
                        .map_err(|e| self.error(loc, e))?;
                let k = power(self, profile.screen_integral())?;
                (
                    Light::Profiled {
                        position: t.point(Vec3::ZERO),
                        intensity: Color::gray(scale * k),
                        profile: Arc::new(profile),
                    },
                    None,
                )
            }
            other => {
                return Err(self.unknown(
                    loc,
                    "light",
                    other,
                    &[
                        "point",
                        "spot",
                        "distant",
                        "infinite",
                        "goniometric",
                        "projection",
                    ],
                ));
            }
        };
        self.builder.add_light(name, light);
        if let Some((s, scale)) = spectrum {
            self.builder.set_last_light_spectrum(s, scale);
        }
        Ok(())
    }

    // ---- Shapes ----

    fn material_now(&mut self) -> MaterialId {
        if let Some(m) = self.state.material {
            return m;
        }
        if let Some(m) = self.default_material {
            return m;
        }
        // pbrt's default material: diffuse 0.5.
        let m = self.builder.add_material(
            "default (diffuse 0.5)",
            Material::Diffuse(DiffuseMaterial {
                reflectance: SpectralTexture::constant(Color::gray(0.5), SpectrumKind::Albedo),
            }),
        );
        self.default_material = Some(m);
        m
    }

    /// A mesh from positions and indices (`per` indices to a face: 3, or 4 for bilinear
    /// patches, split in two triangles).
    fn mesh(&mut self, p: &Params, loc: &Loc, per: usize, reverse: bool) -> Result<TriangleMesh> {
        let Some(pq) = p.get("P") else {
            return Err(self.error(loc, "a mesh needs \"point3 P\""));
        };
        let positions = self.vectors(pq);
        let indices: Vec<u32> = match p.get("indices") {
            Some(q) => {
                if q.nums
                    .iter()
                    .any(|x| *x < 0.0 || x.fract() != 0.0 || *x > u32::MAX as f64)
                {
                    return Err(self.error(&q.loc, "expected indices: whole numbers ≥ 0"));
                }
                q.nums.iter().map(|x| *x as u32).collect()
            }
            None if positions.len() == per => (0..per as u32).collect(),
            None => return Err(self.error(loc, "a mesh needs \"integer indices\"")),
        };
        if !indices.len().is_multiple_of(per) {
            return Err(self.error(
                &p.get("indices").unwrap().loc,
                format!("{} indices: expected a multiple of {per}", indices.len()),
            ));
        }
        let mut triangles: Vec<[u32; 3]> = Vec::new();
        for f in indices.chunks_exact(per) {
            if per == 4 {
                // pbrt's bilinear patch: p00 p10 p01 p11.
                triangles.push([f[0], f[1], f[3]]);
                triangles.push([f[0], f[3], f[2]]);
            } else {
                triangles.push([f[0], f[1], f[2]]);
            }
        }
        if reverse {
            for t in &mut triangles {
                t.swap(1, 2);
            }
        }
        let normals = match p.get("N") {
            Some(q) => self.vectors(q),
            None => Vec::new(),
        };
        let uvs: Vec<[f64; 2]> = match p.get("uv") {
            Some(q) if q.nums.len() % 2 == 0 => {
                q.nums.chunks_exact(2).map(|c| [c[0], c[1]]).collect()
            }
            Some(q) => return Err(self.error(&q.loc, "expected uv pairs")),
            None => Vec::new(),
        };
        for key in ["S", "faceIndices"] {
            p.get(key);
        }
        // Bilinear patches without uv have pbrt's (u, v) over each: (0, 0) at p00, (1, 0) at
        // p10, (0, 1) at p01. Each patch then has corners of its own.
        let in_range = indices.iter().all(|&i| (i as usize) < positions.len());
        let normals_in_range = normals.is_empty() || normals.len() == positions.len();
        if per == 4 && uvs.is_empty() && in_range && normals_in_range {
            let corner = |k: usize| indices[k] as usize;
            let unshared: Vec<usize> = (0..indices.len()).map(corner).collect();
            let positions = unshared.iter().map(|&i| positions[i]).collect();
            let normals = match normals.is_empty() {
                true => Vec::new(),
                false => unshared.iter().map(|&i| normals[i]).collect(),
            };
            let square = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]];
            let uvs = (0..indices.len()).map(|k| square[k % 4]).collect();
            let mut triangles: Vec<[u32; 3]> = (0..indices.len() as u32 / 4)
                .flat_map(|f| [[4 * f, 4 * f + 1, 4 * f + 3], [4 * f, 4 * f + 3, 4 * f + 2]])
                .collect();
            if reverse {
                triangles.iter_mut().for_each(|t| t.swap(1, 2));
            }
            return TriangleMesh::new(positions, triangles, normals, uvs)
                .map_err(|e| self.error(&pq.loc, e.to_string()));
        }
        // pbrt's triangles without uv: (0, 0), (1, 0), (1, 1) at their corners, in the order
        // given (reversed above, so turned back here).
        let [a, b, c] = PBRT_TRIANGLE_UVS;
        let corners = if reverse { [a, c, b] } else { [a, b, c] };
        TriangleMesh::new(positions, triangles, normals, uvs)
            .map(|m| m.with_corner_uvs(corners))
            .map_err(|e| self.error(&pq.loc, e.to_string()))
    }

    fn shape(&mut self, ty: &str, p: &Params, loc: &Loc) -> Result<()> {
        let area = self.state.area_light.clone();
        // The side a one-sided area light emits from follows ReverseOrientation.
        let reverse = self.state.reverse_orientation && area.as_ref().is_some_and(|a| !a.two_sided);
        // A partial quadric (pbrt-v4's zmin, zmax, innerradius, phimax): what it keeps. An
        // area light is sampled over its whole shape, so a light stays whole.
        let emits = area.is_some();
        let cut = |s: &mut Self, keys: &[&str], partial: Partial| -> Option<Partial> {
            let cut = partial.cut()?;
            if emits {
                let l = keys
                    .iter()
                    .find_map(|k| p.get(k))
                    .map_or_else(|| loc.clone(), |q| q.loc.clone());
                s.warn(
                    &l,
                    "a partial shape cannot be an area light: the whole shape emits",
                );
                return None;
            }
            Some(cut)
        };
        let phi_max = |s: &Self| -> Result<f64> {
            let degrees = s.float(p, "phimax", 360.0)?.clamp(0.0, 360.0);
            Ok(if degrees >= 360.0 {
                std::f64::consts::TAU
            } else {
                degrees.to_radians()
            })
        };
        let mut frame = Transform::IDENTITY;
        let shape = match ty {
            "sphere" => {
                let r = self.positive(p, "radius", 1.0)?;
                let (z0, z1) = (self.float(p, "zmin", -r)?, self.float(p, "zmax", r)?);
                let (z0, z1) = (z0.min(z1).clamp(-r, r), z0.max(z1).clamp(-r, r));
                let partial = Partial {
                    z_min: if z0 > -r { z0 } else { f64::NEG_INFINITY },
                    z_max: if z1 < r { z1 } else { f64::INFINITY },
                    phi_max: phi_max(self)?,
                    ..Partial::WHOLE
                };
                if reverse {
                    self.warn(loc, "ReverseOrientation on a one-sided sphere light is not supported: it emits outward");
                }
                let sphere = Sphere::new(Vec3::ZERO, r).with_uv_map(UvMap::Pbrt);
                match cut(self, &["zmin", "zmax", "phimax"], partial) {
                    Some(c) => Shape::Sphere(sphere.with_partial(c)),
                    None => Shape::Sphere(sphere),
                }
            }
            "disk" => {
                let h = self.float(p, "height", 0.0)?;
                let r = self.positive(p, "radius", 1.0)?;
                let partial = Partial {
                    inner_radius: self.float(p, "innerradius", 0.0)?.max(0.0),
                    phi_max: phi_max(self)?,
                    ..Partial::WHOLE
                };
                let n = if reverse { -Vec3::Z } else { Vec3::Z };
                let disk = Disk::new(Vec3::new(0.0, 0.0, h), n, r).with_uv_map(UvMap::Pbrt);
                match cut(self, &["innerradius", "phimax"], partial) {
                    Some(c) => Shape::Disk(disk.with_partial(c)),
                    None => Shape::Disk(disk),
                }
            }
            "cylinder" => {
                let r = self.positive(p, "radius", 1.0)?;
                let (z0, z1) = (self.float(p, "zmin", -1.0)?, self.float(p, "zmax", 1.0)?);
                if z1 <= z0 {
                    return Err(
                        self.error(loc, format!("expected zmax > zmin, found {z1} and {z0}"))
                    );
                }
                let partial = Partial {
                    phi_max: phi_max(self)?,
                    ..Partial::WHOLE
                };
                frame = Transform::translate(Vec3::new(0.0, 0.0, z0));
                let cylinder = Cylinder::new(r, z1 - z0, false).with_uv_map(UvMap::Pbrt);
                match cut(self, &["phimax"], partial) {
                    Some(c) => Shape::Cylinder(cylinder.with_partial(c)),
                    None => Shape::Cylinder(cylinder),
                }
            }
            "trianglemesh" => Shape::Mesh(Arc::new(self.mesh(p, loc, 3, reverse)?)),
            "bilinearmesh" => Shape::Mesh(Arc::new(self.mesh(p, loc, 4, reverse)?)),
            "loopsubdiv" => {
                self.integer(p, "levels", 3)?;
                self.warn(
                    loc,
                    "loopsubdiv: subdivision is not supported: the control mesh is rendered",
                );
                Shape::Mesh(Arc::new(self.mesh(p, loc, 3, reverse)?))
            }
            "plymesh" => {
                let Some((file, floc)) = self.string(p, "filename")? else {
                    return Err(self.error(loc, "a plymesh needs a \"string filename\""));
                };
                let path = self.path_in(floc.file, file);
                let bytes = std::fs::read(&path).map_err(|e| {
                    self.error(&floc, format!("cannot read {}: {e}", path.display()))
                })?;
                let bytes = if file.ends_with(".gz") {
                    use std::io::Read;
                    let mut out = Vec::new();
                    flate2::read::GzDecoder::new(&bytes[..])
                        .read_to_end(&mut out)
                        .map_err(|e| {
                            self.error(&floc, format!("cannot decompress {}: {e}", path.display()))
                        })?;
                    out
                } else {
                    bytes
                };
                let mesh = crate::ply::parse_ply_pbrt(&path, &bytes, PBRT_TRIANGLE_UVS)
                    .map_err(|e| self.error(&floc, format!("{}: {}", path.display(), e.message)))?;
                for key in ["displacement", "edgelength"] {
                    if let Some(q) = p.get(key) {
                        let l = q.loc.clone();
                        self.warn(
                            &l,
                            format!("`{key}`: displacement is not supported: ignored"),
                        );
                    }
                }
                if reverse {
                    self.warn(loc, "ReverseOrientation on a one-sided PLY light is not supported: it emits as its faces are wound");
                }
                Shape::Mesh(Arc::new(mesh))
            }
            "curve" => {
                self.warn(loc, "curves are not supported: skipped");
                p.list.iter().for_each(|q| q.used.set(true));
                return Ok(());
            }
            other => {
                return Err(self.unknown(
                    loc,
                    "shape",
                    other,
                    &[
                        "sphere",
                        "disk",
                        "cylinder",
                        "trianglemesh",
                        "bilinearmesh",
                        "loopsubdiv",
                        "plymesh",
                        "curve",
                    ],
                ));
            }
        };
        if let Some(q) = p.get("emissionfilename") {
            let l = q.loc.clone();
            self.warn(&l, "`emissionfilename` is not supported: ignored");
        }
        // A cut-out, tested stochastically as pbrt-v4 does. Light sampling would still see
        // an area light's cut-away parts, so a light stays whole.
        let alpha = match p.get("alpha") {
            Some(q) if area.is_some() => {
                let l = q.loc.clone();
                self.warn(
                    &l,
                    "`alpha` on an area light is not supported: the light is whole",
                );
                None
            }
            Some(_) => Some(Alpha::stochastic(self.float_texture(p, "alpha", 1.0)?)),
            None => None,
        };
        let m = self.ctm().mul(&frame.matrix);
        let m_end = self.ctm_end().mul(&frame.matrix);
        let to_world = Transform::from_matrix(m)
            .ok_or_else(|| self.error(loc, "the shape's transformation is singular"))?;
        let to_world_end = Transform::from_matrix(m_end)
            .ok_or_else(|| self.error(loc, "the shape's end-time transformation is singular"))?;
        let moves = m_end != m;
        let material = self.material_now();
        self.count += 1;
        let name = format!("{ty} {}", self.count);
        if let Some((_, shapes)) = &mut self.recording {
            shapes.push(Recorded {
                name,
                shape,
                to_world: m,
                to_world_end: m_end,
                material,
                alpha,
            });
            if area.is_some() {
                self.warn(loc, "an area light inside an object instance is not supported (nor in pbrt-v4): not emitting");
            }
            return Ok(());
        }
        match area {
            Some(a) => {
                let added = self.builder.add_emissive_object(
                    name,
                    shape,
                    to_world,
                    material,
                    a.radiance,
                    a.two_sided,
                    1,
                );
                if !added {
                    self.warn(
                        loc,
                        format!(
                            "a {ty} cannot be an area light in Plenum: placed without emitting"
                        ),
                    );
                } else {
                    self.finish_area_light(a, loc);
                }
                if moves {
                    self.warn(loc, "a moving area light is not supported: it stays at its start-time transformation");
                }
            }
            None => {
                self.builder.add_object(name, shape, to_world, material);
                if let Some(alpha) = alpha {
                    self.builder.set_last_alpha(alpha);
                }
                if moves {
                    self.builder.set_last_motion(to_world_end);
                }
            }
        }
        Ok(())
    }

    // ---- The camera ----

    fn finish(&mut self) {
        let (m, params, ty, loc) = match self.camera.take() {
            Some(c) => c,
            None => (
                [Matrix4::IDENTITY; 2],
                Params { list: Vec::new() },
                "perspective".to_string(),
                Loc {
                    file: 0,
                    span: 0..0,
                },
            ),
        };
        let (w, h) = (self.defaults.width as f64, self.defaults.height as f64);
        // Where the camera is, looks and has its up at the start and end times.
        let frame = |m: Matrix4| {
            let world_from_camera = Transform::from_matrix(m)
                .map(|t| t.inverted())
                .unwrap_or(Transform::IDENTITY);
            (
                world_from_camera,
                world_from_camera.point(Vec3::ZERO),
                world_from_camera.vector(Vec3::Z).normalized(),
                world_from_camera.vector(Vec3::Y).normalized(),
            )
        };
        let (world_from_camera, position, forward, up) = frame(m[0]);
        let (_, position_end, forward_end, up_end) = frame(m[1]);
        let motion = (m[1] != m[0]).then_some((position_end, position_end + forward_end));
        if motion.is_some() && up_end.dot(up) < 1.0 - 1e-9 {
            self.warn(&loc, "the camera's turn about its view while the shutter is open is not supported: it keeps its start-time up");
        }
        // pbrt's image x runs along camera +x; Plenum's along forward × up unless told.
        let left_handed = world_from_camera.vector(Vec3::X).dot(forward.cross(up)) < 0.0;
        if ty != "perspective" && ty != "orthographic" {
            self.warn(
                &loc,
                format!("the `{ty}` camera is not supported: a perspective camera"),
            );
        }
        // pbrt's orthographic view is its screen window in camera units: by default
        // [−1, 1] across the shorter image axis.
        let orthographic = (ty == "orthographic").then(|| {
            let window = params
                .get("screenwindow")
                .filter(|q| q.nums.len() == 4 && q.nums[3] > q.nums[2]);
            match window {
                Some(q) => q.nums[3] - q.nums[2],
                None if w >= h => 2.0,
                None => 2.0 * h / w,
            }
        });
        let fov = match self.float(&params, "fov", 90.0) {
            Ok(f) if f > 0.0 && f < 180.0 => f,
            _ => 90.0,
        };
        // The fov spans the shorter image axis.
        let vertical = if w >= h {
            fov
        } else {
            2.0 * ((0.5 * fov).to_radians().tan() * h / w).atan().to_degrees()
        };
        let radius = self
            .float(&params, "lensradius", 0.0)
            .unwrap_or(0.0)
            .max(0.0);
        let focus = self.float(&params, "focaldistance", 1e6).unwrap_or(1e6);
        if orthographic.is_some() && radius > 0.0 {
            self.warn(&loc, "a lens on an orthographic camera is not supported: its rays stay parallel, all in focus");
        }
        for key in ["screenwindow", "frameaspectratio"] {
            if key == "screenwindow" && orthographic.is_some() {
                // Its height was read; a window off the axis, or of another aspect, is not.
                if let Some(q) = params.get(key) {
                    let n = &q.nums;
                    let centred = n.len() == 4
                        && (n[0] + n[1]).abs() < 1e-9
                        && (n[2] + n[3]).abs() < 1e-9
                        && ((n[1] - n[0]) / (n[3] - n[2]) - w / h).abs() < 1e-6;
                    if !centred {
                        let l = q.loc.clone();
                        self.warn(&l, "an orthographic `screenwindow` off centre or of another aspect than the image's: its height is used, centred");
                    }
                }
                continue;
            }
            if let Some(q) = params.get(key) {
                let l = q.loc.clone();
                self.warn(
                    &l,
                    format!("`{key}` is not supported: the image's own aspect is used"),
                );
            }
        }
        // The shutter in the times of the two transformations, which Plenum's motion puts at
        // 0 and 1 (before and after them, things stay where they are, as in pbrt).
        let (t0, t1) = self.transform_times;
        let open = self.float(&params, "shutteropen", 0.0).unwrap_or(0.0);
        let close = self.float(&params, "shutterclose", 1.0).unwrap_or(1.0);
        let shutter = if close >= open {
            [(open - t0) / (t1 - t0), (close - t0) / (t1 - t0)]
        } else {
            self.warn(
                &loc,
                "the shutter closes before it opens: it opens at 0 and closes at 1",
            );
            [(0.0 - t0) / (t1 - t0), (1.0 - t0) / (t1 - t0)]
        };
        self.report_unused("Camera", &ty, &params);
        self.builder.camera = CameraSettings {
            position,
            look_at: position + forward,
            up,
            fov_degrees: vertical,
            lens: Lens {
                radius,
                focus_distance: if focus > 0.0 { focus } else { 1e6 },
                ..Lens::default()
            },
            left_handed,
            shutter,
            motion,
            orthographic,
        };
    }
}
