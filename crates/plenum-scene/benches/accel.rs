//! `cargo bench -p plenum-scene --bench accel`: build and traversal of every acceleration
//! structure on the Stanford bunny (../shared/data), with camera rays and incoherent rays made
//! here (the same kinds as ../shared/bench/make_rays.py). Figures are medians of 5 passes
//! after a warm-up, on all cores; each line also gives the ratio to the BVH measured in the
//! same run. `plenum bench` measures on the shared rays files instead.

use plenum_core::accel::{AccelKind, Coherence};
use plenum_core::geometry::TriangleMesh;
use plenum_core::math::{Ray, Vec3};
use plenum_core::sampling::Rng;
use rayon::prelude::*;
use std::path::Path;
use std::time::Instant;

fn median(mut f: impl FnMut()) -> f64 {
    f();
    let mut t: Vec<f64> = (0..5)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[2]
}

/// A 512×512 pinhole view of the mesh's box, and 250,000 rays from random points in the box
/// in random directions.
fn rays(mesh: &TriangleMesh) -> (Vec<Ray>, Vec<Ray>) {
    let b = mesh.bounds();
    let (centre, extent) = (b.centroid(), b.diagonal());
    let forward = Vec3::new(-0.35, -0.45, -1.0).normalized();
    let eye = centre - forward * (0.42 * extent.length() / 20f64.to_radians().tan());
    let right = Vec3::new(-forward.z, 0.0, forward.x).normalized();
    let up = right.cross(forward);
    let th = 20f64.to_radians().tan();
    let n = 512;
    let camera = (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f64, (i / n) as f64);
            let u = ((x + 0.5) / n as f64 * 2.0 - 1.0) * th;
            let v = (1.0 - (y + 0.5) / n as f64 * 2.0) * th;
            Ray::new(eye, (forward + up * v + right * u).normalized())
        })
        .collect();
    let mut rng = Rng::for_sample(1, 0, 0, 0);
    let incoherent = (0..250_000)
        .map(|_| {
            let o = b.min
                + Vec3::new(
                    rng.uniform() * extent.x,
                    rng.uniform() * extent.y,
                    rng.uniform() * extent.z,
                );
            let z = 1.0 - 2.0 * rng.uniform();
            let s = (1.0 - z * z).max(0.0).sqrt();
            let phi = std::f64::consts::TAU * rng.uniform();
            Ray::new(o, Vec3::new(s * phi.cos(), s * phi.sin(), z))
        })
        .collect();
    (camera, incoherent)
}

fn main() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/meshes/stanford-bunny.obj");
    let mesh = match plenum_scene::load_mesh(&path) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("skipped: {e}");
            return;
        }
    };
    let (camera, incoherent) = rays(&mesh);
    println!(
        "bunny, {} triangles, {} threads",
        mesh.triangle_count(),
        rayon::current_num_threads()
    );
    let mut baseline: Option<[f64; 3]> = None;
    for kind in [AccelKind::Bvh, AccelKind::Grid, AccelKind::Octree] {
        let build = median(|| {
            std::hint::black_box(mesh.with_accel(kind));
        });
        let m = mesh.with_accel(kind);
        // `any`: any-hit queries for rays of that coherence, else closest-hit ones.
        let trace = |rays: &[Ray], any: Option<Coherence>| {
            let n = rays.len() as f64;
            n / median(|| {
                let hits: usize = rays
                    .par_chunks(1024)
                    .map(|c| {
                        c.iter()
                            .filter(|r| match any {
                                Some(c) => m.intersect_any_as(r, f64::INFINITY, c).is_some(),
                                None => m.intersect(r, f64::INFINITY).is_some(),
                            })
                            .count()
                    })
                    .sum();
                std::hint::black_box(hits);
            }) / 1e6
        };
        let figures = [
            trace(&camera, None),
            trace(&camera, Some(Coherence::Coherent)),
            trace(&incoherent, None),
        ];
        let base = *baseline.get_or_insert(figures);
        println!(
            "{kind:>6}: build {:6.1} ms | camera closest {:6.2} Mrays/s ({:.2}×), any {:6.2} ({:.2}×) | incoherent closest {:6.2} ({:.2}×) | {:.1} bytes/triangle",
            build * 1e3,
            figures[0],
            figures[0] / base[0],
            figures[1],
            figures[1] / base[1],
            figures[2],
            figures[2] / base[2],
            m.memory_bytes() as f64 / m.triangle_count() as f64
        );
    }
}
