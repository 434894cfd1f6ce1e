//! `plenum render model.gltf` (or `.glb`): glTF 2.0 scenes. The `gltf` crate reads and
//! validates the JSON (and a GLB's chunks); buffers, accessors and images are read here,
//! each checked against the bytes it points into. The node hierarchy places meshes (a mesh
//! used by several nodes is one mesh, instanced), the first camera and
//! `KHR_lights_punctual` lights; metallic–roughness materials become Plenum's physically
//! based ones (docs/gltf.md). What has no counterpart is warned about, naming where in the
//! file it is (a JSON path such as `materials[2]`).

use crate::diagnostics::SceneError;
use crate::limits::MAX_NESTING;
use crate::RenderDefaults;
use gltf::accessor::{DataType, Dimensions};
use plenum_core::camera::CameraSettings;
use plenum_core::color::Color;
use plenum_core::geometry::{Shape, TriangleMesh};
use plenum_core::integrator::IntegratorKind;
use plenum_core::light::{Attenuation, Light};
use plenum_core::material::{
    CoatedDiffuseMaterial, ConductorMaterial, ConductorSpec, DielectricMaterial, FloatTexture,
    Material, Roughness, SpectralTexture, SpectrumKind, SpectrumValue,
};
use plenum_core::math::{Bounds3, Matrix4, Transform, Vec3};
use plenum_core::scene::{Alpha, Bitangent, Bump, MaterialId, SceneBuilder};
use plenum_core::texture::{ImageTexture, Texture, Wrap};
use plenum_spectrum::Spectrum;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

type Result<T> = std::result::Result<T, SceneError>;

/// Parses a glTF 2.0 file (JSON or binary): the scene, its render defaults, and warnings.
pub fn parse(path: &Path, bytes: &[u8]) -> Result<(SceneBuilder, RenderDefaults, Vec<String>)> {
    let gltf = read(bytes).map_err(|e| located(path, bytes, e))?;
    let base = path.parent().unwrap_or(Path::new("."));
    let mut r = Reader {
        path,
        doc: &gltf.document,
        buffers: Vec::new(),
        builder: SceneBuilder::default(),
        warnings: Vec::new(),
        meshes: HashMap::new(),
        materials: HashMap::new(),
        camera: None,
        bounds: Bounds3::default(),
        lights: 0,
        uv_set: 0,
    };
    r.buffers = r.load_buffers(gltf.blob.as_deref(), base)?;
    if gltf.document.animations().next().is_some() {
        r.warn("animations are not supported: the scene is rendered as it stands");
    }
    if gltf.document.skins().next().is_some() {
        r.warn("skins are not supported: skinned meshes are rendered in their rest pose");
    }
    let scene = match gltf.document.default_scene() {
        Some(s) => Some(s),
        None => gltf.document.scenes().next(),
    };
    match scene {
        Some(scene) => {
            for node in scene.nodes() {
                r.node(node, Matrix4::IDENTITY, 0, base)?;
            }
        }
        None => r.warn("the file has no scene: nothing to render"),
    }
    let mut defaults = RenderDefaults {
        integrator: Some(IntegratorKind::Path),
        sampler: plenum_core::sampling::SamplerKind::Random,
        spp: 16,
        ..RenderDefaults::default()
    };
    r.finish(&mut defaults);
    Ok((r.builder, defaults, r.warnings))
}

/// The `gltf` crate's reading and validation, with one check of its own first: its
/// validation looks up each primitive's POSITION accessor before checking that it exists
/// (gltf-json 1.4.1, `mesh.rs`), and panics where it does not.
fn read(bytes: &[u8]) -> std::result::Result<gltf::Gltf, gltf::Error> {
    use gltf::json::validation::{Error, Validate};
    let gltf = gltf::Gltf::from_slice_without_validation(bytes)?;
    let root = gltf.document.as_json();
    let mut errors = Vec::new();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            for (semantic, index) in &primitive.attributes {
                if index.value() >= root.accessors.len() {
                    let at = gltf::json::Path::new()
                        .field("meshes")
                        .index(m)
                        .field("primitives")
                        .index(p)
                        .field("attributes")
                        .key(&format!("{semantic:?}"));
                    errors.push((at, Error::IndexOutOfBounds));
                }
            }
        }
    }
    if errors.is_empty() {
        root.validate(root, gltf::json::Path::new, &mut |path, error| {
            errors.push((path(), error))
        });
    }
    if errors.is_empty() {
        Ok(gltf)
    } else {
        Err(gltf::Error::Validation(errors))
    }
}

/// A glTF error as a located one: JSON errors at their line and column, validation errors
/// at their JSON path.
fn located(path: &Path, bytes: &[u8], e: gltf::Error) -> SceneError {
    match e {
        gltf::Error::Deserialize(j) if !bytes.starts_with(b"glTF") => {
            let text = String::from_utf8_lossy(bytes);
            let offset = text
                .split_inclusive('\n')
                .take(j.line().saturating_sub(1))
                .map(str::len)
                .sum::<usize>()
                + j.column().saturating_sub(1);
            SceneError::at(
                path,
                &text,
                offset..offset + 1,
                format!("malformed glTF: {j}"),
            )
        }
        gltf::Error::Validation(list) => {
            let all: Vec<String> = list
                .iter()
                .take(5)
                .map(|(p, e)| format!("{}: {e}", p.as_str()))
                .collect();
            SceneError::file(path, format!("invalid glTF: {}", all.join("; ")))
        }
        e => SceneError::file(path, format!("malformed glTF: {e}")),
    }
}

struct Reader<'a> {
    path: &'a Path,
    doc: &'a gltf::Document,
    buffers: Vec<Vec<u8>>,
    builder: SceneBuilder,
    warnings: Vec<String>,
    /// Each (mesh, primitive) read once, for every node that uses it.
    meshes: HashMap<(usize, usize), Option<Arc<TriangleMesh>>>,
    /// Each material added once (None: glTF's default material).
    materials: HashMap<Option<usize>, Surface>,
    camera: Option<(gltf::Camera<'a>, Matrix4)>,
    bounds: Bounds3,
    lights: usize,
    /// The texture coordinate set of the material being read ([`uv_set`]).
    uv_set: u32,
}

/// The texture coordinate set a texture reference reads (`KHR_texture_transform` may
/// override it).
fn info_set(info: &gltf::texture::Info<'_>) -> u32 {
    info.texture_transform()
        .and_then(|t| t.tex_coord())
        .unwrap_or(info.tex_coord())
}

/// [`info_set`] of a normal texture, whose transform the `gltf` crate leaves in its JSON.
fn normal_set(n: &gltf::material::NormalTexture<'_>) -> u32 {
    n.extension_value("KHR_texture_transform")
        .and_then(|t| t.get("texCoord"))
        .and_then(|v| v.as_u64())
        .map_or(n.tex_coord(), |v| v as u32)
}

/// The texture coordinate set a material's meshes carry (Plenum's meshes have one): that of
/// its first texture among base colour, metallic–roughness, normal and emissive; 0 without
/// textures. Its textures reading another set are warned about.
fn uv_set(m: &gltf::Material<'_>) -> u32 {
    let pbr = m.pbr_metallic_roughness();
    pbr.base_color_texture()
        .map(|i| info_set(&i))
        .or_else(|| pbr.metallic_roughness_texture().map(|i| info_set(&i)))
        .or_else(|| m.normal_texture().map(|n| normal_set(&n)))
        .or_else(|| m.emissive_texture().map(|i| info_set(&i)))
        .unwrap_or(0)
}

/// A texture's image decoded, where it came from, and the uv transform its textureInfo gives.
struct Decoded {
    texels: plenum_image::Texels,
    at: String,
    uv_transform: Option<[[f64; 3]; 2]>,
    /// The sampler's wrapping along u and v.
    wrap: [Wrap; 2],
}

/// What a glTF material becomes: Plenum's material, the emission, the cut-out.
#[derive(Clone)]
struct Surface {
    material: MaterialId,
    emission: Color,
    /// The emissive texture (sRGB-decoded) times `emission`, where there is one.
    emission_texture: Option<Texture>,
    alpha: Option<Alpha>,
}

/// The column-major matrix glTF writes as Plenum's row-major one.
fn matrix(m: [[f32; 4]; 4]) -> Matrix4 {
    let mut out = Matrix4::IDENTITY;
    for (c, column) in m.iter().enumerate() {
        for (r, x) in column.iter().enumerate() {
            out.0[r][c] = *x as f64;
        }
    }
    out
}

impl<'a> Reader<'a> {
    fn error(&self, at: &str, message: impl std::fmt::Display) -> SceneError {
        SceneError::file(self.path, format!("{at}: {message}"))
    }

    fn warn(&mut self, message: impl std::fmt::Display) {
        self.warnings
            .push(format!("warning: {}: {message}", self.path.display()));
    }

    fn load_buffers(&self, blob: Option<&[u8]>, base: &Path) -> Result<Vec<Vec<u8>>> {
        let mut out = Vec::new();
        for b in self.doc.buffers() {
            let at = format!("buffers[{}]", b.index());
            let data = match b.source() {
                gltf::buffer::Source::Bin => blob
                    .ok_or_else(|| {
                        self.error(&at, "refers to the GLB's binary chunk, which is missing")
                    })?
                    .to_vec(),
                gltf::buffer::Source::Uri(uri) => self.uri(uri, base, &at)?,
            };
            if data.len() < b.length() {
                return Err(self.error(
                    &at,
                    format!(
                        "holds {} bytes, but its byteLength is {}",
                        data.len(),
                        b.length()
                    ),
                ));
            }
            out.push(data);
        }
        Ok(out)
    }

    /// The bytes a URI names: a `data:` URI's base64, or a file beside the glTF.
    fn uri(&self, uri: &str, base: &Path, at: &str) -> Result<Vec<u8>> {
        if let Some(rest) = uri.strip_prefix("data:") {
            let Some((_, data)) = rest.split_once(";base64,") else {
                return Err(self.error(at, "a data URI that is not base64"));
            };
            return base64(data).ok_or_else(|| self.error(at, "malformed base64 in a data URI"));
        }
        let file = base.join(percent_decode(uri));
        std::fs::read(&file)
            .map_err(|e| self.error(at, format!("cannot read {}: {e}", file.display())))
    }

    /// The bytes of an accessor's elements, checked: (data, offset of the first element,
    /// stride, element size).
    fn accessor_bytes(
        &self,
        a: &gltf::Accessor,
        components: usize,
    ) -> Result<(&[u8], usize, usize)> {
        let at = format!("accessors[{}]", a.index());
        if a.sparse().is_some() {
            return Err(self.error(&at, "sparse accessors are not supported"));
        }
        let Some(view) = a.view() else {
            return Err(self.error(
                &at,
                "an accessor without a bufferView (all zeros) is not supported",
            ));
        };
        let size = a.data_type().size() * components;
        let stride = view.stride().unwrap_or(size);
        if stride < size {
            return Err(self.error(
                &at,
                format!("a byteStride of {stride} for elements of {size} bytes"),
            ));
        }
        let buffer = &self.buffers[view.buffer().index()];
        let view_end = view.offset().checked_add(view.length());
        let Some(data) = view_end.and_then(|end| buffer.get(view.offset()..end)) else {
            return Err(self.error(
                &format!("bufferViews[{}]", view.index()),
                "reaches past the end of its buffer",
            ));
        };
        let need = a
            .count()
            .checked_sub(1)
            .and_then(|n| n.checked_mul(stride))
            .and_then(|n| n.checked_add(size))
            .and_then(|n| n.checked_add(a.offset()));
        match need {
            Some(n) if n <= data.len() => Ok((&data[a.offset()..], stride, size)),
            _ => Err(self.error(
                &at,
                format!(
                    "{} elements do not fit in its bufferView of {} bytes",
                    a.count(),
                    data.len()
                ),
            )),
        }
    }

    /// An accessor of N floats per element (FLOAT, or normalised integers).
    fn floats<const N: usize>(&self, a: &gltf::Accessor, what: &str) -> Result<Vec<[f64; N]>> {
        let at = format!("accessors[{}]", a.index());
        let dims = match a.dimensions() {
            Dimensions::Scalar => 1,
            Dimensions::Vec2 => 2,
            Dimensions::Vec3 => 3,
            Dimensions::Vec4 => 4,
            _ => 0,
        };
        if dims != N {
            return Err(self.error(&at, format!("{what} must have {N} components")));
        }
        let t = a.data_type();
        if t != DataType::F32 && !a.normalized() {
            return Err(self.error(&at, format!("{what} must be floats or normalised integers")));
        }
        let (data, stride, _) = self.accessor_bytes(a, N)?;
        let c = t.size();
        let read = |b: &[u8]| -> f64 {
            match t {
                DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                DataType::U8 => b[0] as f64 / 255.0,
                DataType::I8 => (b[0] as i8 as f64 / 127.0).max(-1.0),
                DataType::U16 => u16::from_le_bytes([b[0], b[1]]) as f64 / 65535.0,
                DataType::I16 => (i16::from_le_bytes([b[0], b[1]]) as f64 / 32767.0).max(-1.0),
                DataType::U32 => {
                    u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64 / u32::MAX as f64
                }
            }
        };
        Ok((0..a.count())
            .map(|i| {
                let e = &data[i * stride..];
                std::array::from_fn(|k| read(&e[k * c..]))
            })
            .collect())
    }

    fn indices(&self, a: &gltf::Accessor) -> Result<Vec<u32>> {
        let at = format!("accessors[{}]", a.index());
        if a.dimensions() != Dimensions::Scalar
            || !matches!(a.data_type(), DataType::U8 | DataType::U16 | DataType::U32)
        {
            return Err(self.error(&at, "indices must be unsigned integer scalars"));
        }
        let (data, stride, _) = self.accessor_bytes(a, 1)?;
        Ok((0..a.count())
            .map(|i| {
                let b = &data[i * stride..];
                match a.data_type() {
                    DataType::U8 => b[0] as u32,
                    DataType::U16 => u16::from_le_bytes([b[0], b[1]]) as u32,
                    _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                }
            })
            .collect())
    }

    /// A primitive's triangles as a mesh (`None`, warned, for points and lines).
    fn mesh(
        &mut self,
        mesh: &gltf::Mesh,
        p: &gltf::Primitive,
    ) -> Result<Option<Arc<TriangleMesh>>> {
        let key = (mesh.index(), p.index());
        if let Some(m) = self.meshes.get(&key) {
            return Ok(m.clone());
        }
        let at = format!("meshes[{}].primitives[{}]", mesh.index(), p.index());
        let mode = p.mode();
        if !matches!(
            mode,
            gltf::mesh::Mode::Triangles
                | gltf::mesh::Mode::TriangleStrip
                | gltf::mesh::Mode::TriangleFan
        ) {
            self.warn(format!("{at}: {mode:?} are not surfaces: skipped"));
            self.meshes.insert(key, None);
            return Ok(None);
        }
        let Some(pos) = p.get(&gltf::Semantic::Positions) else {
            return Err(self.error(&at, "a primitive without POSITION"));
        };
        let positions: Vec<Vec3> = self
            .floats::<3>(&pos, "POSITION")?
            .into_iter()
            .map(|[x, y, z]| Vec3::new(x, y, z))
            .collect();
        let normals: Vec<Vec3> = match p.get(&gltf::Semantic::Normals) {
            Some(n) => self
                .floats::<3>(&n, "NORMAL")?
                .into_iter()
                .map(|[x, y, z]| Vec3::new(x, y, z))
                .collect(),
            None => Vec::new(),
        };
        // glTF's uv origin is the image's top-left, Plenum's its bottom-left. A mesh
        // carries one set of uvs: the one its material's textures read.
        let set = uv_set(&p.material());
        let uvs: Vec<[f64; 2]> = match p.get(&gltf::Semantic::TexCoords(set)) {
            Some(t) => self
                .floats::<2>(&t, &format!("TEXCOORD_{set}"))?
                .into_iter()
                .map(|[u, v]| [u, 1.0 - v])
                .collect(),
            None => Vec::new(),
        };
        // Tangents, for a normal map's frame: read where one uses them.
        let tangents: Vec<[f64; 4]> = match p.get(&gltf::Semantic::Tangents) {
            Some(t) if p.material().normal_texture().is_some() => {
                self.floats::<4>(&t, "TANGENT")?
            }
            _ => Vec::new(),
        };
        let index: Vec<u32> = match p.indices() {
            Some(i) => self.indices(&i)?,
            None => (0..positions.len() as u32).collect(),
        };
        let triangles: Vec<[u32; 3]> = match mode {
            gltf::mesh::Mode::Triangles => {
                index.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
            }
            gltf::mesh::Mode::TriangleStrip => (2..index.len())
                .map(|i| {
                    if i % 2 == 0 {
                        [index[i - 2], index[i - 1], index[i]]
                    } else {
                        [index[i - 1], index[i - 2], index[i]]
                    }
                })
                .collect(),
            _ => (2..index.len())
                .map(|i| [index[0], index[i - 1], index[i]])
                .collect(),
        };
        let mut m = TriangleMesh::new(positions, triangles, normals, uvs)
            .map_err(|e| self.error(&at, e))?;
        if !tangents.is_empty() {
            m = m.with_tangents(tangents).map_err(|e| self.error(&at, e))?;
        }
        let m = Some(Arc::new(m));
        self.meshes.insert(key, m.clone());
        Ok(m)
    }

    /// A texture's image, decoded: colour to linear if `colour`, else (data such as
    /// roughness) as stored; alpha as it is.
    fn texels(
        &mut self,
        info: &gltf::texture::Info<'_>,
        colour: bool,
        base: &Path,
        at: &str,
    ) -> Result<Decoded> {
        let set = info_set(info);
        let uv_map = info
            .texture_transform()
            .map(|t| (t.offset(), t.rotation(), t.scale()));
        self.texels_of(info.texture(), set, uv_map, colour, base, at)
    }

    /// [`Self::texels`] of a normal map, whose reference the `gltf` crate gives without its
    /// `KHR_texture_transform`: read here from the extension's JSON.
    fn normal_texels(
        &mut self,
        n: &gltf::material::NormalTexture<'_>,
        base: &Path,
        at: &str,
    ) -> Result<Decoded> {
        let t = n.extension_value("KHR_texture_transform");
        let pair = |key: &str, default: [f32; 2]| match t
            .and_then(|t| t.get(key))
            .and_then(|v| v.as_array())
        {
            Some(a) if a.len() == 2 => [0, 1].map(|i| a[i].as_f64().unwrap_or(0.0) as f32),
            _ => default,
        };
        let set = normal_set(n);
        let rotation = t.and_then(|t| t.get("rotation")).and_then(|v| v.as_f64());
        let uv_map = t.map(|_| {
            let r = rotation.unwrap_or(0.0) as f32;
            (pair("offset", [0.0, 0.0]), r, pair("scale", [1.0, 1.0]))
        });
        self.texels_of(n.texture(), set, uv_map, false, base, at)
    }

    /// The image of `texture`, looked up by texture coordinates `set` mapped by
    /// `KHR_texture_transform`'s (offset, rotation, scale).
    fn texels_of(
        &mut self,
        texture: gltf::Texture<'_>,
        set: u32,
        uv_map: Option<([f32; 2], f32, [f32; 2])>,
        colour: bool,
        base: &Path,
        at: &str,
    ) -> Result<Decoded> {
        if set != self.uv_set {
            let used = self.uv_set;
            self.warn(format!(
                "{at}: texture coordinates {set} differ from those of the material's first texture, and a mesh carries one set: using TEXCOORD_{used}"
            ));
        }
        let uv_transform = uv_map.map(|([ox, oy], r, [sx, sy])| {
            // KHR_texture_transform: uv′ = offset + R·(scale ∘ uv) in glTF's (u, v), v down,
            // R turning (u, v) by −rotation as (c, s; −s, c) (the spec's own example, the
            // lower-left quadrant for rotation π/2, scale ½, offset (0, 1), fixes the sign).
            let r = r as f64;
            let (s, c) = r.sin_cos();
            let (a, b, c0) = (c * sx as f64, s * sy as f64, ox as f64);
            let (d, e, f) = (-s * sx as f64, c * sy as f64, oy as f64);
            // In Plenum's (u, v), v = 1 − glTF's, and the image is looked up with v up: u′ =
            // a·u + b·(1 − v) + c0, v′ = 1 − (d·u + e·(1 − v) + f).
            [[a, -b, b + c0], [-d, e, 1.0 - e - f]]
        });
        let sampler = texture.sampler();
        let wrap = [sampler.wrap_s(), sampler.wrap_t()].map(|w| match w {
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
            gltf::texture::WrappingMode::ClampToEdge => Wrap::Clamp,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::Mirror,
        });
        let image = texture.source();
        let iat = format!("images[{}]", image.index());
        let decode = match colour {
            true => plenum_image::decode_texture,
            false => plenum_image::decode_data_texture,
        };
        let texels = match image.source() {
            gltf::image::Source::View { view, .. } => {
                let buffer = &self.buffers[view.buffer().index()];
                let bytes = view
                    .offset()
                    .checked_add(view.length())
                    .and_then(|end| buffer.get(view.offset()..end))
                    .ok_or_else(|| {
                        self.error(&iat, "its bufferView reaches past the end of its buffer")
                    })?;
                decode(bytes, &iat)
            }
            gltf::image::Source::Uri { uri, .. } => {
                let bytes = self.uri(uri, base, &iat)?;
                decode(&bytes, uri)
            }
        }
        .map_err(|e| self.error(&iat, e))?;
        Ok(Decoded {
            texels,
            at: iat,
            uv_transform,
            wrap,
        })
    }

    /// An image texture of `d`'s texels mapped by `value` (a texel's index to a colour).
    fn image_texture(&self, d: &Decoded, value: impl Fn(usize) -> Color) -> Result<Texture> {
        Ok(Texture::Image(self.image(d, value)?))
    }

    /// The image of [`Self::image_texture`].
    fn image(&self, d: &Decoded, value: impl Fn(usize) -> Color) -> Result<Arc<ImageTexture>> {
        let colors = (0..d.texels.rgb.len()).map(value).collect();
        let mut image = ImageTexture::new(d.texels.width, d.texels.height, colors, [1.0, 1.0])
            .ok_or_else(|| self.error(&d.at, "the image is empty"))?;
        image = image.with_wrap(d.wrap);
        if let Some(m) = d.uv_transform {
            image = image.with_uv_transform(m);
        }
        Ok(Arc::new(image))
    }

    /// The material's cut-out (none for `OPAQUE`): the base colour's alpha, its factor times
    /// its texture's alpha channel, compared with `alphaCutoff` under `MASK`; under `BLEND`,
    /// a coverage, which the surface has stochastically (blending averaged over samples).
    fn alpha(&self, m: &gltf::Material, base_texels: Option<&Decoded>) -> Result<Option<Alpha>> {
        let cutoff = match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => return Ok(None),
            gltf::material::AlphaMode::Mask => Some(m.alpha_cutoff().unwrap_or(0.5) as f64),
            gltf::material::AlphaMode::Blend => None,
        };
        let factor = m.pbr_metallic_roughness().base_color_factor()[3] as f64;
        let texture = match base_texels {
            Some(d) if d.texels.alpha.is_some() => {
                let alpha = d.texels.alpha.as_deref().unwrap_or_default();
                FloatTexture::Texture(
                    self.image_texture(d, |i| Color::gray(alpha[i] as f64 * factor))?,
                )
            }
            _ => FloatTexture::Constant(factor),
        };
        Ok(Some(Alpha { texture, cutoff }))
    }

    /// A glTF material as Plenum's, and its emitted radiance: a dielectric coat over the base
    /// colour (`coateddiffuse`), a conductor of that colour (pbrt-v4's reflectance form) as
    /// far as it is metallic, glass as far as it transmits.
    fn material(&mut self, m: &gltf::Material, base: &Path) -> Result<Surface> {
        if let Some(done) = self.materials.get(&m.index()) {
            return Ok(done.clone());
        }
        let at = match m.index() {
            Some(i) => format!("materials[{i}]"),
            None => "the default material".to_string(),
        };
        let name = m.name().map(str::to_string).unwrap_or_else(|| at.clone());
        self.uv_set = uv_set(m);
        let pbr = m.pbr_metallic_roughness();
        let [r, g, b, _] = pbr.base_color_factor().map(|x| x as f64);
        let base_texels = match pbr.base_color_texture() {
            Some(info) => {
                Some(self.texels(&info, true, base, &format!("{at}.baseColorTexture"))?)
            }
            None => None,
        };
        let base_color = match &base_texels {
            Some(d) => SpectralTexture::from_texture(
                self.image_texture(d, |i| {
                    let p = d.texels.rgb[i];
                    Color::new(p[0] as f64 * r, p[1] as f64 * g, p[2] as f64 * b)
                })?,
                SpectrumKind::Albedo,
            ),
            None => SpectralTexture::constant(Color::new(r, g, b), SpectrumKind::Albedo),
        };
        let cut_out = self.alpha(m, base_texels.as_ref())?;
        // Roughness in the green channel, metallic in the blue, times their factors.
        let rough_factor = (pbr.roughness_factor() as f64).clamp(0.0, 1.0);
        let metal_factor = (pbr.metallic_factor() as f64).clamp(0.0, 1.0);
        let (alpha, metallic) = match pbr.metallic_roughness_texture() {
            Some(info) => {
                let what = format!("{at}.metallicRoughnessTexture");
                let d = self.texels(&info, false, base, &what)?;
                let texel = |i: usize, c: usize| (d.texels.rgb[i][c] as f64).clamp(0.0, 1.0);
                // α = roughness², per texel.
                let alpha =
                    self.image_texture(&d, |i| Color::gray((texel(i, 1) * rough_factor).powi(2)))?;
                let metallic = match metal_factor {
                    0.0 => FloatTexture::Constant(0.0),
                    _ => FloatTexture::Texture(
                        self.image_texture(&d, |i| Color::gray(texel(i, 2) * metal_factor))?,
                    ),
                };
                (FloatTexture::Texture(alpha), metallic)
            }
            None => (
                FloatTexture::Constant(rough_factor.powi(2)),
                FloatTexture::Constant(metal_factor),
            ),
        };
        let roughness = Roughness {
            u: alpha.clone(),
            v: alpha,
            remap: false,
        };
        let ior = m.ior().map_or(1.5, |x| x as f64);
        if !(ior >= 1.0 && ior.is_finite()) {
            return Err(self.error(&at, format!("an ior of {ior}: expected 1 or more")));
        }
        let eta = SpectrumValue::new(Spectrum::Constant(ior), SpectrumKind::Unbounded);
        let transmission = m.transmission().map_or(0.0, |t| {
            if t.transmission_texture().is_some() {
                self.warnings.push(format!(
                    "warning: {}: {at}: the transmissionTexture is not supported: using its factor",
                    self.path.display()
                ));
            }
            (t.transmission_factor() as f64).clamp(0.0, 1.0)
        });
        // Tangent-space normals, read as stored (not sRGB); `scale` multiplies x and y.
        let bump = match m.normal_texture() {
            Some(n) => {
                let d = self.normal_texels(&n, base, &format!("{at}.normalTexture"))?;
                let rgb = |i: usize| {
                    let t = d.texels.rgb[i];
                    Color::new(t[0] as f64, t[1] as f64, t[2] as f64)
                };
                Some(Bump::NormalMap {
                    image: self.image(&d, rgb)?,
                    scale: n.scale() as f64,
                    bitangent: Bitangent::AlongV,
                })
            }
            None => None,
        };
        // KHR_materials_specular scales the dielectric's reflectance at normal incidence,
        // F0 = ((ior − 1)/(ior + 1))², by the colour factor and the specular factor: the
        // coat gets the ior whose F0 that is (Fresnel's rise toward grazing kept).
        let coat_eta = match m.specular() {
            Some(s) if s.specular_factor() != 1.0 || s.specular_color_factor() != [1.0; 3] => {
                let c = s.specular_color_factor().map(|x| x as f64);
                let colour = (c[0] + c[1] + c[2]) / 3.0;
                if c[0] != c[1] || c[1] != c[2] {
                    self.warn(format!("{at}: a coloured specularColorFactor is not supported: its mean, {colour}, scales the reflectance"));
                }
                if transmission > 0.0 {
                    self.warn(format!(
                        "{at}: KHR_materials_specular on transmission: the glass keeps its ior"
                    ));
                }
                let f0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
                let f0 = (f0 * colour).min(1.0) * (s.specular_factor() as f64).clamp(0.0, 1.0);
                let root = f0.sqrt().min(0.999);
                let coat_ior = (1.0 + root) / (1.0 - root);
                SpectrumValue::new(Spectrum::Constant(coat_ior), SpectrumKind::Unbounded)
            }
            _ => eta.clone(),
        };
        if let Some(s) = m.specular() {
            if s.specular_texture().is_some() || s.specular_color_texture().is_some() {
                self.warn(format!("{at}: specularTexture and specularColorTexture are not supported: their factors are used"));
            }
        }
        if m.volume().is_some() {
            self.warn(format!(
                "{at}: KHR_materials_volume is not supported: the glass is clear"
            ));
        }
        let strength = m.emissive_strength().map_or(1.0, |x| x as f64);
        let [er, eg, eb] = m.emissive_factor().map(|x| x as f64 * strength);
        let emission = Color::new(er, eg, eb);
        // The radiance is the factor (times the strength) times the texture's colour.
        let emission_texture = match m.emissive_texture() {
            Some(info) if !emission.is_black() => {
                let d = self.texels(&info, true, base, &format!("{at}.emissiveTexture"))?;
                Some(self.image_texture(&d, |i| {
                    let t = d.texels.rgb[i];
                    Color::new(t[0] as f64, t[1] as f64, t[2] as f64) * emission
                })?)
            }
            _ => None,
        };

        let coat = Material::CoatedDiffuse(CoatedDiffuseMaterial {
            reflectance: base_color.clone(),
            roughness: roughness.clone(),
            // glTF's layer absorbs nothing between coat and base (pbrt's default 0.01 of
            // an absorbing medium would darken every glTF material by a few per cent).
            thickness: 0.0,
            eta: coat_eta,
            albedo: SpectralTexture::constant(Color::BLACK, SpectrumKind::Albedo),
            g: 0.0,
            max_depth: 10,
            samples: 1,
        });
        let glass = || {
            Material::Dielectric(DielectricMaterial {
                eta: eta.clone(),
                roughness: roughness.clone(),
            })
        };
        let metal = || {
            Material::Conductor(ConductorMaterial {
                spec: ConductorSpec::Reflectance(base_color.clone()),
                roughness: roughness.clone(),
            })
        };
        let add = |b: &mut SceneBuilder, suffix: &str, m: Material| {
            b.add_material(format!("{name}{suffix}"), m)
        };
        let dielectric = match transmission {
            t if t >= 1.0 => glass(),
            t if t > 0.0 => {
                let a = add(&mut self.builder, " (coat)", coat);
                let b = add(&mut self.builder, " (glass)", glass());
                Material::Mix {
                    materials: [a, b],
                    amount: FloatTexture::Constant(t),
                }
            }
            _ => coat,
        };
        let material = match metallic {
            FloatTexture::Constant(x) if x >= 1.0 => metal(),
            FloatTexture::Constant(x) if x <= 0.0 => dielectric,
            amount => {
                let a = add(&mut self.builder, " (dielectric)", dielectric);
                let b = add(&mut self.builder, " (metal)", metal());
                Material::Mix {
                    materials: [a, b],
                    amount,
                }
            }
        };
        let id = self.builder.add_material(name, material);
        if let Some(bump) = bump {
            self.builder.set_bump(id, bump);
        }
        let done = Surface {
            material: id,
            emission,
            emission_texture,
            alpha: cut_out,
        };
        self.materials.insert(m.index(), done.clone());
        Ok(done)
    }

    fn node(
        &mut self,
        node: gltf::Node<'a>,
        parent: Matrix4,
        depth: usize,
        base: &Path,
    ) -> Result<()> {
        let at = format!("nodes[{}]", node.index());
        if depth > MAX_NESTING {
            return Err(self.error(
                &at,
                format!("nodes nested deeper than {MAX_NESTING} (does a node contain itself?)"),
            ));
        }
        let world = parent.mul(&matrix(node.transform().matrix()));
        if !world.0.iter().flatten().all(|x| x.is_finite()) {
            return Err(self.error(&at, "a transform that is not finite"));
        }
        let name = node.name().map_or_else(|| at.clone(), str::to_string);
        if let Some(mesh) = node.mesh() {
            match Transform::from_matrix(world) {
                None => self.warn(format!("{at}: a singular transform: its mesh is skipped")),
                Some(to_world) => {
                    for p in mesh.primitives() {
                        let Some(m) = self.mesh(&mesh, &p)? else {
                            continue;
                        };
                        let Surface {
                            material,
                            emission,
                            emission_texture,
                            alpha,
                        } = self.material(&p.material(), base)?;
                        self.bounds = self
                            .bounds
                            .union(&transformed_bounds(&m.bounds(), &to_world));
                        let pname = if mesh.primitives().len() > 1 {
                            format!("{name}.{}", p.index())
                        } else {
                            name.clone()
                        };
                        if emission.r > 0.0 || emission.g > 0.0 || emission.b > 0.0 {
                            let added = self.builder.add_emissive_object(
                                pname,
                                Shape::Mesh(m),
                                to_world,
                                material,
                                // The texture carries the factor.
                                match emission_texture {
                                    Some(_) => Color::WHITE,
                                    None => emission,
                                },
                                // A single-sided material's back faces are culled: it
                                // emits from its front only.
                                p.material().double_sided(),
                                1,
                            );
                            if let Some(t) = emission_texture.filter(|_| added) {
                                self.builder.set_last_light_texture(t);
                            }
                            self.lights += 1;
                            if alpha.is_some() {
                                self.warn(format!("{at}: an emissive material's alphaMode is not supported: the light is whole"));
                            }
                        } else {
                            self.builder
                                .add_object(pname, Shape::Mesh(m), to_world, material);
                            if let Some(alpha) = alpha {
                                self.builder.set_last_alpha(alpha);
                            }
                        }
                    }
                }
            }
        }
        if let Some(camera) = node.camera() {
            if self.camera.is_none() {
                self.camera = Some((camera, world));
            } else {
                self.warn(format!(
                    "{at}: another camera: Plenum renders the first one met"
                ));
            }
        }
        if let Some(light) = node.light() {
            self.light(&light, world, &at);
        }
        for child in node.children() {
            self.node(child, world, depth + 1, base)?;
        }
        Ok(())
    }

    /// A `KHR_lights_punctual` light, placed by its node: at its origin, shining along −z.
    fn light(&mut self, light: &gltf::khr_lights_punctual::Light, world: Matrix4, at: &str) {
        let t = Transform::from_matrix(world).unwrap_or(Transform::IDENTITY);
        let [r, g, b] = light.color().map(|x| x as f64);
        let intensity = Color::new(r, g, b) * light.intensity().max(0.0) as f64;
        if light.range().is_some() {
            self.warn(format!(
                "{at}: a light's range is not supported: it reaches everywhere"
            ));
        }
        let position = t.point(Vec3::ZERO);
        let direction = t.vector(-Vec3::Z).normalized();
        if !(direction.x.is_finite() && direction.y.is_finite() && direction.z.is_finite()) {
            self.warn(format!(
                "{at}: a light whose transform is degenerate: skipped"
            ));
            return;
        }
        let name = light
            .name()
            .map_or_else(|| format!("{at} light"), str::to_string);
        let l = match light.kind() {
            gltf::khr_lights_punctual::Kind::Point => Light::Point {
                position,
                intensity,
                attenuation: Attenuation::default(),
            },
            gltf::khr_lights_punctual::Kind::Directional => Light::Directional {
                direction,
                intensity,
            },
            gltf::khr_lights_punctual::Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => {
                let outer = (outer_cone_angle as f64).clamp(0.0, std::f64::consts::FRAC_PI_2);
                let inner = (inner_cone_angle as f64).clamp(0.0, outer);
                Light::Spot {
                    position,
                    direction,
                    cos_inner: inner.cos(),
                    cos_outer: outer.cos(),
                    intensity,
                    attenuation: Attenuation::default(),
                }
            }
        };
        self.builder.add_light(name, l);
        self.lights += 1;
    }

    /// The camera (the first met, or one framing the scene) and, without lights, a sky.
    fn finish(&mut self, defaults: &mut RenderDefaults) {
        match self.camera.take() {
            Some((camera, world)) => {
                let t = Transform::from_matrix(world).unwrap_or(Transform::IDENTITY);
                let position = t.point(Vec3::ZERO);
                let forward = t.vector(-Vec3::Z).normalized();
                let up = t.vector(Vec3::Y).normalized();
                let finite = |v: Vec3| v.x.is_finite() && v.y.is_finite() && v.z.is_finite();
                if !(finite(forward) && finite(up) && forward.cross(up).length() > 1e-9) {
                    self.warn(format!("cameras[{}]: its node's transform is degenerate: a camera framing the scene instead", camera.index()));
                    return self.finish(defaults);
                }
                let fov = match camera.projection() {
                    gltf::camera::Projection::Perspective(p) => {
                        if let Some(aspect) = p.aspect_ratio().filter(|a| *a > 0.0 && a.is_finite())
                        {
                            defaults.height = 480;
                            defaults.width =
                                ((480.0 * aspect as f64).round() as u32).clamp(1, 1 << 16);
                        }
                        (p.yfov() as f64).to_degrees().clamp(0.01, 179.0)
                    }
                    gltf::camera::Projection::Orthographic(_) => 40.0,
                };
                // An orthographic camera's view is 2·xmag by 2·ymag, its image as wide.
                let orthographic = match camera.projection() {
                    gltf::camera::Projection::Orthographic(o) => {
                        let (x, y) = (o.xmag().abs() as f64, o.ymag().abs() as f64);
                        if y > 0.0 && x > 0.0 {
                            defaults.height = 480;
                            defaults.width = ((480.0 * x / y).round() as u32).clamp(1, 1 << 16);
                            Some(2.0 * y)
                        } else {
                            self.warn(format!("cameras[{}]: an orthographic camera of zero size: a perspective one of 40° from the same place", camera.index()));
                            None
                        }
                    }
                    _ => None,
                };
                self.builder.camera = CameraSettings {
                    position,
                    look_at: position + forward,
                    up,
                    fov_degrees: fov,
                    orthographic,
                    ..CameraSettings::default()
                };
            }
            None => {
                // Frame the bounding sphere from the front-right, above, as for bare meshes.
                let b = self.bounds;
                let (center, radius) = if b.min.x <= b.max.x {
                    b.bounding_sphere()
                } else {
                    (Vec3::ZERO, 1.0)
                };
                let radius = radius.max(1e-9);
                let fov: f64 = 35.0;
                let direction = Vec3::new(0.6, 0.45, 1.0).normalized();
                let distance = radius / (fov.to_radians() * 0.5).sin() * 1.05;
                self.builder.camera = CameraSettings {
                    position: center + direction * distance,
                    look_at: center,
                    up: Vec3::Y,
                    fov_degrees: fov,
                    ..CameraSettings::default()
                };
            }
        }
        if self.lights == 0 {
            self.warn("no lights: a uniform white sky (radiance 1) lights the scene");
            self.builder.add_light(
                "sky",
                Light::Infinite {
                    radiance: Color::WHITE,
                },
            );
        }
    }
}

/// The world bounds of `b` under `t`: its eight corners transformed.
fn transformed_bounds(b: &Bounds3, t: &Transform) -> Bounds3 {
    let mut out = Bounds3::default();
    for i in 0..8 {
        let c = Vec3::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        );
        out = out.union_point(t.point(c));
    }
    out
}

/// Standard base64 (RFC 4648), padding optional; `None` on any other character.
fn base64(s: &str) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(s.len() * 3 / 4);
    let (mut acc, mut bits) = (0u32, 0);
    for c in s.bytes() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            b'=' => break,
            b' ' | b'\n' | b'\r' | b'\t' => continue,
            _ => return None,
        };
        acc = (acc << 6) | v as u32;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

/// A URI's %XX escapes decoded (file names with spaces are written %20).
fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}
