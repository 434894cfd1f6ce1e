//! The `plenum` command.
//!
//! Exit codes: 0 success; 1 an output file could not be written; 2 bad input (a scene error,
//! a bad argument); 130 interrupted by Ctrl-C, after writing what was rendered.

mod aov;
mod bench;
#[cfg(feature = "embree")]
mod embree;
mod figure;
mod film_file;
mod memory;
mod trace;
mod view;

use clap::{Args, Parser, Subcommand};
use plenum_core::accel::AccelKind;
use plenum_core::integrator::{ColorMode, IntegratorConfig, IntegratorKind, MAX_DEPTH};
use plenum_core::light_sampler::LightSamplerKind;
use plenum_core::raw_film::RawFilm;
use plenum_core::render::{
    new_film, render_film, Adaptive, Crop, RenderControl, RenderSettings, MAX_SUBDIVISION,
};
use plenum_core::sampling::{Filter, FilterKind, PixelSampler, SamplerKind, MAX_SPP};
use plenum_scene::{builtin_scene_with, load_scene_with, LoadedScene};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

#[derive(Parser)]
#[command(
    name = "plenum",
    version,
    about = "Plenum: a ray tracer for learning, teaching and using ray tracing"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to an image (with no scene: Whitted's 1980 picture).
    #[command(args_override_self = true)]
    Render(RenderArgs),
    /// Print the ray tree of one pixel: every ray traced for it and why each branch ended.
    #[command(args_override_self = true)]
    TracePixel(TracePixelArgs),
    /// Measure an acceleration structure on a rays file: build time, memory, Mrays/s.
    Bench(bench::BenchArgs),
    /// Write any scene Plenum reads (.toml, .nff, .ray, .obj, .ply, Mitsuba 3 .xml, glTF .gltf/.glb, pbrt-v4 .pbrt) in the native format.
    Convert(ConvertArgs),
    /// Sum film files (.plf) of one render's sample ranges (`render --samples A..B`) into
    /// its image.
    Merge(MergeArgs),
    /// Serve a page that shows the render as it forms, restarts it with other settings,
    /// and shows the ray tree of a clicked pixel (`--port`, `--bind`; loopback by default).
    View(view::Args),
}

#[derive(Args)]
struct MergeArgs {
    /// The parts: film files of consecutive sample ranges of one scene and settings.
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// The image to write (.png, .exr, .pfm, .hdr), or a film file (.plf) to merge further.
    #[arg(short, long)]
    output: PathBuf,
    /// Exposure in stops, for PNG output (−64 to 64).
    #[arg(long, allow_negative_numbers = true)]
    exposure: Option<f64>,
}

#[derive(Args)]
struct ConvertArgs {
    /// The scene to read.
    input: PathBuf,
    /// The native scene to write (.toml).
    output: PathBuf,
}

/// Settings shared by render and trace-pixel; each overrides the scene file's own.
#[derive(Args, Clone, Default)]
struct ViewArgs {
    /// Image width in pixels.
    #[arg(long, allow_negative_numbers = true, value_parser = whole::<u32>(1, MAX_SIDE))]
    width: Option<u32>,
    /// Image height in pixels.
    #[arg(long, allow_negative_numbers = true, value_parser = whole::<u32>(1, MAX_SIDE))]
    height: Option<u32>,
    /// Samples per pixel (1 to 65536).
    #[arg(long, allow_negative_numbers = true, value_parser = whole::<u32>(1, MAX_SPP as u64))]
    spp: Option<u32>,
    /// Where samples go in a pixel (and on the lens, in time, over lights and glossy lobes):
    /// grid (regular √N×√N), random (N uniform points), jittered (one point in each cell of a
    /// √N×√N grid), cook16 (Cook's 16 correlated regions), sobol (Owen-scrambled Sobol) or
    /// adaptive (Whitted's corner subdivision; with --noise-threshold, sampling until the
    /// error estimate is below it, between --min-spp and --spp).
    /// The scene file's choice, else grid.
    #[arg(long, value_parser = named::<SamplerArg>(|| SAMPLERS.to_vec()))]
    sampler: Option<SamplerArg>,
    /// Reconstruction filter: box, tent, gaussian, mitchell or lanczos (default: the scene
    /// file's choice, else box).
    #[arg(long, value_parser = named::<FilterKind>(|| FilterKind::ALL.map(FilterKind::name).to_vec()))]
    filter: Option<FilterKind>,
    /// Filter radius in pixels (default: 0.5 box, 1 tent, 1.5 gaussian, 2 mitchell, 3 lanczos).
    #[arg(long, allow_negative_numbers = true)]
    filter_radius: Option<f64>,
    /// Adaptive subdivision: split where corner luminances differ by more than this
    /// contrast, (max − min)/(max + min).
    #[arg(long, default_value_t = 0.05, allow_negative_numbers = true)]
    contrast: f64,
    /// Adaptive subdivision: the deepest level (1 to 4; 4 = 16×16 squares per pixel).
    #[arg(long, default_value_t = 3, allow_negative_numbers = true, value_parser = whole::<u32>(1, MAX_SUBDIVISION as u64))]
    adaptive_depth: u32,
    /// Adaptive sampling by variance: stop a pixel when the standard error of its luminance
    /// is below this fraction of its mean (of 0.05 in dark pixels), or at --spp samples
    /// (default: 16 × --min-spp, or the file's spp if larger).
    #[arg(long, allow_negative_numbers = true)]
    noise_threshold: Option<f64>,
    /// Adaptive sampling by variance: samples per pixel before the first check, and per batch.
    #[arg(long, default_value_t = 16, allow_negative_numbers = true, value_parser = whole::<u32>(2, MAX_SPP as u64))]
    min_spp: u32,
    /// Maximum number of reflection/refraction bounces after the camera ray (0: direct light
    /// only; at most 100).
    #[arg(long, allow_negative_numbers = true, value_parser = whole::<u32>(0, MAX_DEPTH as u64))]
    max_depth: Option<u32>,
    /// The rendering method, the lecture's ladder: local (the Phong model from every light,
    /// no shadows), appel (local plus shadow rays), whitted (recursive ray tracing), path (path
    /// tracing), light (light tracing), photon (photon mapping), sppm (stochastic progressive
    /// photon mapping) or bdpt (bidirectional path tracing). Default: the scene file's choice,
    /// else path for a scene of physically based materials only and whitted otherwise.
    #[arg(long, value_parser = named::<IntegratorArg>(|| IntegratorKind::ALL.map(IntegratorKind::name).to_vec()))]
    integrator: Option<IntegratorArg>,
    /// How light is represented: spectral (4 sampled wavelengths per camera sample; the
    /// default) or rgb (three channels, as RGB renderers work).
    #[arg(long, value_parser = named::<ColorArg>(|| vec!["spectral", "rgb"]))]
    color: Option<ColorArg>,
    /// Path tracing: Russian roulette from this many bounces on (default 5).
    #[arg(long, allow_negative_numbers = true, value_parser = whole::<u32>(0, u32::MAX as u64))]
    rr_depth: Option<u32>,
    /// Path tracing: how next-event estimation picks a light: power (in proportion to its
    /// power; the default) or uniform.
    #[arg(long, value_parser = named::<LightSamplerArg>(|| vec!["power", "uniform"]))]
    light_sampler: Option<LightSamplerArg>,
    /// Photon mapping: photon paths traced for the global map (default 200000).
    #[arg(long, allow_negative_numbers = true, value_parser = whole::<u64>(0, u64::MAX))]
    photons: Option<u64>,
    /// Photon mapping: photon paths traced for the caustic map (default 200000; 0: none).
    #[arg(long, allow_negative_numbers = true, value_parser = whole::<u64>(0, u64::MAX))]
    caustic_photons: Option<u64>,
    /// Photon mapping: photons per density estimate, k (default 64).
    #[arg(long, allow_negative_numbers = true, value_parser = whole::<u32>(0, u32::MAX as u64))]
    photon_nearest: Option<u32>,
    /// Photon mapping: the largest gather radius; SPPM: the initial radius, in scene units
    /// (default 0: automatic).
    #[arg(long, allow_negative_numbers = true)]
    photon_radius: Option<f64>,
    /// Photon mapping: final-gather rays per camera sample (default 1).
    #[arg(long, allow_negative_numbers = true, value_parser = whole::<u32>(0, u32::MAX as u64))]
    gather_rays: Option<u32>,
    /// SPPM: photon paths per iteration (default 0: the image's pixel count); the
    /// iterations are --spp.
    #[arg(long, allow_negative_numbers = true, value_parser = whole::<u64>(0, u64::MAX))]
    sppm_photons: Option<u64>,
    /// SPPM: the fraction α of new photons kept as a pixel's radius shrinks (default 2/3).
    #[arg(long, allow_negative_numbers = true)]
    sppm_alpha: Option<f64>,
    /// Random seed (0 to 2^64 − 1).
    #[arg(long, default_value_t = 0, allow_negative_numbers = true, value_parser = whole::<u64>(0, u64::MAX))]
    seed: u64,
    /// The SPD test procedure: one ray through each pixel corner ((W+1)×(H+1) rays), each
    /// pixel the mean of its four corners; an NFF view angle then spans the corner rays.
    #[arg(long)]
    nff_corners: bool,
}

#[derive(Args, Default)]
struct RenderArgs {
    /// Scene file (.toml). Without one, the built-in scene.
    scene: Option<PathBuf>,
    /// Output image; the extension picks the format: .png, .exr, .pfm, .hdr; or .plf, the
    /// raw film (for `plenum merge`).
    #[arg(short, long, default_value = "plenum.png")]
    output: PathBuf,
    /// Also write these views beside the output NAME.EXT, each to NAME.VIEW.EXT
    /// (comma-separated): `rays` (rays traced per pixel, of every kind), `spp` (camera
    /// rays per pixel: the samples adaptive sampling took), `depth` (the deepest bounce of
    /// its camera paths), `cost` (the acceleration structures' node visits, primitive tests
    /// and their sum), `normal`, `albedo` and `position` (what the pixel's camera rays
    /// first meet, the mean over its samples), and `variance` (each pixel's variance of its
    /// value from its own samples, what a z-test of one render against a reference needs;
    /// not for light tracing, BDPT or SPPM, whose pixels are not their own samples' mean,
    /// nor for adaptive subdivision or the SPD corners). A PNG shows a view scaled; PFM
    /// keeps its values; an EXR output holds the views as its layers (VIEW.CHANNEL).
    #[arg(long, value_name = "VIEWS")]
    aov: Option<aov::AovList>,
    /// The count a PNG view of rays, spp, depth or cost shows at full scale (white, or the
    /// cost's top colour), so that several renders' views share one scale. Default: each
    /// view's largest.
    #[arg(long, value_name = "COUNT", allow_negative_numbers = true, value_parser = whole::<u64>(1, u64::MAX))]
    aov_max: Option<u64>,
    /// Save the render's state to this film file (.plf) every --checkpoint-every seconds
    /// and when it is stopped (Ctrl-C, --time-limit); `--resume FILE` continues it. Removed
    /// once the image is written.
    #[arg(long)]
    checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints.
    #[arg(long, default_value_t = 60.0)]
    checkpoint_every: f64,
    /// Continue the render saved in this checkpoint, with its scene and settings (only
    /// --threads, --quiet, --time-limit and --checkpoint-every may be given with it); the
    /// image is the same, to the byte, as that of a render never stopped.
    #[arg(long, conflicts_with = "scene")]
    resume: Option<PathBuf>,
    /// Stop after this many seconds of rendering, writing the image so far and a checkpoint
    /// (--checkpoint, else the output's name with .plf); exit code 3.
    #[arg(long)]
    time_limit: Option<f64>,
    /// Render only pixel samples A to B−1 of every pixel (of --spp), into a film file
    /// (-o NAME.plf) that `plenum merge` sums with the other ranges' into the image.
    #[arg(long)]
    samples: Option<SampleRange>,
    /// Render only a part of the image, each pixel as the whole render makes it, into an
    /// image of the part's size: columns X0 to X1 − 1 and rows Y0 to Y1 − 1 in pixels, or,
    /// written with decimal points, fractions of the width and height as pbrt's
    /// --cropwindow (0.25,0.75,0,0.5). Not for light tracing or BDPT, whose pixels take
    /// light from every pixel's samples, nor adaptive sampling by variance.
    #[arg(long, value_name = "X0,X1,Y0,Y1", allow_negative_numbers = true)]
    crop: Option<CropArg>,
    #[command(flatten)]
    view: ViewArgs,
    /// Worker threads (default, or 0: all cores; at most 1024). The image does not depend
    /// on it.
    #[arg(long, allow_negative_numbers = true, value_parser = whole::<usize>(0, MAX_THREADS as u64))]
    threads: Option<usize>,
    /// Exposure in stops, for PNG output (−64 to 64).
    #[arg(long, allow_negative_numbers = true)]
    exposure: Option<f64>,
    /// Acceleration structure: bvh (default), grid, octree or none (brute force).
    #[arg(long, default_value = "bvh", value_parser = named::<AccelKind>(|| AccelKind::ALL.map(AccelKind::name).to_vec()))]
    accel: AccelKind,
    /// No progress bar and no summary.
    #[arg(short, long)]
    quiet: bool,
    /// Bidirectional path tracing: also write the image of every strategy (s light
    /// vertices, t camera vertices) into this folder, as `s{s}_t{t}` weighted by MIS and
    /// `s{s}_t{t}_unweighted`, in the output's format; they sum to the image.
    #[arg(long)]
    write_strategies: Option<PathBuf>,
}

#[derive(Args)]
struct TracePixelArgs {
    /// Scene file (.toml); `-` for the built-in scene.
    scene: PathBuf,
    /// Pixel column, from the left (0 to width − 1).
    #[arg(allow_negative_numbers = true)]
    x: i64,
    /// Pixel row, from the top (0 to height − 1).
    #[arg(allow_negative_numbers = true)]
    y: i64,
    /// Print JSON instead of an indented tree.
    #[arg(long)]
    json: bool,
    /// Also draw the tree as a figure, to this SVG file: its rays as the camera sees them
    /// and from the side, coloured and labelled by kind, over the objects they pass.
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,
    /// Which of the pixel's samples to trace, counted from 0 (default 0), or `all`: the
    /// tree then holds every sample's rays and the colour is the pixel's. SPPM, adaptive
    /// subdivision and the SPD corners trace the whole pixel.
    #[arg(long)]
    sample: Option<trace::SampleArg>,
    #[command(flatten)]
    view: ViewArgs,
}

/// `--integrator`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct IntegratorArg(IntegratorKind);

impl std::str::FromStr for IntegratorArg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        IntegratorKind::from_name(s)
            .map(IntegratorArg)
            .ok_or_else(|| {
                let names: Vec<&str> = IntegratorKind::ALL.iter().map(|k| k.name()).collect();
                format!(
                    "unknown integrator `{s}`: expected one of {}",
                    names.join(", ")
                )
            })
    }
}

/// `--samples A..B`.
#[derive(Clone, Debug, PartialEq)]
struct SampleRange(std::ops::Range<u32>);

impl std::str::FromStr for SampleRange {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || format!("expected a range of sample indices A..B (A < B), not `{s}`");
        let (a, b) = s.split_once("..").ok_or_else(bad)?;
        let (a, b): (u32, u32) = (
            a.trim().parse().map_err(|_| bad())?,
            b.trim().parse().map_err(|_| bad())?,
        );
        if a >= b {
            return Err(bad());
        }
        Ok(SampleRange(a..b))
    }
}

/// `--crop X0,X1,Y0,Y1`: pixels, or (with a decimal point) fractions of the image.
#[derive(Clone, Copy, Debug, PartialEq)]
enum CropArg {
    Pixels([u32; 4]),
    Fractions([f64; 4]),
}

impl std::str::FromStr for CropArg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || {
            format!("expected X0,X1,Y0,Y1: four whole pixel coordinates (0,64,0,32) or four fractions of the image from 0 to 1 (0.25,0.75,0,0.5), not `{s}`")
        };
        let parts: Vec<&str> = s.split(',').map(str::trim).collect();
        if parts.len() != 4 {
            return Err(bad());
        }
        if s.contains('.') {
            let mut f = [0.0; 4];
            for (v, p) in f.iter_mut().zip(&parts) {
                *v = p.parse().map_err(|_| bad())?;
                if !(0.0..=1.0).contains(v) {
                    return Err(bad());
                }
            }
            Ok(CropArg::Fractions(f))
        } else {
            let mut px = [0; 4];
            for (v, p) in px.iter_mut().zip(&parts) {
                *v = p.parse().map_err(|_| bad())?;
            }
            Ok(CropArg::Pixels(px))
        }
    }
}

impl CropArg {
    /// The pixels of a `width` × `height` image it names; fractions as pbrt-v4 rounds them
    /// (up, at both ends).
    fn pixels(self, width: u32, height: u32) -> Crop {
        let [x0, x1, y0, y1] = match self {
            CropArg::Pixels(p) => p,
            CropArg::Fractions([a, b, c, d]) => {
                let at = |f: f64, n: u32| (f * n as f64).ceil() as u32;
                [at(a, width), at(b, width), at(c, height), at(d, height)]
            }
        };
        Crop { x0, x1, y0, y1 }
    }
}

/// `--light-sampler`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct LightSamplerArg(LightSamplerKind);

impl std::str::FromStr for LightSamplerArg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "power" => Ok(LightSamplerArg(LightSamplerKind::Power)),
            "uniform" => Ok(LightSamplerArg(LightSamplerKind::Uniform)),
            _ => Err(format!(
                "unknown light sampler `{s}`: expected power or uniform"
            )),
        }
    }
}

/// `--color`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct ColorArg(ColorMode);

impl std::str::FromStr for ColorArg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "spectral" => Ok(ColorArg(ColorMode::Spectral)),
            "rgb" => Ok(ColorArg(ColorMode::Rgb)),
            _ => Err(format!(
                "unknown colour mode `{s}`: expected spectral or rgb"
            )),
        }
    }
}

/// `--sampler`: a fixed-count pattern, or adaptive sampling.
#[derive(Clone, Copy, Debug, PartialEq)]
enum SamplerArg {
    Fixed(SamplerKind),
    Adaptive,
}

impl Default for SamplerArg {
    fn default() -> Self {
        SamplerArg::Fixed(SamplerKind::Grid)
    }
}

impl std::str::FromStr for SamplerArg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "adaptive" => Ok(SamplerArg::Adaptive),
            _ => s.parse().map(SamplerArg::Fixed),
        }
    }
}

impl std::fmt::Display for SamplerArg {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            SamplerArg::Fixed(k) => write!(f, "{}", k.name()),
            SamplerArg::Adaptive => write!(f, "adaptive"),
        }
    }
}

/// `--sampler`'s names.
const SAMPLERS: [&str; 6] = ["grid", "random", "jittered", "cook16", "sobol", "adaptive"];

/// A value parser for a name among `names()`: `T`'s own parse, and where it fails, the name
/// that was probably meant, as scene files get.
fn named<T: std::str::FromStr<Err = String>>(
    names: fn() -> Vec<&'static str>,
) -> impl Fn(&str) -> Result<T, String> + Clone + Send + Sync + 'static {
    move |s| {
        s.parse::<T>().map_err(
            |e| match plenum_scene::diagnostics::did_you_mean(s, names()) {
                Some(m) => format!("{e}; did you mean `{m}`?"),
                None => e,
            },
        )
    }
}

/// A value parser for a whole number from `lo` to `hi`, which says so when given anything
/// else (a negative number included).
fn whole<T: TryFrom<u64>>(
    lo: u64,
    hi: u64,
) -> impl Fn(&str) -> Result<T, String> + Clone + Send + Sync + 'static {
    move |s| {
        let range = if hi == u64::MAX {
            format!("a whole number ≥ {lo}")
        } else {
            format!("a whole number from {lo} to {hi}")
        };
        s.trim()
            .parse::<u64>()
            .ok()
            .filter(|n| (lo..=hi).contains(n))
            .and_then(|n| T::try_from(n).ok())
            .ok_or_else(|| format!("expected {range}, not `{s}`"))
    }
}

/// The longest image side `--width` and `--height` take (the image is also held to 2^28
/// pixels).
const MAX_SIDE: u64 = 1 << 20;

static CANCEL: AtomicBool = AtomicBool::new(false);
/// Set with [`CANCEL`] when `--time-limit` stopped the render.
static TIME_UP: AtomicBool = AtomicBool::new(false);

/// The extension of film files: a render's raw state.
const FILM_EXTENSION: &str = "plf";

fn is_film_file(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case(FILM_EXTENSION))
}

/// Most worker threads `--threads` takes: far more than any machine's cores, far fewer than
/// would exhaust the system's threads or memory for their stacks.
const MAX_THREADS: usize = 1024;
/// Largest exposure in stops, either way: 2^64 is beyond any image's range.
const MAX_EXPOSURE: f64 = 64.0;

/// Whether `path` can be written, by opening it for writing as the image will be (without
/// truncating it), and removing it again if it did not exist.
fn check_writable(path: &Path) -> Result<(), std::io::Error> {
    let existed = path.exists();
    std::fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(false)
        .open(path)?;
    if !existed {
        let _ = std::fs::remove_file(path);
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    match cli.command.unwrap_or(Command::Render(RenderArgs {
        output: PathBuf::from("plenum.png"),
        ..Default::default()
    })) {
        Command::Render(args) => run_render(args),
        Command::TracePixel(args) => trace::run(args),
        Command::Convert(args) => convert(args),
        Command::Bench(args) => bench::run(args),
        Command::Merge(args) => merge(args),
        Command::View(args) => view::run(args),
    }
}

/// Loads the scene with `accel` structures, or prints its error; `None` means the built-in
/// scene.
fn load(path: Option<&Path>, accel: AccelKind) -> Result<LoadedScene, ExitCode> {
    match path {
        None => Ok(builtin_scene_with(accel)),
        Some(p) if p.as_os_str() == "-" => Ok(builtin_scene_with(accel)),
        Some(p) => {
            let loaded = load_scene_with(p, accel).map_err(|e| {
                eprintln!("{e}");
                ExitCode::from(2)
            })?;
            for w in &loaded.warnings {
                eprintln!("{w}");
            }
            Ok(loaded)
        }
    }
}

fn settings(view: &ViewArgs, loaded: &mut LoadedScene) -> Result<RenderSettings, ExitCode> {
    render_settings(view, loaded).map_err(|e| {
        eprintln!("error: {e}");
        ExitCode::from(2)
    })
}

/// The render's settings: `view`'s, else the scene file's; an error says what is wrong.
/// Warnings go to stderr.
fn render_settings(view: &ViewArgs, loaded: &mut LoadedScene) -> Result<RenderSettings, String> {
    if let (true, Some(angle)) = (view.nff_corners, loaded.defaults.nff_angle) {
        loaded.scene.camera.fov_degrees = angle;
    }
    let d = &loaded.defaults;
    let width = view.width.unwrap_or(d.width);
    let height = view.height.unwrap_or(d.height);
    if width == 0 || height == 0 {
        return Err("the image must be at least 1×1 pixels".into());
    }
    // 2^28 pixels (16384 × 16384) is 3 GiB of film: beyond that, refuse rather than abort.
    if width as u64 * height as u64 > 1 << 28 {
        return Err(format!(
            "{width}×{height} is too large: at most 2^28 pixels (16384×16384)"
        ));
    }
    let spp = view.spp.unwrap_or(d.spp);
    if spp == 0 || spp > MAX_SPP {
        return Err(format!("--spp must be between 1 and {MAX_SPP}"));
    }
    let max_depth = view.max_depth.unwrap_or(d.max_depth);
    if max_depth > MAX_DEPTH {
        return Err(format!("--max-depth must be at most {MAX_DEPTH}"));
    }
    let chosen = view.sampler.unwrap_or(if d.adaptive {
        SamplerArg::Adaptive
    } else {
        SamplerArg::Fixed(d.sampler)
    });
    let kind = match chosen {
        SamplerArg::Fixed(kind) => kind,
        SamplerArg::Adaptive => SamplerKind::Sobol,
    };
    let sampler = PixelSampler::new(kind, spp);
    if sampler.samples_per_pixel() != spp {
        eprintln!(
            "warning: the {} sampler takes {}; using {} samples instead of {spp}",
            chosen,
            if kind == SamplerKind::Cook16 {
                "multiples of 16"
            } else {
                "square sample counts"
            },
            sampler.samples_per_pixel()
        );
    }
    let filter_kind = view.filter.unwrap_or(d.filter);
    let radius = match (view.filter, view.filter_radius, d.filter_radius) {
        (_, Some(r), _) => r,
        // The file's radius goes with the file's filter.
        (None, None, Some(r)) => r,
        _ => filter_kind.default_radius(),
    };
    let filter = Filter::new(filter_kind, radius).map_err(|e| format!("--filter-radius: {e}"))?;
    let adaptive = match (chosen, view.noise_threshold) {
        (SamplerArg::Fixed(_), Some(_)) => {
            return Err("--noise-threshold needs --sampler adaptive".into());
        }
        (SamplerArg::Fixed(_), None) => None,
        (SamplerArg::Adaptive, Some(threshold)) => {
            if !(threshold > 0.0 && threshold.is_finite()) {
                return Err("--noise-threshold must be a positive number".into());
            }
            // The budget is --spp; without one, at least 16 batches whatever the file says.
            let max_spp = match view.spp {
                Some(n) => n,
                None => spp.max(16 * view.min_spp).min(MAX_SPP),
            };
            if view.min_spp < 2 || view.min_spp > max_spp {
                return Err(format!("--min-spp must be between 2 and --spp ({max_spp})"));
            }
            Some(Adaptive::Variance {
                threshold,
                min_spp: view.min_spp,
                max_spp,
            })
        }
        (SamplerArg::Adaptive, None) => {
            if !(1..=MAX_SUBDIVISION).contains(&view.adaptive_depth) {
                return Err(format!(
                    "--adaptive-depth must be between 1 and {MAX_SUBDIVISION}"
                ));
            }
            if !(view.contrast >= 0.0 && view.contrast.is_finite()) {
                return Err("--contrast must be a number ≥ 0".into());
            }
            Some(Adaptive::Subdivide {
                contrast: view.contrast,
                depth: view.adaptive_depth,
            })
        }
    };
    let method = view
        .integrator
        .map(|a| a.0)
        .or(d.integrator)
        .unwrap_or_else(|| IntegratorKind::default_for(&loaded.scene));
    if loaded.scene.camera.orthographic.is_some()
        && matches!(method, IntegratorKind::Light | IntegratorKind::Bdpt)
    {
        return Err(format!("integrator `{}` cannot render through an orthographic camera: its rays' one direction is a delta that no light path meets (as in pbrt-v4); use path, photon or sppm", method.name()));
    }
    let ignored = options_ignored_by(view, method);
    if !ignored.is_empty() {
        eprintln!(
            "warning: integrator `{}` does not read {}: ignored",
            method.name(),
            ignored.join(", ")
        );
    }
    let color = view.color.map(|a| a.0).or(d.color).unwrap_or_default();
    let light_sampler = view.light_sampler.map_or(d.light_sampler, |a| a.0);
    loaded.scene.set_light_sampler(light_sampler);
    if !method.is_classic() && color == ColorMode::Rgb {
        if let Some(what) = loaded.scene.materials.needs_wavelengths() {
            eprintln!("warning: {what} needs wavelengths: in RGB mode it is rendered at 589.3 nm (use --color spectral)");
        }
    }
    let mut photon = d.photon;
    photon.photons = view.photons.unwrap_or(photon.photons);
    photon.caustic_photons = view.caustic_photons.unwrap_or(photon.caustic_photons);
    photon.nearest = view.photon_nearest.unwrap_or(photon.nearest);
    photon.radius = view.photon_radius.unwrap_or(photon.radius);
    photon.gather_rays = view.gather_rays.unwrap_or(photon.gather_rays);
    photon.sppm_photons = view.sppm_photons.unwrap_or(photon.sppm_photons);
    photon.alpha = view.sppm_alpha.unwrap_or(photon.alpha);
    if let Err((key, e)) = photon.check_field() {
        return Err(format!("--{}: {e}", key.replace('_', "-")));
    }
    let settings = RenderSettings {
        width,
        height,
        sampler,
        filter,
        adaptive,
        integrator: IntegratorConfig {
            kind: method,
            max_depth,
            min_weight: d.min_weight,
            rr_depth: view.rr_depth.unwrap_or(d.rr_depth),
            color,
            strategies: false,
            photon,
        },
        seed: view.seed,
        corners: view.nff_corners,
        crop: None,
        pixel_rays: false,
    };
    if let Err(e) = settings.check() {
        return Err(e.to_string());
    }
    Ok(settings)
}

/// The options given on the command line that `method` does not read: each integrator
/// reads its own (photon counts only photon mapping, SPPM's only SPPM; Russian roulette,
/// light selection and wavelengths only the physically based methods; depth not local
/// illumination or Appel's method, which do not recurse).
fn options_ignored_by(view: &ViewArgs, method: IntegratorKind) -> Vec<&'static str> {
    use IntegratorKind::{Appel, Local, Photon, Sppm};
    let classic = method.is_classic();
    let given = [
        (view.photons.is_some(), "--photons", method != Photon),
        (
            view.caustic_photons.is_some(),
            "--caustic-photons",
            method != Photon,
        ),
        (
            view.photon_nearest.is_some(),
            "--photon-nearest",
            method != Photon,
        ),
        (
            view.gather_rays.is_some(),
            "--gather-rays",
            method != Photon,
        ),
        (
            view.photon_radius.is_some(),
            "--photon-radius",
            !matches!(method, Photon | Sppm),
        ),
        (
            view.sppm_photons.is_some(),
            "--sppm-photons",
            method != Sppm,
        ),
        (view.sppm_alpha.is_some(), "--sppm-alpha", method != Sppm),
        (view.rr_depth.is_some(), "--rr-depth", classic),
        (view.light_sampler.is_some(), "--light-sampler", classic),
        (
            view.color == Some(ColorArg(ColorMode::Spectral)),
            "--color spectral (Whitted's model is RGB)",
            classic,
        ),
        (
            view.max_depth.is_some(),
            "--max-depth",
            matches!(method, Local | Appel),
        ),
    ];
    given
        .into_iter()
        .filter(|&(given, _, ignored)| given && ignored)
        .map(|(_, name, _)| name)
        .collect()
}

/// Rays by kind, the kinds the method traced (camera, shadow, reflection and refraction
/// always; light, connection and photon rays where there were any).
fn ray_summary(c: &plenum_core::integrator::RayCounts) -> String {
    let mut parts = vec![
        format!("{} camera", c.camera),
        format!("{} shadow", c.shadow),
        format!("{} reflection", c.reflection),
        format!("{} refraction", c.refraction),
    ];
    for (n, kind) in [
        (c.light, "light"),
        (c.connection, "connection"),
        (c.photon, "photon"),
    ] {
        if n > 0 {
            parts.push(format!("{n} {kind}"));
        }
    }
    parts.join(", ")
}

fn convert(args: ConvertArgs) -> ExitCode {
    let extension = args.output.extension().and_then(|e| e.to_str());
    if !extension.is_some_and(|e| e.eq_ignore_ascii_case("toml")) {
        eprintln!(
            "error: convert writes the native scene format, TOML: name the output .toml, not {}",
            args.output.display()
        );
        return ExitCode::from(2);
    }
    let loaded = match load(Some(&args.input), AccelKind::None) {
        Ok(l) => l,
        Err(code) => return code,
    };
    let text = plenum_scene::to_toml(&loaded.scene, &loaded.defaults);
    if let Err(e) = std::fs::write(&args.output, text) {
        eprintln!("error: cannot write {}: {e}", args.output.display());
        return ExitCode::from(1);
    }
    ExitCode::SUCCESS
}

/// The options `--resume` may be given with: how to run, not what to render.
const RESUME_OPTIONS: [&str; 5] = [
    "--threads",
    "--quiet",
    "-q",
    "--time-limit",
    "--checkpoint-every",
];

/// This process's arguments after `render`, less the options `drop` with their values
/// (`--name value` or `--name=value`).
fn render_args_without(drop: &[&str]) -> Vec<String> {
    let mut out = Vec::new();
    let mut args = std::env::args()
        .skip(1)
        .skip_while(|a| a != "render")
        .skip(1);
    while let Some(a) = args.next() {
        if drop.contains(&a.as_str()) {
            args.next();
        } else if !drop.iter().any(|d| a.starts_with(&format!("{d}="))) {
            out.push(a);
        }
    }
    out
}

/// The arguments of the render a checkpoint continues: those it was started with (paths
/// made absolute from the folder it was started in), then those given now.
fn resumed_args(stored: &[String], cwd: &Path) -> Result<RenderArgs, String> {
    let given = render_args_without(&["--resume"]);
    for a in &given {
        let name = a.split('=').next().unwrap_or("");
        if name.starts_with('-') && !RESUME_OPTIONS.contains(&name) {
            return Err(format!("`{a}` cannot be given with --resume: the render goes on with the scene and settings it was started with; only {} may change", RESUME_OPTIONS.join(", ")));
        }
    }
    let argv = ["plenum", "render"]
        .into_iter()
        .map(String::from)
        .chain(stored.iter().cloned())
        .chain(given);
    let mut args = match Cli::try_parse_from(argv) {
        Ok(Cli {
            command: Some(Command::Render(a)),
        }) => a,
        Ok(_) => return Err("the checkpoint's command line is not a render".to_string()),
        Err(e) => return Err(format!("the checkpoint's command line: {e}")),
    };
    let absolute = |p: &mut PathBuf| {
        if p.is_relative() && p.as_os_str() != "-" {
            *p = cwd.join(&*p);
        }
    };
    args.scene.as_mut().map(absolute);
    absolute(&mut args.output);
    args.checkpoint.as_mut().map(absolute);
    args.write_strategies.as_mut().map(absolute);
    Ok(args)
}

/// The arguments after `render` as given, less those that belong to this run only, and the
/// checkpoint's path where it was chosen for the user: what `--resume` starts from.
fn arguments_to_resume(checkpoint: &Path, given: bool) -> Vec<String> {
    let mut out = render_args_without(&["--time-limit", "--resume"]);
    if !given {
        out.push("--checkpoint".to_string());
        out.push(checkpoint.to_string_lossy().into_owned());
    }
    out
}

/// FNV-1a of the scene as read, in the native format (which holds every mesh's vertices),
/// and of its file: a checkpoint goes on only with the scene it was made of.
fn scene_hash(loaded: &LoadedScene, path: Option<&Path>) -> u64 {
    let mut h = film_file::Fnv::new();
    h.update(plenum_scene::to_toml(&loaded.scene, &loaded.defaults).as_bytes());
    if let Some(bytes) = path.and_then(|p| std::fs::read(p).ok()) {
        h.update(&bytes);
    }
    h.value()
}

fn run_render(mut args: RenderArgs) -> ExitCode {
    // --resume: the render's own arguments, and the film it had got to.
    let mut resumed = None;
    if let Some(path) = args.resume.take() {
        let (film, provenance) = match film_file::read(&path) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::from(2);
            }
        };
        args = match resumed_args(&provenance.args, &provenance.cwd) {
            Ok(a) => a,
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::from(2);
            }
        };
        resumed = Some((path, film, provenance));
    }
    let load_start = Instant::now();
    let mut loaded = match load(args.scene.as_deref(), args.accel) {
        Ok(l) => l,
        Err(code) => return code,
    };
    for what in loaded.scene.geometry.capped_structures() {
        eprintln!(
            "warning: the {} over {what} reached its memory bound (items that overlap many cells); it is kept coarser there, and slower",
            args.accel
        );
    }
    let load_seconds = load_start.elapsed().as_secs_f64();
    let mut settings = match settings(&args.view, &mut loaded) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let refuse = |e: String| {
        eprintln!("error: {e}");
        ExitCode::from(2)
    };
    if let Some(crop) = args.crop {
        settings.crop = Some(crop.pixels(settings.width, settings.height));
        if let Err(e) = settings.check() {
            return refuse(format!("--crop: {e}"));
        }
    }
    if let Some(dir) = &args.write_strategies {
        if settings.integrator.kind != IntegratorKind::Bdpt {
            return refuse("--write-strategies needs --integrator bdpt".to_string());
        }
        settings.integrator.strategies = true;
        if let Err(e) = settings.check() {
            return refuse(e);
        }
        if let Err(e) = std::fs::create_dir_all(dir) {
            eprintln!("error: cannot make {}: {e}", dir.display());
            return ExitCode::from(1);
        }
    }
    let film_output = is_film_file(&args.output);
    if !film_output {
        if let Err(e) = plenum_image::OutputFormat::from_path(&args.output) {
            return refuse(format!("{e} (or .{FILM_EXTENSION}, the raw film)"));
        }
    }
    // Found now, not after the whole render.
    if let Err(e) = check_writable(&args.output) {
        return refuse(format!("cannot write {}: {e}", args.output.display()));
    }
    let exposure = args.exposure.unwrap_or(loaded.defaults.exposure);
    if exposure.is_nan() || exposure.abs() > MAX_EXPOSURE {
        return refuse(format!("--exposure must be a number of stops between -{MAX_EXPOSURE} and {MAX_EXPOSURE}, not {exposure}"));
    }
    let exposure = exposure as f32;

    // Checkpoints, time limit, sample ranges and film output keep the raw film.
    let spp = settings.sampler.samples_per_pixel();
    if let Some(SampleRange(r)) = &args.samples {
        if r.end > spp {
            return refuse(format!(
                "--samples {}..{} reaches beyond the {spp} samples per pixel",
                r.start, r.end
            ));
        }
        if settings.adaptive.is_some() || settings.corners {
            return refuse("--samples needs a fixed number of samples per pixel: adaptive sampling and the SPD corners decide per pixel, and cannot be split".to_string());
        }
        if !film_output {
            return refuse(format!("--samples renders a part of the image for `plenum merge`: name the output .{FILM_EXTENSION}, its raw film"));
        }
    }
    if !(args.checkpoint_every > 0.0 && args.checkpoint_every.is_finite()) {
        return refuse("--checkpoint-every must be a positive number of seconds".to_string());
    }
    if let Some(t) = args.time_limit {
        if !(t > 0.0 && t.is_finite()) {
            return refuse("--time-limit must be a positive number of seconds".to_string());
        }
    }
    let checkpoint = args.checkpoint.clone().or_else(|| {
        args.time_limit
            .map(|_| args.output.with_extension(FILM_EXTENSION))
    });
    let keeps_film = checkpoint.is_some() || args.samples.is_some() || film_output;
    if args.samples.is_some() && settings.integrator.kind == IntegratorKind::Sppm {
        return refuse("--samples cannot split integrator `sppm`: each iteration gathers within the radii the iterations before it left, so its iterations cannot be rendered apart (render it whole; --checkpoint keeps it safe)".to_string());
    }
    let views = args.aov.clone().unwrap_or_default();
    if let Err(e) = views.check(&settings, keeps_film, film_output) {
        return refuse(e);
    }
    settings.pixel_rays = views.needs_pixel_rays();
    if args.aov_max.is_some() && !views.needs_pixel_rays() {
        return refuse("--aov-max sets the scale of the views of counts: give it with --aov rays, spp, depth or cost".to_string());
    }
    if keeps_film && settings.integrator.strategies {
        return refuse("--write-strategies cannot be combined with checkpoints, --time-limit, --samples or film output: the strategy images are not kept in the film".to_string());
    }
    if let Some(c) = &checkpoint {
        if !is_film_file(c) {
            return refuse(format!(
                "--checkpoint: name the checkpoint .{FILM_EXTENSION}, not {}",
                c.display()
            ));
        }
        if c == &args.output {
            return refuse("--checkpoint and the output are the same file".to_string());
        }
    }
    let cwd = std::env::current_dir().unwrap_or_default();
    let provenance = film_file::Provenance {
        scene: args.scene.clone(),
        scene_hash: scene_hash(&loaded, args.scene.as_deref()),
        settings: format!("{settings:?}"),
        args: match &resumed {
            Some((_, _, p)) => p.args.clone(),
            None => arguments_to_resume(
                checkpoint.as_deref().unwrap_or(Path::new("")),
                args.checkpoint.is_some(),
            ),
        },
        cwd: match &resumed {
            Some((_, _, p)) => p.cwd.clone(),
            None => cwd,
        },
    };
    let strategy_images = if settings.integrator.strategies {
        let d = settings.integrator.max_depth as usize;
        (d + 2) * (d + 3) / 2
    } else {
        0
    };
    let per_pixel = memory::bytes_per_pixel(
        settings.integrator.kind,
        settings.adaptive.is_some(),
        strategy_images,
    );
    let (image_width, image_height) = settings.image_size();
    if let Err(e) = memory::check(image_width, image_height, per_pixel, memory::available()) {
        return refuse(e);
    }
    let samples = args.samples.as_ref().map_or(0..spp, |r| r.0.clone());
    let mut film = match resumed {
        Some((path, film, old)) => {
            if old.scene_hash != provenance.scene_hash {
                return refuse(format!(
                    "{} was made of another scene: {} has changed since (or its meshes have)",
                    path.display(),
                    args.scene
                        .as_deref()
                        .map_or("the built-in scene".into(), |p| p.display().to_string())
                ));
            }
            if old.settings != provenance.settings {
                return refuse(format!(
                    "{} was made with other settings:\n  then: {}\n  now:  {}",
                    path.display(),
                    old.settings,
                    provenance.settings
                ));
            }
            film
        }
        None => new_film(&settings, samples),
    };

    let threads = args.threads.unwrap_or(0);
    if threads > MAX_THREADS {
        return refuse(format!(
            "--threads must be at most {MAX_THREADS} (0: all cores), not {threads}"
        ));
    }
    let pool = match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
        Ok(p) => p,
        Err(e) => return refuse(format!("cannot start {threads} threads: {e}")),
    };
    // The first Ctrl-C finishes the tiles in flight and writes the image; a second one
    // ends the process at once.
    let _ = ctrlc::set_handler(|| {
        if CANCEL.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
    });
    if let Some(t) = args.time_limit {
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_secs_f64(t));
            TIME_UP.store(true, Ordering::SeqCst);
            CANCEL.store(true, Ordering::SeqCst);
        });
    }

    let show_progress = !args.quiet && std::io::stderr().is_terminal();
    let bar = indicatif::ProgressBar::hidden();
    if show_progress {
        bar.set_draw_target(indicatif::ProgressDrawTarget::stderr());
        bar.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {percent:>3}% {elapsed} (eta {eta})")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
    }
    let save = |film: &RawFilm| -> bool {
        let Some(path) = &checkpoint else { return true };
        match film_file::write(path, film, &provenance) {
            Ok(()) => true,
            Err(e) => {
                eprintln!(
                    "warning: cannot write the checkpoint {}: {e}",
                    path.display()
                );
                false
            }
        }
    };
    let mut periodic = |film: &RawFilm| {
        save(film);
    };
    let start = Instant::now();
    let progress = |done: usize, total: usize| {
        if show_progress {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        }
    };
    let output = pool.install(|| {
        let control = RenderControl {
            cancel: &CANCEL,
            progress: &progress,
            checkpoint: checkpoint.as_ref().map(|_| {
                (
                    Duration::from_secs_f64(args.checkpoint_every),
                    &mut periodic as &mut dyn FnMut(&RawFilm),
                )
            }),
        };
        render_film(&loaded.scene, &settings, &mut film, control)
    });
    let elapsed = start.elapsed().as_secs_f64();
    bar.finish_and_clear();

    let written = if film_output {
        film_file::write(&args.output, &film, &provenance)
            .map_err(|e| format!("cannot write {}: {e}", args.output.display()))
    } else {
        let f = &output.film;
        plenum_image::write_image(&args.output, f.width, f.height, f.pixels(), exposure)
            .map_err(|e| e.to_string())
    };
    if let Err(e) = written {
        eprintln!("error: {e}");
        if !output.complete {
            save(&film);
        }
        return ExitCode::from(1);
    }
    match views.write(
        &args.output,
        &film,
        &output,
        &loaded.scene,
        &settings,
        args.aov_max,
    ) {
        Ok(notes) => {
            if !args.quiet {
                for n in notes {
                    eprintln!("{n}");
                }
            }
        }
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(1);
        }
    }
    if let Some(dir) = &args.write_strategies {
        let ext = args
            .output
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("exr");
        for (s, t, weighted, plain) in &output.strategies {
            for (film, suffix) in [(weighted, ""), (plain, "_unweighted")] {
                let path = dir.join(format!("s{s}_t{t}{suffix}.{ext}"));
                if let Err(e) = plenum_image::write_image(
                    &path,
                    film.width,
                    film.height,
                    film.pixels(),
                    exposure,
                ) {
                    eprintln!("error: {e}");
                    return ExitCode::from(1);
                }
            }
        }
    }
    let film_image = &output.film;
    if !args.quiet {
        let c = &output.counts;
        eprintln!(
            "loaded in {:.3} s; {}×{}, {}, {:.3} s, {} ({}), rays: {}; {:.2} Mrays/s; {}: {} node visits, {} primitive tests → {}",
            load_seconds,
            film_image.width,
            film_image.height,
            match (settings.adaptive, &args.samples) {
                (None, None) => format!("{} spp", spp),
                (None, Some(SampleRange(r))) =>
                    format!("samples {}..{} of {spp} per pixel", r.start, r.end),
                (Some(_), _) => format!(
                    "{:.2} spp on average (adaptive)",
                    c.camera as f64 / (film_image.width as f64 * film_image.height as f64)
                ),
            },
            elapsed,
            settings.integrator.kind.name(),
            match (
                settings.integrator.kind.is_classic(),
                settings.integrator.color
            ) {
                (false, ColorMode::Spectral) => "spectral",
                _ => "rgb",
            },
            ray_summary(c),
            c.total() as f64 / elapsed / 1e6,
            args.accel,
            c.cost.nodes,
            c.cost.tests,
            args.output.display()
        );
    }
    if output.counts.invalid > 0 {
        eprintln!(
            "warning: {} samples came out NaN or infinite and were left out of the image",
            output.counts.invalid
        );
    }
    if !output.complete {
        let stopped = if TIME_UP.load(Ordering::SeqCst) {
            "the time limit was reached"
        } else {
            "interrupted"
        };
        eprintln!(
            "{stopped}: wrote the part rendered so far to {}",
            args.output.display()
        );
        if let Some(path) = &checkpoint {
            if save(&film) {
                eprintln!(
                    "the render's state is in {}: continue it with `plenum render --resume {}`",
                    path.display(),
                    path.display()
                );
            }
        }
        return ExitCode::from(if TIME_UP.load(Ordering::SeqCst) {
            3
        } else {
            130
        });
    }
    // Done: the image holds everything the checkpoint did.
    if let Some(path) = &checkpoint {
        let _ = std::fs::remove_file(path);
    }
    ExitCode::SUCCESS
}

/// `plenum merge`: the parts' films summed in the order of their sample ranges.
fn merge(args: MergeArgs) -> ExitCode {
    let refuse = |e: String| {
        eprintln!("error: {e}");
        ExitCode::from(2)
    };
    let film_output = is_film_file(&args.output);
    if !film_output {
        if let Err(e) = plenum_image::OutputFormat::from_path(&args.output) {
            return refuse(format!("{e} (or .{FILM_EXTENSION}, the raw film)"));
        }
    }
    let exposure = args.exposure.unwrap_or(0.0);
    if exposure.is_nan() || exposure.abs() > MAX_EXPOSURE {
        return refuse(format!("--exposure must be a number of stops between -{MAX_EXPOSURE} and {MAX_EXPOSURE}, not {exposure}"));
    }
    let mut parts = Vec::new();
    let mut first: Option<(PathBuf, film_file::Provenance)> = None;
    for path in &args.parts {
        let (film, p) = match film_file::read(path) {
            Ok(r) => r,
            Err(e) => return refuse(e),
        };
        if let Some((first_path, f)) = &first {
            if p.scene_hash != f.scene_hash {
                return refuse(format!(
                    "{} and {} were rendered from different scenes",
                    first_path.display(),
                    path.display()
                ));
            }
            if p.settings != f.settings {
                return refuse(format!(
                    "{} and {} were rendered with different settings:\n  {}\n  {}",
                    first_path.display(),
                    path.display(),
                    f.settings,
                    p.settings
                ));
            }
        } else {
            if p.settings.contains("adaptive: Some") {
                return refuse(format!("{} was rendered with adaptive sampling, which decides per pixel how many samples to take: it cannot be split or merged", path.display()));
            }
            first = Some((path.clone(), p));
        }
        parts.push(film);
    }
    let Some((_, provenance)) = first else {
        return refuse("nothing to merge".to_string());
    };
    let film = match RawFilm::merge(parts) {
        Ok(f) => f,
        Err(e) => return refuse(e),
    };
    if film.samples != (0..film.spp) {
        eprintln!(
            "warning: the parts hold samples {}..{} of the {} per pixel: the image has the noise of {} samples",
            film.samples.start,
            film.samples.end,
            film.spp,
            film.samples.len()
        );
    }
    let written = if film_output {
        film_file::write(&args.output, &film, &provenance)
            .map_err(|e| format!("cannot write {}: {e}", args.output.display()))
    } else {
        let image = film.image();
        plenum_image::write_image(
            &args.output,
            image.width,
            image.height,
            image.pixels(),
            exposure as f32,
        )
        .map_err(|e| e.to_string())
    };
    match written {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(1)
        }
    }
}
