//! Mitsuba 3's XML, the document layer: elements into plugin objects and their typed
//! properties, as Mitsuba's own parser reads them (`src/core/parser.cpp` of Mitsuba 3.9):
//! `$name` substitution in every attribute from `<default>`s, `<include>` relative to the
//! including file, `id`s and `<ref>`s (forward ones too), `<transform>`s composed in the order
//! written, and version-0.x files' camelCase names upgraded. Every object and property keeps
//! where it was written, so that the plugin layer can locate errors and warnings.

use crate::diagnostics::{did_you_mean, SceneError};
use crate::limits::MAX_NESTING;
use plenum_core::math::{Matrix4, Transform, Vec3};
use std::cell::Cell;
use std::collections::HashMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The deepest `<include>` chain, and the most files a scene may read (a file that includes
/// another twice, which includes another twice, … would otherwise read 2^depth files).
const MAX_INCLUDE_DEPTH: usize = 32;
const MAX_FILES: usize = 4096;
/// The most XML nodes a file may hold (far beyond any scene; bounds memory on bad input).
const MAX_NODES: u32 = 10_000_000;

pub type Result<T> = std::result::Result<T, SceneError>;

/// A file read: its path (for messages and relative paths) and text.
pub struct Source {
    pub path: PathBuf,
    pub text: String,
}

/// Where something was written: a file of [`Document::sources`] and a byte range in it.
#[derive(Clone, Debug)]
pub struct Loc {
    pub file: usize,
    pub span: Range<usize>,
}

/// A spectrum as written: one value, or (wavelength in nm, value) pairs.
#[derive(Clone, Debug)]
pub enum SpectrumData {
    Constant(f64),
    Pairs(Vec<(f64, f64)>),
}

/// A property's value.
#[derive(Clone, Debug)]
pub enum Value {
    Float(f64),
    Integer(i64),
    Boolean(bool),
    String(String),
    /// `<point>` or `<vector>`.
    Vector(Vec3),
    /// `<rgb>` (linear), or `<srgb>` already decoded.
    Rgb([f64; 3]),
    Spectrum(SpectrumData),
    Transform(Matrix4),
    /// `<ref id="…">`, resolved by [`Document::object_of`].
    Ref(String),
    /// A nested plugin: an index into [`Document::objects`].
    Object(usize),
}

impl Value {
    fn kind(&self) -> &'static str {
        match self {
            Value::Float(_) => "a float",
            Value::Integer(_) => "an integer",
            Value::Boolean(_) => "a boolean",
            Value::String(_) => "a string",
            Value::Vector(_) => "a point or vector",
            Value::Rgb(_) => "an rgb colour",
            Value::Spectrum(_) => "a spectrum",
            Value::Transform(_) => "a transform",
            Value::Ref(_) | Value::Object(_) => "a plugin",
        }
    }
}

pub struct Property {
    pub name: String,
    pub value: Value,
    pub loc: Loc,
    /// Set when the plugin layer reads it; what is never read is reported as ignored.
    pub used: Cell<bool>,
}

/// A plugin object: `<bsdf type="diffuse" id="white">…</bsdf>`.
pub struct Object {
    /// The element: `scene`, `shape`, `bsdf`, `emitter`, `sensor`, `film`, …
    pub tag: String,
    /// The `type` attribute (`scene` for the root).
    pub plugin: String,
    pub id: Option<String>,
    pub props: Vec<Property>,
    pub loc: Loc,
}

/// A whole scene: every file read, every object (the root scene first).
pub struct Document {
    pub sources: Vec<Source>,
    pub objects: Vec<Object>,
    pub ids: HashMap<String, usize>,
}

/// The elements that make plugin objects.
const OBJECT_TAGS: &[&str] = &[
    "scene",
    "shape",
    "bsdf",
    "emitter",
    "sensor",
    "film",
    "rfilter",
    "sampler",
    "integrator",
    "texture",
    "medium",
    "phase",
    "volume",
];

const PROPERTY_TAGS: &[&str] = &[
    "float",
    "integer",
    "boolean",
    "string",
    "point",
    "vector",
    "rgb",
    "srgb",
    "spectrum",
    "transform",
    "ref",
    "include",
    "default",
    "alias",
    "path",
];

impl Document {
    /// Reads the scene file `path` (whose text is `text`) and everything it includes.
    pub fn parse(path: &Path, text: String) -> Result<Document> {
        let mut parser = Parser {
            doc: Document {
                sources: Vec::new(),
                objects: Vec::new(),
                ids: HashMap::new(),
            },
            params: Vec::new(),
            include_depth: 0,
            include_stack: Vec::new(),
        };
        parser.file(path.to_path_buf(), text, None, 0)?;
        if parser.doc.objects.first().map(|o| o.tag.as_str()) != Some("scene") {
            let loc = parser.doc.objects.first().map_or(
                Loc {
                    file: 0,
                    span: 0..0,
                },
                |o| o.loc.clone(),
            );
            return Err(parser
                .doc
                .error(&loc, "expected a <scene> element at the top of the file"));
        }
        Ok(parser.doc)
    }

    /// A located error.
    pub fn error(&self, loc: &Loc, message: impl Into<String>) -> SceneError {
        let s = &self.sources[loc.file];
        SceneError::at(&s.path, &s.text, loc.span.clone(), message)
    }

    /// A located warning line.
    pub fn warning(&self, loc: &Loc, message: impl Into<String>) -> String {
        self.error(loc, message).as_warning()
    }

    /// The folder that paths written in file `file` are relative to.
    pub fn base_dir(&self, file: usize) -> &Path {
        self.sources[file].path.parent().unwrap_or(Path::new("."))
    }

    /// The object a property holds or refers to; an error where the id is unknown.
    pub fn object_of(&self, p: &Property) -> Result<Option<usize>> {
        match &p.value {
            Value::Object(i) => Ok(Some(*i)),
            Value::Ref(id) => match self.ids.get(id) {
                Some(&i) => Ok(Some(i)),
                None => {
                    let e = self.error(&p.loc, format!("no object has the id `{id}`"));
                    Err(
                        match did_you_mean(id, self.ids.keys().map(String::as_str)) {
                            Some(s) => e.with_help(format!("did you mean `{s}`?")),
                            None => e,
                        },
                    )
                }
            },
            _ => Ok(None),
        }
    }

    /// An error about a property whose value has the wrong type.
    pub fn expected(&self, p: &Property, what: &str) -> SceneError {
        self.error(
            &p.loc,
            format!(
                "expected `{}` to be {what}, found {}",
                p.name,
                p.value.kind()
            ),
        )
    }
}

struct Parser {
    doc: Document,
    /// `<default>` parameters, `$name` → value, the longest names first (so that `$ab` is
    /// replaced before `$a`).
    params: Vec<(String, String)>,
    /// How many `<include>`s deep the file being read is.
    include_depth: usize,
    /// The files including the one being read, to refuse one that includes itself.
    include_stack: Vec<Option<PathBuf>>,
}

/// An element's attributes after substitution, with where each value was written.
struct Attributes {
    list: Vec<(String, String, Range<usize>)>,
}

impl Attributes {
    fn get(&self, name: &str) -> Option<(&str, Range<usize>)> {
        self.list
            .iter()
            .find(|(n, _, _)| n == name)
            .map(|(_, v, r)| (v.as_str(), r.clone()))
    }
}

impl Parser {
    fn loc(&self, file: usize, span: Range<usize>) -> Loc {
        Loc { file, span }
    }

    /// Parses one file; `parent` is the object its top element belongs to (none for the
    /// main file). Returns nothing: objects and properties are added to the document.
    fn file(
        &mut self,
        path: PathBuf,
        text: String,
        parent: Option<(usize, Option<String>)>,
        depth: usize,
    ) -> Result<()> {
        let file = self.doc.sources.len();
        self.doc.sources.push(Source { path, text });
        // The document borrows the text, which stays in `sources`; parse from a copy of the
        // pointer-stable String by cloning (scene files are small next to their meshes).
        let text = self.doc.sources[file].text.clone();
        let options = roxmltree::ParsingOptions {
            allow_dtd: false,
            nodes_limit: MAX_NODES,
            ..Default::default()
        };
        let xml = roxmltree::Document::parse_with_options(&text, options).map_err(|e| {
            let pos = e.pos();
            let offset = byte_offset(&text, pos.row as usize, pos.col as usize);
            self.doc.error(
                &Loc {
                    file,
                    span: offset..offset + 1,
                },
                format!("malformed XML: {e}"),
            )
        })?;
        let root = xml.root_element();
        let version = root.attribute("version");
        let old = match version {
            Some(v) => {
                let major = v.trim().split('.').next().unwrap_or("");
                match major.parse::<u32>() {
                    Ok(m) => m < 2,
                    Err(_) => {
                        let span = root.attribute_node("version").unwrap().range_value();
                        return Err(self.doc.error(
                            &self.loc(file, span),
                            format!("expected a version such as 3.0.0, found `{v}`"),
                        ));
                    }
                }
            }
            None => {
                return Err(self.doc.error(
                    &self.loc(file, root.range().start..root.range().start + 1),
                    "the top element needs a `version` attribute (such as version=\"3.0.0\")",
                ))
            }
        };
        let ctx = FileContext { file, old };
        match parent {
            None => {
                self.element(&ctx, root, None, 0, true)?;
            }
            Some((parent, name)) => {
                if root.tag_name().name() == "scene" {
                    // An included scene's children join the including element.
                    let attrs = self.attributes(&ctx, root)?;
                    self.check_attributes(&ctx, root, &attrs, &["version"], &[])?;
                    for child in root.children().filter(|c| c.is_element()) {
                        self.element(&ctx, child, Some(parent), depth, false)?;
                    }
                } else {
                    let before = self.doc.objects.len();
                    self.element(&ctx, root, Some(parent), depth, true)?;
                    // An included plugin takes the <include>'s name, if it has one.
                    if let Some(name) = name {
                        let owner = &mut self.doc.objects[parent];
                        if let Some(p) = owner
                            .props
                            .iter_mut()
                            .rev()
                            .find(|p| matches!(p.value, Value::Object(i) if i == before))
                        {
                            p.name = name;
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// Attribute values with `$name` substituted; an error for an undefined parameter.
    fn attributes(&self, ctx: &FileContext, node: roxmltree::Node) -> Result<Attributes> {
        let mut list = Vec::new();
        for a in node.attributes() {
            let span = a.range_value();
            let mut value = a.value().to_string();
            if value.contains('$') {
                value = self.substitute(ctx, &value, span.clone())?;
            }
            list.push((a.name().to_string(), value, span));
        }
        Ok(Attributes { list })
    }

    fn substitute(&self, ctx: &FileContext, value: &str, span: Range<usize>) -> Result<String> {
        let mut out = String::with_capacity(value.len());
        let bytes = value.as_bytes();
        let mut i = 0;
        while i < value.len() {
            if bytes[i] == b'\\' && bytes.get(i + 1) == Some(&b'$') {
                out.push('$');
                i += 2;
                continue;
            }
            if bytes[i] == b'$' {
                let rest = &value[i + 1..];
                if let Some((key, v)) = self
                    .params
                    .iter()
                    .find(|(k, _)| rest.starts_with(k.as_str()))
                {
                    out.push_str(v);
                    i += 1 + key.len();
                    continue;
                }
                let name: String = rest
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                    .collect();
                let e = self.doc.error(
                    &self.loc(ctx.file, span),
                    format!("undefined parameter `${name}`"),
                );
                return Err(e.with_help(
                    "define it with <default name=\"…\" value=\"…\"/> before its first use",
                ));
            }
            let c = value[i..].chars().next().unwrap();
            out.push(c);
            i += c.len_utf8();
        }
        Ok(out)
    }

    fn check_attributes(
        &self,
        ctx: &FileContext,
        node: roxmltree::Node,
        attrs: &Attributes,
        allowed: &[&str],
        required: &[&str],
    ) -> Result<()> {
        for (name, _, _) in &attrs.list {
            if !allowed.contains(&name.as_str()) && !required.contains(&name.as_str()) {
                let a = node.attributes().find(|a| a.name() == name).unwrap();
                let all: Vec<&str> = allowed.iter().chain(required).copied().collect();
                return Err(self.doc.error(
                    &self.loc(ctx.file, a.range()),
                    format!(
                        "unexpected attribute `{name}` on <{}>: expected {}",
                        node.tag_name().name(),
                        if all.is_empty() {
                            "none".to_string()
                        } else {
                            all.join(", ")
                        }
                    ),
                ));
            }
        }
        for r in required {
            if attrs.get(r).is_none() {
                return Err(self.doc.error(
                    &self.loc(ctx.file, tag_span(node)),
                    format!("<{}> needs a `{r}` attribute", node.tag_name().name()),
                ));
            }
        }
        Ok(())
    }

    /// One element under `parent` (none: the top of the main file).
    fn element(
        &mut self,
        ctx: &FileContext,
        node: roxmltree::Node,
        parent: Option<usize>,
        depth: usize,
        top: bool,
    ) -> Result<()> {
        if depth > MAX_NESTING {
            return Err(self.doc.error(
                &self.loc(ctx.file, tag_span(node)),
                format!("elements nested deeper than {MAX_NESTING} levels"),
            ));
        }
        let tag = node.tag_name().name();
        let attrs = self.attributes(ctx, node)?;
        let loc = self.loc(ctx.file, tag_span(node));
        // `<spectrum type="…">` is a plugin (a spectrum texture).
        let is_object =
            OBJECT_TAGS.contains(&tag) || (tag == "spectrum" && attrs.get("type").is_some());
        if is_object {
            if top {
                self.check_attributes(ctx, node, &attrs, &["type", "id", "name"], &["version"])?;
            } else if tag == "scene" {
                return Err(self.doc.error(&loc, "a <scene> inside another element"));
            } else {
                self.check_attributes(ctx, node, &attrs, &["id", "name"], &["type"])?;
            }
            let plugin = attrs
                .get("type")
                .map_or("scene".to_string(), |(t, _)| t.to_string());
            let id = attrs.get("id").map(|(i, _)| i.to_string());
            let index = self.doc.objects.len();
            if let (Some(id), Some((_, span))) = (&id, attrs.get("id")) {
                if self.doc.ids.insert(id.clone(), index).is_some() {
                    return Err(self.doc.error(
                        &self.loc(ctx.file, span),
                        format!("the id `{id}` is given twice"),
                    ));
                }
            }
            self.doc.objects.push(Object {
                tag: tag.to_string(),
                plugin,
                id,
                props: Vec::new(),
                loc: loc.clone(),
            });
            if let Some(parent) = parent {
                let name = self.property_name(parent, attrs.get("name").map(|(n, _)| n), ctx);
                self.doc.objects[parent].props.push(Property {
                    name,
                    value: Value::Object(index),
                    loc: loc.clone(),
                    used: Cell::new(false),
                });
            }
            for child in node.children().filter(|c| c.is_element()) {
                self.element(ctx, child, Some(index), depth + 1, false)?;
            }
            if ctx.old {
                // Mitsuba 0.6's diffuse called its colour `diffuseReflectance`.
                let o = &mut self.doc.objects[index];
                if o.plugin == "diffuse" {
                    for p in &mut o.props {
                        if p.name == "diffuse_reflectance" {
                            p.name = "reflectance".into();
                        }
                    }
                }
            }
            return Ok(());
        }
        let Some(parent) = parent else {
            return Err(self
                .doc
                .error(&loc, format!("expected <scene>, found <{tag}>")));
        };
        if !PROPERTY_TAGS.contains(&tag) {
            let known = OBJECT_TAGS.iter().chain(PROPERTY_TAGS).copied();
            let e = self.doc.error(&loc, format!("unknown element <{tag}>"));
            return Err(match did_you_mean(tag, known) {
                Some(s) => e.with_help(format!("did you mean <{s}>?")),
                None => e,
            });
        }
        if tag != "transform" {
            if let Some(child) = node.children().find(|c| c.is_element()) {
                return Err(self.doc.error(
                    &self.loc(ctx.file, tag_span(child)),
                    format!("<{tag}> holds no elements"),
                ));
            }
        }
        let number = |s: &str, span: Range<usize>| -> Result<f64> {
            parse_number(s).ok_or_else(|| {
                self.doc.error(
                    &self.loc(ctx.file, span),
                    format!("expected a number, found `{s}`"),
                )
            })
        };
        let value = match tag {
            "default" => {
                self.check_attributes(ctx, node, &attrs, &[], &["name", "value"])?;
                let (name, span) = attrs.get("name").unwrap();
                if name.is_empty() {
                    return Err(self
                        .doc
                        .error(&self.loc(ctx.file, span), "an empty parameter name"));
                }
                let key = name.to_string();
                if !self.params.iter().any(|(k, _)| *k == key) {
                    let value = attrs.get("value").unwrap().0.to_string();
                    let at = self.params.iter().position(|(k, _)| k.len() < key.len());
                    self.params
                        .insert(at.unwrap_or(self.params.len()), (key, value));
                }
                return Ok(());
            }
            "include" => {
                self.check_attributes(ctx, node, &attrs, &["name"], &["filename"])?;
                let (filename, span) = attrs.get("filename").unwrap();
                let path = self.doc.base_dir(ctx.file).join(filename);
                if self.include_depth >= MAX_INCLUDE_DEPTH {
                    return Err(self.doc.error(
                        &self.loc(ctx.file, span),
                        format!("includes nested deeper than {MAX_INCLUDE_DEPTH} files"),
                    ));
                }
                if self.doc.sources.len() >= MAX_FILES {
                    return Err(self.doc.error(
                        &self.loc(ctx.file, span),
                        format!("more than {MAX_FILES} files included"),
                    ));
                }
                let canonical = std::fs::canonicalize(&path).ok();
                let own = std::fs::canonicalize(&self.doc.sources[ctx.file].path).ok();
                if canonical.is_some()
                    && (canonical == own || self.include_stack.contains(&canonical))
                {
                    return Err(self.doc.error(
                        &self.loc(ctx.file, span),
                        format!("{} includes itself", path.display()),
                    ));
                }
                let bytes = std::fs::read(&path).map_err(|e| {
                    self.doc.error(
                        &self.loc(ctx.file, span.clone()),
                        format!("cannot read the included file {}: {e}", path.display()),
                    )
                })?;
                let (text, _) = crate::text::lenient(&path, bytes);
                self.include_depth += 1;
                self.include_stack.push(own);
                let name = attrs.get("name").map(|(n, _)| n.to_string());
                let r = self.file(path, text, Some((parent, name)), depth + 1);
                self.include_stack.pop();
                self.include_depth -= 1;
                return r;
            }
            "alias" => {
                self.check_attributes(ctx, node, &attrs, &[], &["id", "as"])?;
                let (id, span) = attrs.get("id").unwrap();
                let Some(&target) = self.doc.ids.get(id) else {
                    return Err(self.doc.error(
                        &self.loc(ctx.file, span),
                        format!("no object with the id `{id}` is defined above this alias"),
                    ));
                };
                let (alias, span) = attrs.get("as").unwrap();
                if self.doc.ids.insert(alias.to_string(), target).is_some() {
                    return Err(self.doc.error(
                        &self.loc(ctx.file, span),
                        format!("the id `{alias}` is given twice"),
                    ));
                }
                return Ok(());
            }
            "path" => {
                // Extra folders to look for files in: not followed; files are found
                // relative to the scene file.
                self.check_attributes(ctx, node, &attrs, &[], &["value"])?;
                self.doc.objects[parent].props.push(Property {
                    name: "<path>".into(),
                    value: Value::String(attrs.get("value").unwrap().0.to_string()),
                    loc,
                    used: Cell::new(false),
                });
                return Ok(());
            }
            "ref" => {
                self.check_attributes(ctx, node, &attrs, &["name"], &["id"])?;
                Value::Ref(attrs.get("id").unwrap().0.to_string())
            }
            "float" => {
                self.check_attributes(ctx, node, &attrs, &[], &["name", "value"])?;
                let (v, span) = attrs.get("value").unwrap();
                Value::Float(number(v, span)?)
            }
            "integer" => {
                self.check_attributes(ctx, node, &attrs, &[], &["name", "value"])?;
                let (v, span) = attrs.get("value").unwrap();
                Value::Integer(v.trim().parse::<i64>().map_err(|_| {
                    self.doc.error(
                        &self.loc(ctx.file, span),
                        format!("expected a whole number, found `{v}`"),
                    )
                })?)
            }
            "boolean" => {
                self.check_attributes(ctx, node, &attrs, &[], &["name", "value"])?;
                let (v, span) = attrs.get("value").unwrap();
                Value::Boolean(match v.trim().to_ascii_lowercase().as_str() {
                    "true" => true,
                    "false" => false,
                    _ => {
                        return Err(self.doc.error(
                            &self.loc(ctx.file, span),
                            format!("expected true or false, found `{v}`"),
                        ))
                    }
                })
            }
            "string" => {
                self.check_attributes(ctx, node, &attrs, &[], &["name", "value"])?;
                Value::String(attrs.get("value").unwrap().0.to_string())
            }
            "point" | "vector" => {
                self.check_attributes(ctx, node, &attrs, &["value", "x", "y", "z"], &["name"])?;
                Value::Vector(self.xyz(ctx, node, &attrs, 0.0)?)
            }
            "rgb" | "srgb" => {
                self.check_attributes(ctx, node, &attrs, &[], &["name", "value"])?;
                let (v, span) = attrs.get("value").unwrap();
                let mut c = self.rgb(ctx, v, span)?;
                if tag == "srgb" {
                    c = c.map(srgb_to_linear);
                }
                Value::Rgb(c)
            }
            "spectrum" => {
                self.check_attributes(ctx, node, &attrs, &["value", "filename"], &["name"])?;
                match (attrs.get("value"), attrs.get("filename")) {
                    (Some((v, span)), None) => Value::Spectrum(self.spectrum(ctx, v, span)?),
                    (None, Some((f, span))) => {
                        let path = self.doc.base_dir(ctx.file).join(f);
                        let text = std::fs::read_to_string(&path).map_err(|e| {
                            self.doc.error(
                                &self.loc(ctx.file, span.clone()),
                                format!("cannot read the spectrum file {}: {e}", path.display()),
                            )
                        })?;
                        Value::Spectrum(self.spectrum_file(ctx, &text, span, &path)?)
                    }
                    _ => {
                        return Err(self.doc.error(
                            &loc,
                            "<spectrum> needs either `value` or `filename`, not both",
                        ))
                    }
                }
            }
            "transform" => {
                self.check_attributes(ctx, node, &attrs, &[], &["name"])?;
                let mut m = Matrix4::IDENTITY;
                for op in node.children().filter(|c| c.is_element()) {
                    m = self.transform_op(ctx, op)?.mul(&m);
                }
                Value::Transform(m)
            }
            _ => unreachable!("every property tag is handled"),
        };
        let name = self.property_name(parent, attrs.get("name").map(|(n, _)| n), ctx);
        self.doc.objects[parent].props.push(Property {
            name,
            value,
            loc,
            used: Cell::new(false),
        });
        Ok(())
    }

    /// A property's name: as written (camelCase upgraded in version-0.x files), or
    /// `_arg_N` for an unnamed nested plugin or reference.
    fn property_name(&self, parent: usize, name: Option<&str>, ctx: &FileContext) -> String {
        match name {
            Some(n) if ctx.old => camel_to_snake(n),
            Some(n) => n.to_string(),
            None => format!("_arg_{}", self.doc.objects[parent].props.len()),
        }
    }

    fn xyz(
        &self,
        ctx: &FileContext,
        node: roxmltree::Node,
        attrs: &Attributes,
        default: f64,
    ) -> Result<Vec3> {
        if let Some((v, span)) = attrs.get("value") {
            if let Some((_, s)) = attrs.get("x").or(attrs.get("y")).or(attrs.get("z")) {
                return Err(self.doc.error(
                    &self.loc(ctx.file, s),
                    "give either `value` or `x`, `y`, `z`",
                ));
            }
            let t = self.numbers(ctx, v, span.clone())?;
            return match t.as_slice() {
                [a] => Ok(Vec3::new(*a, *a, *a)),
                [x, y, z] => Ok(Vec3::new(*x, *y, *z)),
                _ => Err(self.doc.error(
                    &self.loc(ctx.file, span),
                    format!("expected 1 or 3 numbers, found {}", t.len()),
                )),
            };
        }
        let _ = node;
        let mut c = [default; 3];
        for (i, axis) in ["x", "y", "z"].iter().enumerate() {
            if let Some((v, span)) = attrs.get(axis) {
                c[i] = parse_number(v).ok_or_else(|| {
                    self.doc.error(
                        &self.loc(ctx.file, span),
                        format!("expected a number, found `{v}`"),
                    )
                })?;
            }
        }
        Ok(Vec3::new(c[0], c[1], c[2]))
    }

    fn numbers(&self, ctx: &FileContext, s: &str, span: Range<usize>) -> Result<Vec<f64>> {
        tokens(s)
            .map(|t| {
                parse_number(t).ok_or_else(|| {
                    self.doc.error(
                        &self.loc(ctx.file, span.clone()),
                        format!("expected a number, found `{t}`"),
                    )
                })
            })
            .collect()
    }

    fn vector3(&self, ctx: &FileContext, s: &str, span: Range<usize>) -> Result<Vec3> {
        match self.numbers(ctx, s, span.clone())?.as_slice() {
            [x, y, z] => Ok(Vec3::new(*x, *y, *z)),
            t => Err(self.doc.error(
                &self.loc(ctx.file, span),
                format!("expected 3 numbers, found {}", t.len()),
            )),
        }
    }

    fn rgb(&self, ctx: &FileContext, s: &str, span: Range<usize>) -> Result<[f64; 3]> {
        let s = s.trim();
        if let Some(hex) = s.strip_prefix('#') {
            // `#rrggbb`, sRGB-encoded.
            let ok = hex.len() == 6 && hex.chars().all(|c| c.is_ascii_hexdigit());
            if !ok {
                return Err(self.doc.error(
                    &self.loc(ctx.file, span),
                    format!("expected a colour #rrggbb, found `{s}`"),
                ));
            }
            let byte = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).unwrap() as f64 / 255.0;
            return Ok([byte(0), byte(2), byte(4)].map(srgb_to_linear));
        }
        match self.numbers(ctx, s, span.clone())?.as_slice() {
            [v] => Ok([*v; 3]),
            [r, g, b] => Ok([*r, *g, *b]),
            t => Err(self.doc.error(
                &self.loc(ctx.file, span),
                format!("expected 1 or 3 numbers, found {}", t.len()),
            )),
        }
    }

    fn spectrum(&self, ctx: &FileContext, s: &str, span: Range<usize>) -> Result<SpectrumData> {
        let list: Vec<&str> = tokens(s).collect();
        if let [one] = list.as_slice() {
            if !one.contains(':') {
                return parse_number(one)
                    .map(SpectrumData::Constant)
                    .ok_or_else(|| {
                        self.doc.error(
                            &self.loc(ctx.file, span),
                            format!("expected a number or wavelength:value pairs, found `{one}`"),
                        )
                    });
            }
        }
        let mut pairs = Vec::with_capacity(list.len());
        for t in list {
            let pair = t
                .split_once(':')
                .and_then(|(l, v)| Some((parse_number(l)?, parse_number(v)?)));
            match pair {
                Some(p) => pairs.push(p),
                None => {
                    return Err(self.doc.error(
                        &self.loc(ctx.file, span),
                        format!("expected wavelength:value pairs (nm), found `{t}`"),
                    ))
                }
            }
        }
        Ok(SpectrumData::Pairs(pairs))
    }

    fn spectrum_file(
        &self,
        ctx: &FileContext,
        text: &str,
        span: Range<usize>,
        path: &Path,
    ) -> Result<SpectrumData> {
        let mut pairs = Vec::new();
        for (n, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let v: Vec<Option<f64>> = line.split_whitespace().map(parse_number).collect();
            match v.as_slice() {
                [Some(l), Some(x)] => pairs.push((*l, *x)),
                _ => {
                    return Err(self.doc.error(
                        &self.loc(ctx.file, span),
                        format!(
                            "{}:{}: expected a wavelength in nm and a value",
                            path.display(),
                            n + 1
                        ),
                    ))
                }
            }
        }
        Ok(SpectrumData::Pairs(pairs))
    }

    /// One operation inside `<transform>`, as a matrix.
    fn transform_op(&self, ctx: &FileContext, node: roxmltree::Node) -> Result<Matrix4> {
        let attrs = self.attributes(ctx, node)?;
        let loc = self.loc(ctx.file, tag_span(node));
        let tag = node.tag_name().name();
        let singular = |what: &str| self.doc.error(&loc, format!("a singular {what}"));
        let t = match tag {
            "translate" => {
                self.check_attributes(ctx, node, &attrs, &["value", "x", "y", "z"], &[])?;
                Transform::translate(self.xyz(ctx, node, &attrs, 0.0)?)
            }
            "scale" => {
                self.check_attributes(ctx, node, &attrs, &["value", "x", "y", "z"], &[])?;
                Transform::scale(self.xyz(ctx, node, &attrs, 1.0)?)
                    .ok_or_else(|| singular("scale (a factor is zero)"))?
            }
            "rotate" => {
                self.check_attributes(ctx, node, &attrs, &["value", "x", "y", "z"], &["angle"])?;
                let axis = self.xyz(ctx, node, &attrs, 0.0)?;
                let (a, span) = attrs.get("angle").unwrap();
                let angle = parse_number(a).ok_or_else(|| {
                    self.doc.error(
                        &self.loc(ctx.file, span),
                        format!("expected an angle in degrees, found `{a}`"),
                    )
                })?;
                Transform::rotate(axis, angle)
                    .ok_or_else(|| self.doc.error(&loc, "the rotation axis is zero"))?
            }
            "lookat" => {
                self.check_attributes(ctx, node, &attrs, &["up"], &["origin", "target"])?;
                let (o, os) = attrs.get("origin").unwrap();
                let (t, ts) = attrs.get("target").unwrap();
                let origin = self.vector3(ctx, o, os)?;
                let target = self.vector3(ctx, t, ts)?;
                let mut up = match attrs.get("up") {
                    Some((u, us)) => self.vector3(ctx, u, us)?,
                    None => Vec3::ZERO,
                };
                let dir = (target - origin).normalized();
                if up == Vec3::ZERO {
                    up = dir.orthonormal_basis().0;
                }
                // Mitsuba's look-at frame: x to the left of the view, y up, z forward.
                let left = up.normalized().cross(dir).normalized();
                let new_up = dir.cross(left);
                let ok = [dir, left, new_up]
                    .iter()
                    .all(|v| v.x.is_finite() && v.y.is_finite() && v.z.is_finite());
                if !ok {
                    return Err(self.doc.error(
                        &loc,
                        "a look-at whose target is its origin, or whose up is along the view",
                    ));
                }
                Transform::frame(origin, left, new_up, dir).ok_or_else(|| singular("look-at"))?
            }
            "matrix" => {
                self.check_attributes(ctx, node, &attrs, &[], &["value"])?;
                let (v, span) = attrs.get("value").unwrap();
                let t = self.numbers(ctx, v, span.clone())?;
                let n = match t.len() {
                    16 => 4,
                    9 => 3,
                    k => {
                        return Err(self.doc.error(
                            &self.loc(ctx.file, span),
                            format!("expected 9 or 16 numbers, found {k}"),
                        ))
                    }
                };
                let mut m = Matrix4::IDENTITY;
                for i in 0..n {
                    for j in 0..n {
                        m.0[i][j] = t[i * n + j];
                    }
                }
                Transform::from_matrix(m).ok_or_else(|| {
                    self.doc.error(
                        &self.loc(ctx.file, span),
                        "the matrix is singular, or its last row is not 0 0 0 1",
                    )
                })?
            }
            other => {
                let e = self.doc.error(&loc, format!("unknown transform <{other}>"));
                return Err(
                    match did_you_mean(other, ["translate", "rotate", "scale", "lookat", "matrix"])
                    {
                        Some(s) => e.with_help(format!("did you mean <{s}>?")),
                        None => e.with_help("expected translate, rotate, scale, lookat or matrix"),
                    },
                );
            }
        };
        Ok(t.matrix)
    }
}

struct FileContext {
    file: usize,
    /// Written for Mitsuba 0.x (version below 2): camelCase names.
    old: bool,
}

/// The span of an element's start tag name, for messages.
fn tag_span(node: roxmltree::Node) -> Range<usize> {
    let start = node.range().start;
    start..start + 1 + node.tag_name().name().len()
}

/// Mitsuba's tokenizer: values separated by commas and white space.
fn tokens(s: &str) -> impl Iterator<Item = &str> {
    s.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
}

fn parse_number(s: &str) -> Option<f64> {
    s.trim().parse::<f64>().ok().filter(|x| x.is_finite())
}

fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Mitsuba's upgrade of version-0.x names: `intIOR` → `int_ior`, `maxDepth` → `max_depth`.
fn camel_to_snake(s: &str) -> String {
    let chars: Vec<char> = s.chars().collect();
    let mut out = String::with_capacity(s.len() + 4);
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if i > 0 && chars[i - 1].is_ascii_lowercase() && c.is_ascii_uppercase() {
            out.push('_');
            out.push(c.to_ascii_lowercase());
            while i + 1 < chars.len() && chars[i + 1].is_ascii_uppercase() {
                i += 1;
                out.push(chars[i].to_ascii_lowercase());
            }
        } else {
            out.push(c);
        }
        i += 1;
    }
    out
}

/// The byte offset of 1-based (row, column in characters) in `text`.
fn byte_offset(text: &str, row: usize, col: usize) -> usize {
    let mut offset = 0;
    for (i, line) in text.split_inclusive('\n').enumerate() {
        if i + 1 == row {
            return offset
                + line
                    .char_indices()
                    .nth(col.saturating_sub(1))
                    .map_or(line.len(), |(b, _)| b);
        }
        offset += line.len();
    }
    text.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camel_case_names_are_upgraded_as_mitsuba_does() {
        assert_eq!(camel_to_snake("intIOR"), "int_ior");
        assert_eq!(camel_to_snake("maxDepth"), "max_depth");
        assert_eq!(camel_to_snake("diffuseReflectance"), "diffuse_reflectance");
        assert_eq!(camel_to_snake("alpha"), "alpha");
    }

    #[test]
    fn offsets_count_characters_within_the_row() {
        let t = "ab\nçd e\n";
        assert_eq!(byte_offset(t, 1, 1), 0);
        assert_eq!(byte_offset(t, 2, 1), 3);
        assert_eq!(&t[byte_offset(t, 2, 3)..byte_offset(t, 2, 3) + 1], " ");
    }
}
