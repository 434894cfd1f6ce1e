//! `plenum bench`: an acceleration structure measured on exactly the rays another
//! intersector traces (../shared/bench): build time and memory, then closest-hit and any-hit
//! throughput, the median of several passes after a warm-up. With `--baseline`, a second
//! structure is measured in the same process, its passes taking turns with the first's, and
//! the two compared pass by pass and hit by hit.

use clap::Args;
use plenum_core::accel::{AccelKind, Coherence, SahCost};
use plenum_core::geometry::TriangleMesh;
use plenum_core::math::{Bounds3, Ray, Vec3};
use plenum_core::scene::Scene;
use plenum_scene::ray_files::{read_rays, write_hits, FileHit, FileRay};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

#[derive(Args)]
pub struct BenchArgs {
    /// The geometry: a mesh (.obj, .ply), or any scene file, whose primitives are used.
    #[arg(long)]
    mesh: PathBuf,
    /// A rays file (PLRAYS1, see ../shared/bench/README.md).
    #[arg(long)]
    rays: PathBuf,
    /// Acceleration structure: bvh, grid, octree or none; embree (Intel Embree 3, for
    /// reference) when built with `--features embree`.
    #[arg(long, default_value = "bvh")]
    accel: BenchAccel,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Write the closest hits here (PLHITS1), to compare ray by ray with another intersector.
    #[arg(long)]
    hits_out: Option<PathBuf>,
    /// Timed passes per query, after one warm-up pass.
    #[arg(long, default_value_t = 5)]
    passes: usize,
    /// A second structure to measure in turn with `--accel`, pass for pass, reporting the
    /// ratio of their speeds in each pair of passes: a machine whose speed drifts between
    /// runs of a few seconds then slows both alike.
    #[arg(long)]
    baseline: Option<BenchAccel>,
    /// Whether the rays follow one another (camera rays) or not, a hint to the any-hit
    /// walk that changes its speed, never its hits: coherent, incoherent, or auto (found
    /// from the rays: see `RaysCoherence::of`). Embree is given the same hint.
    #[arg(long, default_value = "auto")]
    coherence: CoherenceArg,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

/// What `--coherence` names.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum CoherenceArg {
    Auto,
    Coherent,
    Incoherent,
}

/// Whether a file's rays are coherent, and the share of them that follow the ray before.
struct RaysCoherence {
    coherence: Coherence,
    /// Of consecutive rays, the share within [`NEIGHBOUR_DEGREES`] of each other's direction
    /// and [`NEIGHBOUR_SPREAD`] of the origins' spread of each other's origin.
    neighbours: f64,
    /// Whether `--coherence` said so rather than the rays.
    forced: bool,
}

/// Consecutive rays closer than this in direction, in degrees, may be neighbours: some 25
/// pixels apart in a 1024-pixel image 40° across.
const NEIGHBOUR_DEGREES: f64 = 1.0;
/// ... and closer than this share of the diagonal of the box around all origins.
const NEIGHBOUR_SPREAD: f64 = 0.01;

impl RaysCoherence {
    /// Found from the rays: coherent where at least half of them are neighbours of the ray
    /// before (camera rays from one point in scanline order: all but a row's first; rays
    /// made at random: next to none).
    fn of(rays: &[FileRay], arg: CoherenceArg) -> RaysCoherence {
        let origin = |r: &FileRay| Vec3::from_array(r.origin.map(f64::from));
        let direction = |r: &FileRay| Vec3::from_array(r.direction.map(f64::from));
        let near_origin = match rays.len() {
            0 | 1 => 0.0,
            _ => {
                NEIGHBOUR_SPREAD
                    * Bounds3::from_points(rays.iter().map(origin))
                        .diagonal()
                        .length()
            }
        };
        let near_direction = NEIGHBOUR_DEGREES.to_radians().cos();
        let neighbours = rays
            .windows(2)
            .filter(|pair| {
                let (a, b) = (&pair[0], &pair[1]);
                (origin(a) - origin(b)).length() <= near_origin
                    && direction(a).dot(direction(b)) >= near_direction
            })
            .count() as f64
            / rays.len().saturating_sub(1).max(1) as f64;
        let (coherence, forced) = match arg {
            CoherenceArg::Auto if neighbours >= 0.5 => (Coherence::Coherent, false),
            CoherenceArg::Auto => (Coherence::Incoherent, false),
            CoherenceArg::Coherent => (Coherence::Coherent, true),
            CoherenceArg::Incoherent => (Coherence::Incoherent, true),
        };
        RaysCoherence {
            coherence,
            neighbours,
            forced,
        }
    }

    fn name(&self) -> &'static str {
        match self.coherence {
            Coherence::Coherent => "coherent",
            Coherence::Incoherent => "incoherent",
        }
    }
}

/// What `--accel` names: one of Plenum's structures, or Embree.
#[derive(Clone, Copy, Debug)]
pub enum BenchAccel {
    Plenum(AccelKind),
    Embree,
}

impl std::str::FromStr for BenchAccel {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "embree" if cfg!(feature = "embree") => Ok(BenchAccel::Embree),
            "embree" => Err(
                "this plenum was built without Embree: build it with `--features embree` \
                 (after `apt-get install libembree-dev`)"
                    .into(),
            ),
            _ => s.parse().map(BenchAccel::Plenum),
        }
    }
}

impl BenchAccel {
    fn name(self) -> &'static str {
        match self {
            BenchAccel::Plenum(kind) => kind.name(),
            BenchAccel::Embree => "embree",
        }
    }
}

/// What is traced: a mesh's triangles (hits name triangles) or a scene (hits name primitives).
enum Target {
    Mesh(Box<TriangleMesh>),
    Scene(Box<Scene>),
    #[cfg(feature = "embree")]
    Embree(Box<crate::embree::EmbreeMesh>),
}

impl Target {
    fn closest(&self, ray: &Ray, t_max: f64) -> Option<(f64, u32)> {
        match self {
            // Hits name triangles as the mesh file does.
            Target::Mesh(m) => m
                .intersect(ray, t_max)
                .map(|h| (h.t, m.source_triangle(h.part))),
            Target::Scene(s) => s.geometry.intersect(ray, t_max).map(|(p, h)| (h.t, p)),
            #[cfg(feature = "embree")]
            Target::Embree(e) => e.closest(ray, t_max),
        }
    }

    fn occluded(&self, ray: &Ray, t_max: f64, coherence: Coherence) -> bool {
        match self {
            Target::Mesh(m) => m.intersect_any_as(ray, t_max, coherence).is_some(),
            Target::Scene(s) => s.geometry.occluded(ray, t_max, coherence),
            #[cfg(feature = "embree")]
            Target::Embree(e) => e.occluded(ray, t_max, coherence),
        }
    }

    fn primitive_count(&self) -> usize {
        match self {
            Target::Mesh(m) => m.triangle_count(),
            Target::Scene(s) => s.geometry.primitives.len(),
            #[cfg(feature = "embree")]
            Target::Embree(e) => e.triangle_count(),
        }
    }

    /// The tree's cost per ray, where the structure is a BVH of Plenum's.
    fn sah_cost(&self) -> Option<SahCost> {
        match self {
            Target::Mesh(m) => m.sah_cost(),
            _ => None,
        }
    }

    fn memory_bytes(&self) -> usize {
        match self {
            Target::Mesh(m) => m.memory_bytes(),
            Target::Scene(s) => s.geometry.accel_memory_bytes(),
            // Embree does not say.
            #[cfg(feature = "embree")]
            Target::Embree(_) => 0,
        }
    }
}

/// A file ray as Plenum traces it: the interval [t_min, t_max] becomes (0, t_max − t_min]
/// from the point at t_min, since Plenum's rays start where they are valid. Plenum's
/// queries leave out their far end, so they are given the next f64 above it (a hit exactly
/// at t_max counts, as the format and Embree have it).
struct Prepared {
    ray: Ray,
    t_min: f64,
    t_max: f64,
}

fn prepare(r: &FileRay) -> Prepared {
    let o = Vec3::new(r.origin[0] as f64, r.origin[1] as f64, r.origin[2] as f64);
    let d = Vec3::new(
        r.direction[0] as f64,
        r.direction[1] as f64,
        r.direction[2] as f64,
    );
    let t_min = (r.t_min as f64).max(0.0);
    Prepared {
        ray: Ray::new(o + d * t_min, d),
        t_min,
        t_max: (r.t_max as f64 - t_min).next_up(),
    }
}

pub fn run(args: BenchArgs) -> ExitCode {
    let pool = match rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
    {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: cannot start the worker threads: {e}");
            return ExitCode::from(1);
        }
    };
    if args.passes == 0 {
        eprintln!("error: --passes must be at least 1");
        return ExitCode::from(2);
    }
    let file_rays = match read_rays(&args.rays) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let build = |accel: BenchAccel| {
        pool.install(|| build_target(accel, &args.mesh))
            .unwrap_or_else(|e: plenum_scene::SceneError| {
                eprintln!("{e}");
                std::process::exit(2)
            })
    };
    let (target, build_seconds) = build(args.accel);
    let baseline = args.baseline.map(|accel| (accel, build(accel)));
    let rays: Vec<Prepared> = file_rays.iter().map(prepare).collect();
    let coherence = RaysCoherence::of(&file_rays, args.coherence);
    let threads = pool.current_num_threads();
    let closest_pass =
        |target: &Target, hits: &mut [FileHit]| pool.install(|| trace_closest(target, &rays, hits));
    let any_pass =
        |target: &Target| pool.install(|| count_occluded(target, &rays, coherence.coherence));

    let mut hits = vec![FileHit::MISS; rays.len()];
    let mut occluded = 0;
    let mut base_hits = Vec::new();
    let mut base_occluded = 0;
    let (times, base_times) = match &baseline {
        None => (
            Times {
                closest: timed_passes(args.passes, || closest_pass(&target, &mut hits)),
                any: timed_passes(args.passes, || occluded = any_pass(&target)),
            },
            None,
        ),
        Some((_, (base, _))) => {
            base_hits.resize(rays.len(), FileHit::MISS);
            let (closest, base_closest) = timed_in_turn(
                args.passes,
                || closest_pass(&target, &mut hits),
                || closest_pass(base, &mut base_hits),
            );
            let (any, base_any) = timed_in_turn(
                args.passes,
                || occluded = any_pass(&target),
                || base_occluded = any_pass(base),
            );
            let base_times = Times {
                closest: base_closest,
                any: base_any,
            };
            (Times { closest, any }, Some(base_times))
        }
    };
    let geometry = args.mesh.display().to_string();
    let measured = Measured {
        accel: args.accel,
        target: &target,
        build_seconds,
        times,
        hits: &hits,
        occluded,
    };
    let against = baseline
        .as_ref()
        .zip(base_times)
        .map(|((accel, (base, seconds)), times)| {
            let base = Measured {
                accel: *accel,
                target: base,
                build_seconds: *seconds,
                times,
                hits: &base_hits,
                occluded: base_occluded,
            };
            Against {
                closest: Spread::of_ratios(&base.times.closest, &measured.times.closest),
                any: Spread::of_ratios(&base.times.any, &measured.times.any),
                agreeing_hits: agreeing_hits(&hits, &base_hits),
                baseline: base.report(&geometry, threads),
            }
        });
    let output = Output {
        report: measured.report(&geometry, threads),
        coherence,
        against,
    };

    if let Some(path) = &args.hits_out {
        if let Err(e) = write_hits(path, &hits) {
            eprintln!("error: cannot write {}: {e}", path.display());
            return ExitCode::from(1);
        }
    }
    if args.json {
        println!("{}", output.json());
    } else {
        output.print(&args.rays, args.passes);
    }
    ExitCode::SUCCESS
}

/// Loads the geometry and builds `accel` over it: the structure, and the build's seconds
/// (the build alone, not the loading).
fn build_target(accel: BenchAccel, path: &Path) -> Result<(Target, f64), plenum_scene::SceneError> {
    let is_mesh = matches!(extension(path).as_str(), "obj" | "ply");
    let kind = match accel {
        BenchAccel::Plenum(kind) => kind,
        BenchAccel::Embree => return embree_target(path, is_mesh),
    };
    if is_mesh {
        let mut mesh = plenum_scene::load_mesh(path)?;
        let start = Instant::now();
        mesh.set_accel(kind);
        Ok((Target::Mesh(Box::new(mesh)), start.elapsed().as_secs_f64()))
    } else {
        // Read with no structures, so that the time is the build of `kind` ones alone.
        let scene = plenum_scene::load_scene_with(path, AccelKind::None)?.scene;
        let start = Instant::now();
        let scene = scene.with_accel(kind);
        Ok((
            Target::Scene(Box::new(scene)),
            start.elapsed().as_secs_f64(),
        ))
    }
}

/// Every ray's closest hit, into `hits`, in chunks across the pool's threads.
fn trace_closest(target: &Target, rays: &[Prepared], hits: &mut [FileHit]) {
    hits.par_chunks_mut(1024)
        .zip(rays.par_chunks(1024))
        .for_each(|(out, rays)| {
            for (h, r) in out.iter_mut().zip(rays) {
                *h = match target.closest(&r.ray, r.t_max) {
                    Some((t, prim)) => FileHit {
                        t: (t + r.t_min) as f32,
                        prim,
                    },
                    None => FileHit::MISS,
                };
            }
        })
}

/// How many rays are blocked, by any-hit queries across the pool's threads.
fn count_occluded(target: &Target, rays: &[Prepared], coherence: Coherence) -> usize {
    rays.par_chunks(1024)
        .map(|rays| {
            rays.iter()
                .filter(|r| target.occluded(&r.ray, r.t_max, coherence))
                .count()
        })
        .sum()
}

/// Rays whose closest hits agree: both miss, or both hit the same primitive or at distances
/// within 10⁻⁴ of each other relatively (a ray through a shared edge may report either
/// triangle; ../shared/bench/check_hits.py accepts the same).
fn agreeing_hits(a: &[FileHit], b: &[FileHit]) -> usize {
    a.iter()
        .zip(b)
        .filter(|(a, b)| {
            let (a_hit, b_hit) = (a.prim != u32::MAX, b.prim != u32::MAX);
            a_hit == b_hit
                && (!a_hit
                    || a.prim == b.prim
                    || (a.t - b.t).abs() <= 1e-4 * a.t.abs().max(b.t.abs()))
        })
        .count()
}

/// Embree's structure over a mesh file's triangles, and its build time.
#[cfg(feature = "embree")]
fn embree_target(path: &Path, is_mesh: bool) -> Result<(Target, f64), plenum_scene::SceneError> {
    if !is_mesh {
        eprintln!("error: --accel embree takes a mesh file (.obj or .ply)");
        std::process::exit(2);
    }
    let mesh = plenum_scene::load_mesh(path)?;
    let threads = rayon::current_num_threads();
    let start = Instant::now();
    let embree = crate::embree::EmbreeMesh::build(&mesh, threads).unwrap_or_else(|e| {
        eprintln!("error: {e}");
        std::process::exit(1)
    });
    Ok((
        Target::Embree(Box::new(embree)),
        start.elapsed().as_secs_f64(),
    ))
}

#[cfg(not(feature = "embree"))]
fn embree_target(_: &Path, _: bool) -> Result<(Target, f64), plenum_scene::SceneError> {
    unreachable!("`embree` does not parse without the feature")
}

fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase()
}

/// One structure's build and passes, and what its last passes found.
struct Measured<'a> {
    accel: BenchAccel,
    target: &'a Target,
    build_seconds: f64,
    times: Times,
    hits: &'a [FileHit],
    occluded: usize,
}

impl Measured<'_> {
    fn report(&self, geometry: &str, threads: usize) -> Report {
        let n = self.hits.len().max(1) as f64;
        let prims = self.target.primitive_count();
        let memory = self.target.memory_bytes();
        let (closest, any) = (median(&self.times.closest), median(&self.times.any));
        Report {
            geometry: geometry.to_string(),
            primitives: prims,
            accel: self.accel.name(),
            threads,
            build_ms: self.build_seconds * 1e3,
            build_mprims_per_s: prims as f64 / self.build_seconds.max(1e-12) / 1e6,
            memory_bytes: memory,
            bytes_per_primitive: memory as f64 / prims.max(1) as f64,
            sah_cost: self.target.sah_cost(),
            rays: self.hits.len(),
            closest_mrays_per_s: n / closest.max(1e-12) / 1e6,
            closest_ms: closest * 1e3,
            hit_fraction: self.hits.iter().filter(|h| h.prim != u32::MAX).count() as f64 / n,
            any_mrays_per_s: n / any.max(1e-12) / 1e6,
            any_ms: any * 1e3,
            occluded_fraction: self.occluded as f64 / n,
        }
    }
}

/// The seconds of each timed pass, per query.
struct Times {
    closest: Vec<f64>,
    any: Vec<f64>,
}

/// One warm-up run, then the seconds of each of `passes` runs.
fn timed_passes(passes: usize, mut f: impl FnMut()) -> Vec<f64> {
    f();
    (0..passes).map(|_| seconds(&mut f)).collect()
}

/// `a` and `b` in turn: a warm-up run of each, then `passes` runs of each, which of the two
/// goes first swapped every pass. The seconds of each run, `a`'s and `b`'s.
fn timed_in_turn(passes: usize, mut a: impl FnMut(), mut b: impl FnMut()) -> (Vec<f64>, Vec<f64>) {
    a();
    b();
    (0..passes)
        .map(|pass| {
            if pass % 2 == 0 {
                let ta = seconds(&mut a);
                (ta, seconds(&mut b))
            } else {
                let tb = seconds(&mut b);
                (seconds(&mut a), tb)
            }
        })
        .unzip()
}

fn seconds(f: &mut impl FnMut()) -> f64 {
    let start = Instant::now();
    f();
    start.elapsed().as_secs_f64()
}

fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted[sorted.len() / 2]
}

/// The median, least and greatest of some numbers.
struct Spread {
    median: f64,
    least: f64,
    most: f64,
}

impl Spread {
    /// Of `numerators[i] / denominators[i]`: for times of a baseline over the same pass's
    /// times of the structure measured, how many times as fast the structure was.
    fn of_ratios(numerators: &[f64], denominators: &[f64]) -> Spread {
        let ratios: Vec<f64> = numerators
            .iter()
            .zip(denominators)
            .map(|(n, d)| n / d.max(1e-12))
            .collect();
        Spread {
            median: median(&ratios),
            least: ratios.iter().copied().fold(f64::INFINITY, f64::min),
            most: ratios.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }

    fn json(&self) -> serde_json::Value {
        serde_json::json!({ "median": self.median, "least": self.least, "most": self.most })
    }
}

/// The measured structure against `--baseline`, measured in turn with it.
struct Against {
    /// How many times as fast as the baseline, pass by pass.
    closest: Spread,
    any: Spread,
    /// Rays whose closest hits agree with the baseline's (see [`agreeing_hits`]).
    agreeing_hits: usize,
    baseline: Report,
}

struct Output {
    report: Report,
    coherence: RaysCoherence,
    against: Option<Against>,
}

impl Output {
    fn json(&self) -> String {
        let mut json = self.report.json();
        json["coherence"] = serde_json::json!({
            "hint": self.coherence.name(),
            "neighbours": self.coherence.neighbours,
            "forced": self.coherence.forced,
        });
        if let Some(against) = &self.against {
            json["baseline"] = serde_json::json!({
                "report": against.baseline.json(),
                "closest_speedup": against.closest.json(),
                "any_speedup": against.any.json(),
                "agreeing_hits": against.agreeing_hits,
            });
        }
        json.to_string()
    }

    fn print(&self, rays: &Path, passes: usize) {
        self.report.print(rays, passes);
        let c = &self.coherence;
        println!(
            "any hit walked for {} rays ({}): {:.1} % follow the ray before",
            c.name(),
            if c.forced {
                "--coherence"
            } else {
                "found from the rays"
            },
            100.0 * c.neighbours
        );
        if let Some(against) = &self.against {
            let b = &against.baseline;
            println!();
            println!(
                "baseline {}, its passes in turn with {}'s:",
                b.accel, self.report.accel
            );
            b.print_build();
            b.print_speeds();
            let ratio = |s: &Spread| format!("{:.2}× ({:.2}–{:.2})", s.median, s.least, s.most);
            println!(
                "{} against {}, pass by pass, median (least–most): closest hit {}, any hit {}",
                self.report.accel,
                b.accel,
                ratio(&against.closest),
                ratio(&against.any)
            );
            println!(
                "closest hits agreeing: {} of {} rays",
                against.agreeing_hits, self.report.rays
            );
        }
    }
}

struct Report {
    geometry: String,
    primitives: usize,
    accel: &'static str,
    threads: usize,
    build_ms: f64,
    build_mprims_per_s: f64,
    memory_bytes: usize,
    bytes_per_primitive: f64,
    sah_cost: Option<SahCost>,
    rays: usize,
    closest_mrays_per_s: f64,
    closest_ms: f64,
    hit_fraction: f64,
    any_mrays_per_s: f64,
    any_ms: f64,
    occluded_fraction: f64,
}

impl Report {
    fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "geometry": self.geometry,
            "primitives": self.primitives,
            "accel": self.accel,
            "threads": self.threads,
            "build_ms": self.build_ms,
            "build_mprims_per_s": self.build_mprims_per_s,
            "memory_bytes": self.memory_bytes,
            "bytes_per_primitive": self.bytes_per_primitive,
            "sah_cost": self.sah_cost.map(|c| serde_json::json!({
                "total": c.nodes + c.leaves,
                "nodes": c.nodes,
                "leaf_blocks": c.leaves,
            })),
            "rays": self.rays,
            "closest_mrays_per_s": self.closest_mrays_per_s,
            "closest_ms": self.closest_ms,
            "hit_fraction": self.hit_fraction,
            "any_mrays_per_s": self.any_mrays_per_s,
            "any_ms": self.any_ms,
            "occluded_fraction": self.occluded_fraction,
        })
    }

    fn print(&self, rays: &Path, passes: usize) {
        println!(
            "{}: {} primitives, {} on {} threads",
            self.geometry, self.primitives, self.accel, self.threads
        );
        self.print_build();
        println!(
            "{} rays from {} (median of {passes} passes after a warm-up)",
            self.rays,
            rays.display()
        );
        self.print_speeds();
    }

    fn print_build(&self) {
        let memory = if self.memory_bytes == 0 {
            "memory not reported".to_string()
        } else {
            format!(
                "{:.1} bytes per primitive ({:.1} MB with vertices and indices)",
                self.bytes_per_primitive,
                self.memory_bytes as f64 / 1e6
            )
        };
        println!(
            "build: {:.1} ms ({:.2} Mprims/s); {memory}",
            self.build_ms, self.build_mprims_per_s
        );
        if let Some(c) = self.sah_cost {
            // As Embree's statistics (verbose=2) give it, for comparison.
            println!(
                "tree: SAH cost {:.3} ({:.3} nodes + {:.3} leaf blocks of four per ray)",
                c.nodes + c.leaves,
                c.nodes,
                c.leaves
            );
        }
    }

    fn print_speeds(&self) {
        println!(
            "closest hit: {:.2} Mrays/s ({:.1} ms), {:.1} % hit",
            self.closest_mrays_per_s,
            self.closest_ms,
            self.hit_fraction * 100.0
        );
        println!(
            "any hit:     {:.2} Mrays/s ({:.1} ms), {:.1} % occluded",
            self.any_mrays_per_s,
            self.any_ms,
            self.occluded_fraction * 100.0
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plenum_core::sampling::{uniform_sphere, Rng};

    fn file_ray(origin: Vec3, direction: Vec3) -> FileRay {
        let d = direction.normalized();
        FileRay {
            origin: [origin.x as f32, origin.y as f32, origin.z as f32],
            t_min: 0.0,
            direction: [d.x as f32, d.y as f32, d.z as f32],
            t_max: f32::INFINITY,
        }
    }

    /// Camera rays from one point through a 64 × 64 image 40° across, in scanline order,
    /// follow one another but for each row's first; rays between random points (seed
    /// 0x5EED0C0E) do not; too few rays to tell are incoherent; `--coherence` overrides.
    #[test]
    fn coherence_is_found_from_the_rays() {
        let eye = Vec3::new(0.0, 0.0, 5.0);
        let half = 20f64.to_radians().tan();
        let camera: Vec<FileRay> = (0..64 * 64)
            .map(|i| {
                let (x, y) = ((i % 64) as f64, (i / 64) as f64);
                let u = ((x + 0.5) / 32.0 - 1.0) * half;
                let v = (1.0 - (y + 0.5) / 32.0) * half;
                file_ray(eye, Vec3::new(u, v, -1.0))
            })
            .collect();
        let found = RaysCoherence::of(&camera, CoherenceArg::Auto);
        assert_eq!(found.coherence, Coherence::Coherent);
        assert!(!found.forced);
        let rows_first = 63.0 / (64.0 * 64.0 - 1.0);
        assert!(
            (found.neighbours - (1.0 - rows_first)).abs() < 1e-9,
            "{}",
            found.neighbours
        );

        let mut rng = Rng::new(0x5EED0C0E, 0);
        let mut point = || uniform_sphere([rng.uniform(), rng.uniform()]);
        let random: Vec<FileRay> = (0..4096)
            .map(|_| {
                let (a, b) = (point(), point());
                file_ray(a, b - a)
            })
            .collect();
        let found = RaysCoherence::of(&random, CoherenceArg::Auto);
        assert_eq!(found.coherence, Coherence::Incoherent);
        assert!(found.neighbours < 0.01, "{}", found.neighbours);

        for few in [&camera[..0], &camera[..1]] {
            let found = RaysCoherence::of(few, CoherenceArg::Auto);
            assert_eq!(
                (found.coherence, found.neighbours),
                (Coherence::Incoherent, 0.0)
            );
        }
        let forced = RaysCoherence::of(&random, CoherenceArg::Coherent);
        assert_eq!(
            (forced.coherence, forced.forced),
            (Coherence::Coherent, true)
        );
    }
}
