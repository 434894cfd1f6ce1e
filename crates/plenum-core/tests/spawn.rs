//! "A ray spawned from a hit never re-hits the surface it leaves": random shapes under random
//! transforms, hit by random rays; from each hit, rays leave in random directions from the
//! offset origin. Planar shapes must never be hit again; convex solids must not be hit again
//! by rays leaving outward, and rays going inward must cross the whole solid, not re-hit the
//! entry point. Fixed seeds; no tolerance beyond "no hit".

use plenum_core::geometry::{Cuboid, Cylinder, Disk, Polygon, Shape, Sphere, TriangleMesh};
use plenum_core::math::{offset_ray_origin, Ray, Transform, Vec3};
use plenum_core::sampling::Rng;
use plenum_core::scene::Primitive;
use std::sync::Arc;

fn uniform_sphere(rng: &mut Rng) -> Vec3 {
    let z = 1.0 - 2.0 * rng.uniform();
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * std::f64::consts::PI * rng.uniform();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Log-uniform in [lo, hi]: covers many scales.
fn log_uniform(rng: &mut Rng, lo: f64, hi: f64) -> f64 {
    (lo.ln() + rng.uniform() * (hi.ln() - lo.ln())).exp()
}

fn random_transform(rng: &mut Rng) -> Transform {
    let scale = Vec3::new(
        log_uniform(rng, 0.05, 20.0),
        log_uniform(rng, 0.05, 20.0),
        log_uniform(rng, 0.05, 20.0),
    );
    let rotate = Transform::rotate(uniform_sphere(rng), rng.uniform() * 360.0).unwrap();
    let translate = Transform::translate(uniform_sphere(rng) * log_uniform(rng, 0.01, 1000.0));
    translate
        .after(&rotate)
        .after(&Transform::scale(scale).unwrap())
}

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    /// No ray from the surface can hit it again.
    Planar,
    /// Convex and closed: outward rays escape, inward rays cross it.
    Convex,
}

fn random_shape(rng: &mut Rng, which: usize) -> (Shape, Kind) {
    let point = |rng: &mut Rng| uniform_sphere(rng) * log_uniform(rng, 0.01, 100.0);
    match which {
        0 => (
            Shape::Sphere(Sphere::new(point(rng), log_uniform(rng, 0.001, 1000.0))),
            Kind::Convex,
        ),
        1 => {
            let mesh = TriangleMesh::new(
                vec![point(rng), point(rng), point(rng)],
                vec![[0, 1, 2]],
                vec![],
                vec![],
            )
            .unwrap();
            (Shape::Mesh(Arc::new(mesh)), Kind::Planar)
        }
        2 => {
            // A regular polygon in a random plane.
            let n = 3 + (rng.next_u32() % 6) as usize;
            let normal = uniform_sphere(rng);
            let (s, t) = normal.orthonormal_basis();
            let c = point(rng);
            let r = log_uniform(rng, 0.01, 100.0);
            let vertices = (0..n)
                .map(|i| {
                    let a = i as f64 / n as f64 * std::f64::consts::TAU;
                    c + (s * a.cos() + t * a.sin()) * r
                })
                .collect();
            (
                Shape::Polygon(Box::new(Polygon::new(vertices).unwrap())),
                Kind::Planar,
            )
        }
        3 => (
            Shape::Disk(Disk::new(
                point(rng),
                uniform_sphere(rng),
                log_uniform(rng, 0.01, 100.0),
            )),
            Kind::Planar,
        ),
        4 => {
            let a = point(rng);
            let size = Vec3::new(
                log_uniform(rng, 0.01, 100.0),
                log_uniform(rng, 0.01, 100.0),
                log_uniform(rng, 0.01, 100.0),
            );
            (Shape::Cuboid(Cuboid::new(a, a + size)), Kind::Convex)
        }
        _ => (
            Shape::Cylinder(Cylinder::new(
                log_uniform(rng, 0.01, 100.0),
                log_uniform(rng, 0.01, 100.0),
                true,
            )),
            Kind::Convex,
        ),
    }
}

#[test]
fn spawned_rays_never_rehit_their_surface() {
    let names = [
        "sphere",
        "triangle",
        "polygon",
        "disk",
        "box",
        "capped cylinder",
    ];
    for (which, name) in names.iter().enumerate() {
        let mut rng = Rng::new(0x5eed + which as u64, 7);
        let mut hits = 0;
        let mut spawned = 0;
        let mut trial = 0;
        while hits < 2000 && trial < 100_000 {
            trial += 1;
            let (shape, kind) = random_shape(&mut rng, which);
            let to_world = if trial % 2 == 0 {
                None
            } else {
                Some(Box::new(random_transform(&mut rng)))
            };
            let prim = Primitive {
                vertex_materials: None,
                shape,
                to_world,
                motion: None,
                material: 0,
                light: None,
                alpha: None,
                bump: None,
            };
            let Some(bounds) = prim.world_bounds() else {
                continue;
            };
            let (centre, radius) = bounds.bounding_sphere();
            // From outside the bounding sphere toward a random point of the box.
            let origin =
                centre + uniform_sphere(&mut rng) * radius * log_uniform(&mut rng, 1.5, 100.0);
            let d = bounds.diagonal();
            let target = bounds.min
                + Vec3::new(
                    d.x * rng.uniform(),
                    d.y * rng.uniform(),
                    d.z * rng.uniform(),
                );
            let ray = Ray::new(origin, target - origin);
            let Some(hit) = prim.intersect(&ray, f64::INFINITY) else {
                continue;
            };
            hits += 1;
            let it = prim.interaction(&ray, &hit, 0, true);
            for _ in 0..8 {
                let w = uniform_sphere(&mut rng);
                let spawn = Ray::new(offset_ray_origin(it.p, it.p_error, it.n, w), w);
                spawned += 1;
                let again = prim.intersect(&spawn, f64::INFINITY);
                match (kind, w.dot(it.n) > 0.0, again) {
                    (_, _, None) => {
                        assert!(
                            !(kind == Kind::Convex && w.dot(it.n) < -1e-3),
                            "{name}: an inward ray from {:?} escaped the solid",
                            it.p
                        );
                    }
                    (Kind::Planar, _, Some(h)) | (Kind::Convex, true, Some(h)) => panic!(
                        "{name} (trial {trial}): re-hit at t = {:e} from {:?} along {w:?}",
                        h.t, it.p
                    ),
                    (Kind::Convex, false, Some(h)) => {
                        // An inward ray must cross the solid: through another face, or across
                        // a curved one, not stop where it started.
                        let curved = which == 0 || (which == 5 && hit.part == 0);
                        let chord = (spawn.at(h.t) - it.p).length();
                        assert!(
                            if curved {
                                chord > 1e-12 * radius
                            } else {
                                h.part != hit.part
                            },
                            "{name} (trial {trial}): an inward ray re-hit its start"
                        );
                    }
                }
            }
        }
        // The property must have been exercised, not skipped.
        assert!(hits == 2000 && spawned == 16000, "{name}: only {hits} hits");
    }
}
