//! `plenum bench`: an acceleration structure measured on exactly the rays another
//! intersector traces (../shared/bench): build time and memory, then closest-hit and any-hit
//! throughput, the median of several passes after a warm-up.

use clap::Args;
use plenum_core::accel::AccelKind;
use plenum_core::geometry::TriangleMesh;
use plenum_core::math::{Ray, Vec3};
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
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
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
            Target::Scene(s) => s.intersect(ray, t_max).map(|(p, h)| (h.t, p)),
            #[cfg(feature = "embree")]
            Target::Embree(e) => e.closest(ray, t_max),
        }
    }

    fn occluded(&self, ray: &Ray, t_max: f64) -> bool {
        match self {
            Target::Mesh(m) => m.intersect_any(ray, t_max).is_some(),
            Target::Scene(s) => s.occluded(ray, t_max),
            #[cfg(feature = "embree")]
            Target::Embree(e) => e.occluded(ray, t_max),
        }
    }

    fn primitive_count(&self) -> usize {
        match self {
            Target::Mesh(m) => m.triangle_count(),
            Target::Scene(s) => s.primitives.len(),
            #[cfg(feature = "embree")]
            Target::Embree(e) => e.triangle_count(),
        }
    }

    fn memory_bytes(&self) -> usize {
        match self {
            Target::Mesh(m) => m.memory_bytes(),
            Target::Scene(s) => s.accel_memory_bytes(),
            // Embree does not say.
            #[cfg(feature = "embree")]
            Target::Embree(_) => 0,
        }
    }
}

/// A file ray as Plenum traces it: the interval [t_min, t_max] becomes (0, t_max − t_min)
/// from the point at t_min, since Plenum's rays start where they are valid.
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
        t_max: r.t_max as f64 - t_min,
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
    let is_mesh = matches!(extension(&args.mesh).as_str(), "obj" | "ply");
    // Load, then time the build of the chosen structure alone.
    let (target, build_seconds) = pool
        .install(|| {
            let kind = match args.accel {
                BenchAccel::Plenum(kind) => kind,
                BenchAccel::Embree => return embree_target(&args.mesh, is_mesh),
            };
            if is_mesh {
                let mut mesh = plenum_scene::load_mesh(&args.mesh)?;
                let start = Instant::now();
                mesh.set_accel(kind);
                Ok((Target::Mesh(Box::new(mesh)), start.elapsed().as_secs_f64()))
            } else {
                let scene = plenum_scene::load_scene(&args.mesh)?.scene;
                let start = Instant::now();
                let scene = scene.with_accel(kind);
                Ok((
                    Target::Scene(Box::new(scene)),
                    start.elapsed().as_secs_f64(),
                ))
            }
        })
        .unwrap_or_else(|e: plenum_scene::SceneError| {
            eprintln!("{e}");
            std::process::exit(2)
        });
    let rays: Vec<Prepared> = file_rays.iter().map(prepare).collect();
    let threads = pool.current_num_threads();

    let mut hits = vec![FileHit::MISS; rays.len()];
    let closest_pass = |hits: &mut [FileHit]| {
        pool.install(|| {
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
        })
    };
    let any_pass = || {
        pool.install(|| {
            rays.par_chunks(1024)
                .map(|rays| {
                    rays.iter()
                        .filter(|r| target.occluded(&r.ray, r.t_max))
                        .count()
                })
                .sum::<usize>()
        })
    };
    let closest_seconds = median_time(args.passes, || closest_pass(&mut hits));
    let hit_count = hits.iter().filter(|h| h.prim != u32::MAX).count();
    let mut occluded = 0;
    let any_seconds = median_time(args.passes, || occluded = any_pass());

    if let Some(path) = &args.hits_out {
        if let Err(e) = write_hits(path, &hits) {
            eprintln!("error: cannot write {}: {e}", path.display());
            return ExitCode::from(1);
        }
    }
    let n = rays.len().max(1) as f64;
    let prims = target.primitive_count();
    let memory = target.memory_bytes();
    let report = Report {
        geometry: args.mesh.display().to_string(),
        primitives: prims,
        accel: args.accel.name(),
        threads,
        build_ms: build_seconds * 1e3,
        build_mprims_per_s: prims as f64 / build_seconds.max(1e-12) / 1e6,
        memory_bytes: memory,
        bytes_per_primitive: memory as f64 / prims.max(1) as f64,
        rays: rays.len(),
        closest_mrays_per_s: n / closest_seconds.max(1e-12) / 1e6,
        closest_ms: closest_seconds * 1e3,
        hit_fraction: hit_count as f64 / n,
        any_mrays_per_s: n / any_seconds.max(1e-12) / 1e6,
        any_ms: any_seconds * 1e3,
        occluded_fraction: occluded as f64 / n,
    };
    if args.json {
        println!("{}", report.json());
    } else {
        report.print(&args.rays, args.passes);
    }
    ExitCode::SUCCESS
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

/// One warm-up run, then the median time of `passes` runs.
fn median_time(passes: usize, mut f: impl FnMut()) -> f64 {
    f();
    let mut times: Vec<f64> = (0..passes)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
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
    rays: usize,
    closest_mrays_per_s: f64,
    closest_ms: f64,
    hit_fraction: f64,
    any_mrays_per_s: f64,
    any_ms: f64,
    occluded_fraction: f64,
}

impl Report {
    fn json(&self) -> String {
        serde_json::json!({
            "geometry": self.geometry,
            "primitives": self.primitives,
            "accel": self.accel,
            "threads": self.threads,
            "build_ms": self.build_ms,
            "build_mprims_per_s": self.build_mprims_per_s,
            "memory_bytes": self.memory_bytes,
            "bytes_per_primitive": self.bytes_per_primitive,
            "rays": self.rays,
            "closest_mrays_per_s": self.closest_mrays_per_s,
            "closest_ms": self.closest_ms,
            "hit_fraction": self.hit_fraction,
            "any_mrays_per_s": self.any_mrays_per_s,
            "any_ms": self.any_ms,
            "occluded_fraction": self.occluded_fraction,
        })
        .to_string()
    }

    fn print(&self, rays: &Path, passes: usize) {
        println!(
            "{}: {} primitives, {} on {} threads",
            self.geometry, self.primitives, self.accel, self.threads
        );
        println!(
            "build: {:.1} ms ({:.2} Mprims/s); {:.1} bytes per primitive ({:.1} MB with vertices and indices)",
            self.build_ms,
            self.build_mprims_per_s,
            self.bytes_per_primitive,
            self.memory_bytes as f64 / 1e6
        );
        println!(
            "{} rays from {} (median of {passes} passes after a warm-up)",
            self.rays,
            rays.display()
        );
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
