//! `plenum view`: a page in the browser that shows the render as it forms, restarts it with
//! other settings, shows where the work goes (rays, samples, depth and the acceleration
//! structures' cost per pixel), and shows the ray tree of a clicked pixel over the image and
//! in a 3-D view of the scene's outlines (`outline.rs`) that the mouse orbits.
//!
//! One process: the HTTP server answers each connection on a thread of its own, the render
//! runs on a worker thread (its tiles on the render pool), and a watcher re-renders when the
//! scene file changes. The page polls `/api/status` and fetches `/api/image` when a newer
//! image is there. A render of a fixed sample count is done in passes of 1, 1, 2, 4, … samples
//! per pixel, each merged into the film so far, so a whole noisy image comes first and
//! the last is the same, to the byte, as `plenum render`'s; SPPM, adaptive sampling and the
//! SPD corners, which cannot be split so, show their film as it fills.

mod http;
mod outline;

use crate::trace::{trace, tree_json, SampleArg, Traced};
use crate::{named, render_settings, whole, Cli, Command, ViewArgs, MAX_THREADS};
use http::{Request, Response};
use plenum_core::accel::AccelKind;
use plenum_core::camera::Camera;
use plenum_core::integrator::{whole_image, ColorMode, IntegratorKind, RayCounts};
use plenum_core::raw_film::RawFilm;
use plenum_core::render::{new_film, render_film};
use plenum_core::render::{PixelRays, RenderControl, RenderSettings};
use plenum_core::sampling::FilterKind;
use plenum_core::scene::Scene;
use plenum_scene::{builtin_scene_with, load_scene_with};
use serde_json::{json, Value};
use std::net::{IpAddr, TcpListener, TcpStream};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant, SystemTime};

const PAGE: &str = include_str!("page.html");

/// Settings the page may change, by their command-line names.
const SETTINGS: [&str; 10] = [
    "integrator",
    "sampler",
    "spp",
    "max-depth",
    "accel",
    "color",
    "width",
    "height",
    "seed",
    "filter",
];

/// Connections served at once; more wait to be refused rather than exhaust threads.
const MAX_CONNECTIONS: usize = 64;
/// How often the watcher looks at the scene file, and the page sees the film fill.
const WATCH_EVERY: Duration = Duration::from_millis(300);
const SNAPSHOT_EVERY: Duration = Duration::from_millis(250);

#[derive(clap::Args)]
#[command(args_override_self = true)]
pub struct Args {
    /// Scene file (any format `render` reads). Without one, the built-in scene.
    scene: Option<PathBuf>,
    #[command(flatten)]
    view: ViewArgs,
    /// Acceleration structure: bvh (default), grid, octree or none (brute force).
    #[arg(long, default_value = "bvh", value_parser = named::<AccelKind>(|| AccelKind::ALL.map(AccelKind::name).to_vec()))]
    accel: AccelKind,
    /// Worker threads for the render (default, or 0: all cores).
    #[arg(long, allow_negative_numbers = true, value_parser = whole::<usize>(0, MAX_THREADS as u64))]
    threads: Option<usize>,
    /// The port to serve the page on (default 0: a free one, printed at start).
    #[arg(long, default_value_t = 0)]
    port: u16,
    /// The address to serve on. Anything other than loopback lets other machines see the
    /// scene and start renders on this one: give it on purpose only.
    #[arg(long, default_value = "127.0.0.1")]
    bind: IpAddr,
}

/// A render to run: the scene loaded and the settings made from the command line and
/// the page's changes.
struct Job {
    scene: Scene,
    settings: RenderSettings,
    accel: AccelKind,
}

/// An image for the page: linear sRGB, row by row from the top.
struct Snapshot {
    width: u32,
    height: u32,
    rgb: Vec<f32>,
}

#[derive(Default)]
struct State {
    job: Option<Arc<Job>>,
    /// Bumped by every render started, so the page can tell a new one.
    generation: u64,
    image: Option<Arc<Snapshot>>,
    /// Bumped by every image published.
    version: u64,
    /// Each pixel's rays and their cost so far, summed over the passes done (none for
    /// SPPM and the SPD corners, whose rays belong to no one pixel).
    rays: Option<Arc<Vec<PixelRays>>>,
    samples_done: u32,
    /// Tiles of the pass under way: (done, in all).
    tiles: (usize, usize),
    pass_samples: u32,
    counts: RayCounts,
    started: Option<Instant>,
    /// Seconds the last render took, once it is over.
    finished: Option<f64>,
    /// The last error in the scene file (the watcher's) or a failed render, shown on the
    /// page; the last good image stays.
    error: Option<String>,
    /// The page's settings, as command-line options appended to the command line's.
    overrides: Vec<(String, String)>,
}

struct Server {
    /// The command line `plenum view` was started with: the page's settings are parsed
    /// as more of its options, so they are checked and mean exactly what they would there.
    argv: Vec<String>,
    scene_path: Option<PathBuf>,
    state: Mutex<State>,
    /// The render under way: its cancel flag and its thread.
    worker: Mutex<Option<(Arc<AtomicBool>, JoinHandle<()>)>>,
    pool: rayon::ThreadPool,
    connections: AtomicUsize,
}

pub fn run(args: Args) -> ExitCode {
    let threads = match args.threads {
        None | Some(0) => std::thread::available_parallelism().map_or(1, |n| n.get()),
        Some(n) => n,
    };
    let pool = match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: cannot start {threads} render threads: {e}");
            return ExitCode::from(1);
        }
    };
    let server = Arc::new(Server {
        argv: std::env::args().collect(),
        scene_path: args.scene.clone(),
        state: Mutex::new(State::default()),
        worker: Mutex::new(None),
        pool,
        connections: AtomicUsize::new(0),
    });
    // A scene that does not load is reported as `render` reports it, before serving.
    let job = match server.prepare(&[]) {
        Ok(job) => job,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::from(2);
        }
    };
    let listener = match TcpListener::bind((args.bind, args.port)) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("error: cannot serve on {}:{}: {e}", args.bind, args.port);
            return ExitCode::from(1);
        }
    };
    if !args.bind.is_loopback() {
        eprintln!(
            "warning: serving on {} beyond this machine: anyone who can reach it sees the scene and can start renders",
            args.bind
        );
    }
    let address = match listener.local_addr() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(1);
        }
    };
    println!("Plenum's view: http://{address}/");
    use std::io::Write as _;
    let _ = std::io::stdout().flush();
    server.start(job);
    if let Some(path) = server.scene_path.clone() {
        let s = server.clone();
        std::thread::spawn(move || s.watch(path));
    }
    for stream in listener.incoming() {
        let Ok(stream) = stream else { continue };
        if server.connections.fetch_add(1, Ordering::SeqCst) >= MAX_CONNECTIONS {
            server.connections.fetch_sub(1, Ordering::SeqCst);
            let _ = http::read_request(&stream);
            http::write_response(&stream, &Response::error(503, "too many connections"));
            continue;
        }
        let s = server.clone();
        std::thread::spawn(move || {
            s.serve(&stream);
            s.connections.fetch_sub(1, Ordering::SeqCst);
        });
    }
    ExitCode::SUCCESS
}

impl Server {
    fn state(&self) -> MutexGuard<'_, State> {
        // A panicked request thread leaves the state as consistent as any other.
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Loads the scene and makes the settings of the command line with `overrides`
    /// appended; the error as `render` would print it.
    fn prepare(&self, overrides: &[(String, String)]) -> Result<Job, String> {
        let mut argv = self.argv.clone();
        argv.extend(overrides.iter().map(|(k, v)| format!("--{k}={v}")));
        let args = match clap::Parser::try_parse_from(&argv) {
            Ok(Cli {
                command: Some(Command::View(args)),
            }) => args,
            Ok(_) => return Err("error: not a view command line".into()),
            Err(e) => {
                // clap's first line names the option and what it expected.
                let text = e.to_string();
                return Err(text.lines().next().unwrap_or("error").to_string());
            }
        };
        let mut loaded = match &args.scene {
            None => builtin_scene_with(args.accel),
            Some(p) => load_scene_with(p, args.accel).map_err(|e| e.to_string())?,
        };
        for w in &loaded.warnings {
            eprintln!("{w}");
        }
        let mut settings =
            render_settings(&args.view, &mut loaded).map_err(|e| format!("error: {e}"))?;
        // The page's views of where the work goes.
        settings.pixel_rays = true;
        Ok(Job {
            scene: loaded.scene,
            settings,
            accel: args.accel,
        })
    }

    /// Stops the render under way (it stops between tiles) and starts `job`'s.
    fn start(self: &Arc<Self>, job: Job) {
        let mut worker = self.worker.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((cancel, handle)) = worker.take() {
            cancel.store(true, Ordering::SeqCst);
            let _ = handle.join();
        }
        let job = Arc::new(job);
        {
            let mut s = self.state();
            s.job = Some(job.clone());
            s.generation += 1;
            s.samples_done = 0;
            s.tiles = (0, 0);
            s.pass_samples = 0;
            s.counts = RayCounts::default();
            s.rays = None;
            s.started = Some(Instant::now());
            s.finished = None;
        }
        let cancel = Arc::new(AtomicBool::new(false));
        let (me, flag) = (self.clone(), cancel.clone());
        let handle = std::thread::spawn(move || me.render(&job, &flag));
        *worker = Some((cancel, handle));
    }

    /// Renders `job` in passes, publishing each image, until done or cancelled.
    fn render(&self, job: &Job, cancel: &AtomicBool) {
        let settings = &job.settings;
        let spp = settings.sampler.samples_per_pixel();
        let splits = whole_image(settings.integrator.kind).is_none()
            && settings.adaptive.is_none()
            && !settings.corners;
        // One pass of all the samples (a `Vec` of one range).
        let passes = if splits {
            passes(spp)
        } else {
            std::iter::once(0..spp).collect()
        };
        let mut sum: Option<RawFilm> = None;
        for range in passes {
            let mut film = new_film(settings, range.clone());
            let first = sum.is_none();
            self.state().pass_samples = range.len() as u32;
            let progress = |done: usize, all: usize| self.state().tiles = (done, all);
            // The first pass shows its tiles as they come; later ones replace the image
            // once merged.
            let mut snapshot = |f: &RawFilm| {
                if first {
                    self.publish(f, 0);
                }
            };
            let out = self.pool.install(|| {
                let control = RenderControl {
                    cancel,
                    progress: &progress,
                    checkpoint: Some((SNAPSHOT_EVERY, &mut snapshot as &mut dyn FnMut(&RawFilm))),
                };
                render_film(&job.scene, settings, &mut film, control)
            });
            {
                let mut s = self.state();
                s.counts.add(&out.counts);
                if out.complete && !out.pixel_rays.is_empty() {
                    let mut rays = s.rays.as_deref().cloned().unwrap_or_default();
                    rays.resize(out.pixel_rays.len(), PixelRays::default());
                    for (sum, r) in rays.iter_mut().zip(&out.pixel_rays) {
                        sum.add(r);
                    }
                    s.rays = Some(Arc::new(rays));
                }
            }
            if !out.complete {
                return;
            }
            let merged = match sum.take() {
                None => film,
                Some(s) => match RawFilm::merge(vec![s, film]) {
                    Ok(m) => m,
                    Err(e) => {
                        let mut s = self.state();
                        s.error = Some(format!("error: {e}"));
                        s.finished = s.started.map(|t| t.elapsed().as_secs_f64());
                        return;
                    }
                },
            };
            self.publish(&merged, range.end);
            sum = Some(merged);
        }
        let mut s = self.state();
        s.finished = s.started.map(|t| t.elapsed().as_secs_f64());
    }

    fn publish(&self, film: &RawFilm, samples_done: u32) {
        let image = film.image();
        let mut rgb = Vec::with_capacity(image.width as usize * image.height as usize * 3);
        for y in 0..image.height {
            for x in 0..image.width {
                let c = image.get(x, y);
                rgb.extend([c.r as f32, c.g as f32, c.b as f32]);
            }
        }
        let mut s = self.state();
        s.image = Some(Arc::new(Snapshot {
            width: image.width,
            height: image.height,
            rgb,
        }));
        s.version += 1;
        s.samples_done = samples_done;
    }

    /// Re-renders whenever the scene file changes; an error in it goes to the page, and
    /// the render and image stay.
    fn watch(self: Arc<Self>, path: PathBuf) {
        let stamp = |p: &PathBuf| {
            std::fs::metadata(p)
                .ok()
                .map(|m| (m.modified().unwrap_or(SystemTime::UNIX_EPOCH), m.len()))
        };
        let mut last = stamp(&path);
        loop {
            std::thread::sleep(WATCH_EVERY);
            let now = stamp(&path);
            if now == last {
                continue;
            }
            last = now;
            let overrides = self.state().overrides.clone();
            match self.prepare(&overrides) {
                Ok(job) => {
                    self.state().error = None;
                    self.start(job);
                }
                Err(e) => self.state().error = Some(e),
            }
        }
    }

    fn serve(self: &Arc<Self>, stream: &TcpStream) {
        let response = match http::read_request(stream) {
            Ok(request) => self.respond(&request),
            Err(e) => Response::error(400, &e),
        };
        http::write_response(stream, &response);
    }

    fn respond(self: &Arc<Self>, r: &Request) -> Response {
        match (r.method.as_str(), r.path.as_str()) {
            ("GET", "/") | ("GET", "/index.html") => Response {
                status: 200,
                content_type: "text/html; charset=utf-8",
                body: PAGE.as_bytes().to_vec(),
                headers: Vec::new(),
            },
            ("GET", "/api/status") => Response::json(200, &self.status()),
            ("GET", "/api/image") => self.image(),
            ("GET", "/api/trace") => self.trace(r),
            ("GET", "/api/figure") => self.figure(r),
            ("GET", "/api/scene") => self.scene(),
            ("GET", "/api/view") => self.view(r),
            ("POST", "/api/render") => self.restart(r),
            (
                _,
                "/" | "/index.html" | "/api/status" | "/api/image" | "/api/trace" | "/api/figure"
                | "/api/scene" | "/api/view" | "/api/render",
            ) => Response::error(405, &format!("{} is not allowed on {}", r.method, r.path)),
            _ => Response::error(404, &format!("nothing at {}", r.path)),
        }
    }

    fn status(&self) -> Value {
        let s = self.state();
        let elapsed = s
            .finished
            .or_else(|| s.started.map(|t| t.elapsed().as_secs_f64()))
            .unwrap_or(0.0);
        let rays = s.counts.total();
        let settings = s.job.as_ref().map(|j| {
            let st = &j.settings;
            json!({
                "integrator": st.integrator.kind.name(),
                "sampler": st.sampler.kind().name(),
                "spp": st.sampler.samples_per_pixel(),
                "max-depth": st.integrator.max_depth,
                "accel": j.accel.name(),
                "color": match st.integrator.color {
                    ColorMode::Rgb => "rgb",
                    ColorMode::Spectral => "spectral",
                },
                "width": st.width,
                "height": st.height,
                "seed": st.seed,
                "filter": st.filter.kind().name(),
            })
        });
        let spp = s
            .job
            .as_ref()
            .map_or(0, |j| j.settings.sampler.samples_per_pixel());
        let pass = if s.tiles.1 > 0 {
            s.pass_samples as f64 * s.tiles.0 as f64 / s.tiles.1 as f64
        } else {
            0.0
        };
        let running = s.finished.is_none() && s.started.is_some();
        json!({
            "scene": self.scene_path.as_ref().map_or("(built-in)".to_string(), |p| p.display().to_string()),
            "generation": s.generation,
            "version": s.version,
            "running": running,
            "samples_done": s.samples_done,
            "spp": spp,
            "progress": if running { ((s.samples_done as f64 + pass) / spp.max(1) as f64).min(1.0) } else { 1.0 },
            "rays": rays,
            "node_visits": s.counts.cost.nodes,
            "primitive_tests": s.counts.cost.tests,
            "mrays_per_s": if elapsed > 0.0 { rays as f64 / elapsed / 1e6 } else { 0.0 },
            "elapsed": elapsed,
            "error": s.error,
            "settings": settings,
            "choices": {
                "integrator": IntegratorKind::ALL.map(|k| k.name()),
                "sampler": crate::SAMPLERS,
                "accel": AccelKind::ALL.map(AccelKind::name),
                "color": ["spectral", "rgb"],
                "filter": FilterKind::ALL.map(|k| k.name()),
            },
        })
    }

    fn image(&self) -> Response {
        let (image, version) = {
            let s = self.state();
            (s.image.clone(), s.version)
        };
        let Some(image) = image else {
            return Response::error(409, "no image yet: the render has just started");
        };
        let mut body = Vec::with_capacity(image.rgb.len() * 4);
        for v in &image.rgb {
            body.extend_from_slice(&v.to_le_bytes());
        }
        Response {
            status: 200,
            content_type: "application/octet-stream",
            body,
            headers: vec![
                ("X-Width", image.width.to_string()),
                ("X-Height", image.height.to_string()),
                ("X-Version", version.to_string()),
            ],
        }
    }

    /// The scene's outlines, camera and lights for the 3-D view ([`outline::scene_json`]).
    fn scene(&self) -> Response {
        let Some(job) = self.state().job.clone() else {
            return Response::error(409, "no render yet");
        };
        let (w, h) = (job.settings.width, job.settings.height);
        Response::json(200, &outline::scene_json(&job.scene, w, h))
    }

    /// A view of where the work goes (`name=rays|spp|depth|cost`), over the passes done:
    /// one little-endian f32 per pixel, row by row, with the image's size and the largest
    /// value in the headers. The cost is node visits plus primitive tests.
    fn view(&self, r: &Request) -> Response {
        const NAMES: [&str; 4] = ["rays", "spp", "depth", "cost"];
        let name = r.get("name").unwrap_or("");
        let value: fn(&PixelRays) -> u64 = match name {
            "rays" => |p| p.total,
            "spp" => |p| p.camera,
            "depth" => |p| p.deepest,
            "cost" => |p| p.cost.nodes + p.cost.tests,
            _ => {
                return Response::error(
                    400,
                    &format!(
                        "unknown view `{name}`: expected name={}",
                        NAMES.join(", name=")
                    ),
                )
            }
        };
        let (job, rays) = {
            let s = self.state();
            (s.job.clone(), s.rays.clone())
        };
        let Some(job) = job else {
            return Response::error(409, "no render yet");
        };
        let kind = job.settings.integrator.kind;
        let Some(rays) = rays else {
            let why = if kind == IntegratorKind::Sppm || job.settings.corners {
                "its rays belong to no one pixel (SPPM's photon passes, the SPD corners)"
            } else {
                "no pass has finished yet"
            };
            return Response::error(409, &format!("no view of the work: {why}"));
        };
        let (w, h) = job.settings.image_size();
        let mut body = Vec::with_capacity(rays.len() * 4);
        let mut most = 0;
        for p in rays.iter() {
            let v = value(p);
            most = most.max(v);
            body.extend_from_slice(&(v as f32).to_le_bytes());
        }
        Response {
            status: 200,
            content_type: "application/octet-stream",
            body,
            headers: vec![
                ("X-Width", w.to_string()),
                ("X-Height", h.to_string()),
                ("X-Max", most.to_string()),
            ],
        }
    }

    /// The ray tree of pixel (x, y) of the render under way (`sample=K`, default 0, or
    /// `all`, as `trace-pixel --sample`), each ray with the segment it draws over the image.
    fn trace(&self, r: &Request) -> Response {
        let (job, traced) = match self.traced(r) {
            Ok(t) => t,
            Err(response) => return response,
        };
        let (w, h) = (job.settings.width, job.settings.height);
        let tree = &traced.tree;
        let mut doc = tree_json(&traced);
        let camera = Camera::new(&job.scene.camera, w, h);
        if let Some(rays) = doc["rays"].as_array_mut() {
            for (ray, node) in rays.iter_mut().zip(&tree.nodes) {
                let (end, _) = crate::figure::ray_end(&job.scene, node);
                ray["end"] = json!([end.x, end.y, end.z]);
                ray["segment"] = match camera.project_segment(node.origin, end) {
                    Some((a, b)) => json!([a, b]),
                    None => Value::Null,
                };
            }
        }
        Response::json(200, &doc)
    }

    /// The ray tree of `/api/trace`'s pixel drawn as `trace-pixel --svg` draws it.
    fn figure(&self, r: &Request) -> Response {
        match self.traced(r) {
            Ok((job, traced)) => Response {
                status: 200,
                content_type: "image/svg+xml",
                body: crate::figure::tree_svg(&job.scene, &job.settings, &traced).into_bytes(),
                headers: Vec::new(),
            },
            Err(response) => response,
        }
    }

    /// The job under way and the tree of the pixel `r` asks for (`x`, `y`, `sample`), or
    /// the error response.
    fn traced(&self, r: &Request) -> Result<(Arc<Job>, Traced), Response> {
        let Some(job) = self.state().job.clone() else {
            return Err(Response::error(409, "no render yet"));
        };
        let (w, h) = (job.settings.width, job.settings.height);
        let coordinate = |key: &str, size: u32| -> Result<u32, String> {
            let v = r.get(key).ok_or_else(|| {
                format!("missing `{key}`: expected {}?x=X&y=Y[&sample=K]", r.path)
            })?;
            v.parse::<u32>().ok().filter(|&n| n < size).ok_or_else(|| {
                format!(
                    "`{key}` must be a whole number from 0 to {}, not `{v}`",
                    size - 1
                )
            })
        };
        let (x, y) = match (coordinate("x", w), coordinate("y", h)) {
            (Ok(x), Ok(y)) => (x, y),
            (Err(e), _) | (_, Err(e)) => return Err(Response::error(400, &e)),
        };
        let sample = match r.get("sample").map(str::parse::<SampleArg>).transpose() {
            Ok(s) => s,
            Err(e) => return Err(Response::error(400, &format!("`sample`: {e}"))),
        };
        match trace(&job.scene, &job.settings, (x, y), sample) {
            Ok(t) => Ok((job, t)),
            Err(e) => Err(Response::error(400, &e)),
        }
    }

    /// Restarts the render with the page's settings (`/api/render?spp=16&integrator=path`).
    fn restart(self: &Arc<Self>, r: &Request) -> Response {
        let mut overrides = self.state().overrides.clone();
        for (k, v) in &r.query {
            if !SETTINGS.contains(&k.as_str()) {
                return Response::error(
                    400,
                    &format!(
                        "unknown setting `{k}`: expected one of {}",
                        SETTINGS.join(", ")
                    ),
                );
            }
            overrides.retain(|(o, _)| o != k);
            overrides.push((k.clone(), v.clone()));
        }
        match self.prepare(&overrides) {
            Ok(job) => {
                {
                    let mut s = self.state();
                    s.overrides = overrides;
                    s.error = None;
                }
                self.start(job);
                Response::json(200, &self.status())
            }
            Err(e) => Response::error(400, &e),
        }
    }
}

/// Sample ranges of passes over `spp` samples: 1, 1, 2, 4, … (each pass as many samples as
/// all before it), the last cut to what is left.
fn passes(spp: u32) -> Vec<std::ops::Range<u32>> {
    let mut out = Vec::new();
    let mut start = 0;
    while start < spp {
        let end = (start + start.max(1)).min(spp);
        out.push(start..end);
        start = end;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passes_double_and_cover_every_sample_once() {
        assert_eq!(passes(1), vec![0..1]);
        assert_eq!(passes(6), vec![0..1, 1..2, 2..4, 4..6]);
        for spp in 1..300 {
            let p = passes(spp);
            assert_eq!(p.first().unwrap().start, 0);
            assert_eq!(p.last().unwrap().end, spp);
            assert!(p.windows(2).all(|w| w[0].end == w[1].start));
        }
    }
}
