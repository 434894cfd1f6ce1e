//! Scene files for Plenum: the native TOML format (and the OBJ meshes it references), read
//! with located diagnostics and built into a core [`plenum_core::scene::Scene`].

pub mod diagnostics;
mod gltf;
mod limits;
mod mitsuba;
mod model;
mod mtl;
mod native;
mod nff;
mod obj;
mod pbrt;
mod ply;
mod ray;
pub mod ray_files;
mod reader;
mod text;
mod writer;

pub use writer::to_toml;

pub use diagnostics::SceneError;
use plenum_core::accel::AccelKind;
use plenum_core::scene::Scene;
use std::path::Path;

/// Render settings a scene file may carry; the command line overrides them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderDefaults {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    /// The pixel sampler, and whether sampling is adaptive (`sampler = "adaptive"`).
    pub sampler: plenum_core::sampling::SamplerKind,
    pub adaptive: bool,
    pub filter: plenum_core::sampling::FilterKind,
    /// `None`: the filter's own default radius.
    pub filter_radius: Option<f64>,
    pub max_depth: u32,
    pub min_weight: f64,
    /// Stops of exposure applied before clamping to 8 bits.
    pub exposure: f64,
    /// The integrator the file asks for; `None`: `path` for a scene of physically based
    /// materials only, `whitted` otherwise.
    pub integrator: Option<plenum_core::integrator::IntegratorKind>,
    /// The colour mode the file asks for; `None`: the command line's default.
    pub color: Option<plenum_core::integrator::ColorMode>,
    /// Path tracing: Russian roulette from this many bounces on.
    pub rr_depth: u32,
    pub light_sampler: plenum_core::light_sampler::LightSamplerKind,
    /// NFF's view angle between the outermost rays, for the SPD corner-ray procedure.
    pub nff_angle: Option<f64>,
    /// Photon mapping's and SPPM's settings.
    pub photon: plenum_core::integrator::PhotonConfig,
}

impl Default for RenderDefaults {
    fn default() -> Self {
        RenderDefaults {
            width: 640,
            height: 480,
            spp: 1,
            sampler: plenum_core::sampling::SamplerKind::Grid,
            adaptive: false,
            filter: plenum_core::sampling::FilterKind::Box,
            filter_radius: None,
            max_depth: 5,
            min_weight: 1.0 / 256.0,
            exposure: 0.0,
            integrator: None,
            color: None,
            rr_depth: 5,
            light_sampler: Default::default(),
            nff_angle: None,
            photon: Default::default(),
        }
    }
}

/// A scene and the render settings its file asked for.
pub struct LoadedScene {
    pub scene: Scene,
    pub defaults: RenderDefaults,
    /// Harmless problems read past (unknown fields of imported formats), one line each.
    pub warnings: Vec<String>,
}

/// Reads a mesh file (`.obj` or `.ply`) as one mesh, triangles in file order (polygons
/// fanned from their first vertex), as the shared benchmark files number them; in no
/// structure yet ([`plenum_core::geometry::TriangleMesh::set_accel`] builds one).
pub fn load_mesh(path: &Path) -> Result<plenum_core::geometry::TriangleMesh, SceneError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match extension.as_str() {
        "ply" => ply::load_ply(path),
        "obj" => {
            let (text, _) = text::read_lenient(path)
                .map_err(|e| SceneError::file(path, format!("cannot read the mesh file: {e}")))?;
            let mut model = obj::parse_obj_model(path, &text, false)?;
            Ok(model.groups.remove(0).1)
        }
        _ => Err(SceneError::file(
            path,
            "not a mesh file: expected .obj or .ply".to_string(),
        )),
    }
}

/// The extensions of the scene files Plenum reads, by reader.
pub const SCENE_EXTENSIONS: [&str; 9] = [
    "toml", "nff", "ray", "obj", "ply", "xml", "gltf", "glb", "pbrt",
];

/// Reads a scene file, choosing the format by extension: `.toml` (the native format), `.nff`
/// (Haines' Neutral File Format), `.ray` (the course ray tracer's format), `.obj` and `.ply`
/// (a mesh, framed by a default camera and lights), `.xml` (Mitsuba 3), `.gltf` and `.glb`
/// (glTF 2.0), `.pbrt` (pbrt-v4); any other is refused. Relative paths
/// inside are resolved against the file's folder. The scene's structures are BVHs.
pub fn load_scene(path: &Path) -> Result<LoadedScene, SceneError> {
    load_scene_with(path, AccelKind::Bvh)
}

/// [`load_scene`] with `accel` structures over the primitives and inside every mesh, each
/// built once.
pub fn load_scene_with(path: &Path, accel: AccelKind) -> Result<LoadedScene, SceneError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if !SCENE_EXTENSIONS.contains(&extension.as_str()) {
        let found = if extension.is_empty() {
            "it has no extension".to_string()
        } else {
            format!("`.{extension}` is not one")
        };
        return Err(SceneError::file(
            path,
            format!("not a scene file Plenum reads: {found}; the formats are .toml (native), .nff, .ray, .obj, .ply, .xml (Mitsuba 3), .gltf and .glb (glTF 2.0) and .pbrt (pbrt-v4)"),
        ));
    }
    let bytes = std::fs::read(path)
        .map_err(|e| SceneError::file(path, format!("cannot read the scene file: {e}")))?;
    read_scene_with(path, &extension, bytes, accel)
}

/// [`load_scene`] of a file's bytes already read: `extension` (lower case) chooses the reader,
/// `path` names the file in messages and resolves relative paths inside. The fuzz targets
/// call it.
pub fn read_scene(path: &Path, extension: &str, bytes: Vec<u8>) -> Result<LoadedScene, SceneError> {
    read_scene_with(path, extension, bytes, AccelKind::Bvh)
}

/// [`read_scene`] with `accel` structures, as [`load_scene_with`].
pub fn read_scene_with(
    path: &Path,
    extension: &str,
    bytes: Vec<u8>,
    accel: AccelKind,
) -> Result<LoadedScene, SceneError> {
    let (builder, defaults, mut warnings) = match extension {
        "gltf" | "glb" => gltf::parse(path, &bytes)?,
        // PLY is binary, and OBJ is read leniently by the model's reader.
        "obj" | "ply" => model::model_from_bytes(path, extension, bytes)?,
        _ => {
            let (text, not_utf8) = text::lenient(path, bytes);
            let base = path.parent().unwrap_or(Path::new("."));
            let (builder, defaults, mut warnings) = match extension {
                "nff" => {
                    let (builder, defaults) = nff::parse(path, &text)?;
                    (builder, defaults, Vec::new())
                }
                "pbrt" => pbrt::parse(path, text)?,
                "xml" => mitsuba::parse(path, text)?,
                "ray" => ray::parse(path, &text, base)?,
                _ => native::parse(path, &text, base)?,
            };
            warnings.splice(0..0, not_utf8);
            (builder, defaults, warnings)
        }
    };
    let scene = builder.build_with(accel);
    if scene.emits_nothing() {
        warnings.push(
            SceneError::file(path, "the scene has no light: no light source, no emitting surface, a black background and no ambient light, so the image will be black").as_warning(),
        );
    }
    Ok(LoadedScene {
        scene,
        defaults,
        warnings,
    })
}

/// An MTL material library's bytes, read as an OBJ's `mtllib` is; the number of materials.
/// For the fuzz targets: MTL files are otherwise read only through an OBJ.
pub fn read_material_library(path: &Path, bytes: Vec<u8>) -> Result<usize, SceneError> {
    let (text, _) = text::lenient(path, bytes);
    let base = path.parent().unwrap_or(Path::new("."));
    mtl::parse_mtl(path, &text, base).map(|(materials, _)| materials.len())
}

/// Parses native scene text; `path` names it in messages, `base_dir` resolves relative paths.
pub fn parse_scene(path: &Path, text: &str, base_dir: &Path) -> Result<LoadedScene, SceneError> {
    let (builder, defaults, warnings) = native::parse(path, text, base_dir)?;
    Ok(LoadedScene {
        scene: builder.build(),
        defaults,
        warnings,
    })
}

/// The text of the built-in scene: Whitted's 1980 picture.
pub const BUILTIN_SCENE: &str = include_str!("../../../scenes/whitted.toml");

/// Whitted's 1980 picture: a checkerboard floor, a glass sphere and a mirror sphere under
/// two point lights.
pub fn builtin_scene() -> LoadedScene {
    builtin_scene_with(AccelKind::Bvh)
}

/// [`builtin_scene`] with `accel` structures.
pub fn builtin_scene_with(accel: AccelKind) -> LoadedScene {
    let (builder, defaults, warnings) = native::parse(
        Path::new("<built-in whitted.toml>"),
        BUILTIN_SCENE,
        Path::new("."),
    )
    .expect("the built-in scene is valid");
    LoadedScene {
        scene: builder.build_with(accel),
        defaults,
        warnings,
    }
}
