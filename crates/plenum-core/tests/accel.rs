//! Every acceleration structure finds the same closest hit as brute force (`none`): the same
//! primitive, at a distance within 1e-5 relative (a different primitive only where two are
//! hit at that same distance, as at a shared edge). And any-hit agrees with closest-hit about
//! whether something is hit. Property tests with a fixed seed: random triangle soups with
//! degenerate and tiny triangles, spheres and polygons, axis-parallel rays, rays that start
//! on a surface, and the empty scene.

use plenum_core::accel::{AccelKind, Coherence};
use plenum_core::geometry::{Polygon, Shape, Sphere, TriangleMesh};
use plenum_core::material::Material;
use plenum_core::math::{Ray, Transform, Vec3};
use plenum_core::scene::{Scene, SceneBuilder};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

const FAST: [AccelKind; 3] = [AccelKind::Bvh, AccelKind::Grid, AccelKind::Octree];

fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x5EED_0004),
        failure_persistence: None,
        ..Config::default()
    }
}

fn vec3(r: f64) -> impl Strategy<Value = Vec3> {
    (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn triangle() -> impl Strategy<Value = [Vec3; 3]> {
    prop_oneof![
        6 => (vec3(10.0), vec3(3.0), vec3(3.0)).prop_map(|(c, a, b)| [c, c + a, c + b]),
        // Tiny.
        1 => (vec3(10.0), vec3(1e-4), vec3(1e-4)).prop_map(|(c, a, b)| [c, c + a, c + b]),
        // Degenerate: three points on a line, or two equal.
        1 => (vec3(10.0), vec3(3.0), -1.0..2.0f64).prop_map(|(c, a, s)| [c, c + a, c + a * s]),
        1 => (vec3(10.0), vec3(3.0)).prop_map(|(c, a)| [c, c + a, c + a]),
        // In an axis plane, where axis-parallel rays graze or hit head-on.
        1 => (vec3(10.0), -3.0..3.0f64, -3.0..3.0f64).prop_map(|(c, u, v)| [
            c,
            c + Vec3::new(u, 0.0, 0.0),
            c + Vec3::new(0.0, v, 0.0)
        ]),
    ]
}

fn direction() -> impl Strategy<Value = Vec3> {
    prop_oneof![
        3 => vec3(1.0).prop_filter("non-zero", |d| d.length() > 1e-3),
        1 => (0..6usize).prop_map(|i| {
            let axis = [Vec3::X, Vec3::Y, Vec3::Z][i % 3];
            if i < 3 { axis } else { -axis }
        }),
    ]
}

/// Rays from anywhere around the geometry.
fn rays() -> impl Strategy<Value = Vec<Ray>> {
    prop::collection::vec(
        (vec3(14.0), direction()).prop_map(|(o, d)| Ray::new(o, d)),
        1..40,
    )
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-5 * a.abs().max(b.abs())
}

/// Closest hits agree: same primitive and distance, or another primitive at that distance.
fn agree(fast: Option<(u32, f64)>, oracle: Option<(u32, f64)>) -> Result<(), String> {
    match (fast, oracle) {
        (None, None) => Ok(()),
        (Some((p, t)), Some((q, s))) if close(t, s) && (p == q || close(t, s)) => Ok(()),
        _ => Err(format!("{fast:?} but brute force found {oracle:?}")),
    }
}

fn check_mesh(triangles: &[[Vec3; 3]], rays: &[Ray]) -> Result<(), TestCaseError> {
    let positions: Vec<Vec3> = triangles.iter().flatten().copied().collect();
    let indices: Vec<[u32; 3]> = (0..triangles.len() as u32)
        .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect();
    let mesh = TriangleMesh::new(positions, indices, vec![], vec![]).unwrap();
    let oracle = mesh.with_accel(AccelKind::None);
    // Rays that start on a triangle (its centroid), leaving in the ray's direction.
    let mut all: Vec<Ray> = rays.to_vec();
    for ((_, tri), r) in mesh.triangles().zip(rays) {
        let c = (tri[0] + tri[1] + tri[2]) / 3.0;
        all.push(Ray::new(c, r.direction));
    }
    for kind in FAST {
        let m = mesh.with_accel(kind);
        for ray in &all {
            // The BVH stores triangles in its own order: compare them as given.
            let want = oracle
                .intersect(ray, f64::INFINITY)
                .map(|h| (oracle.source_triangle(h.part), h.t));
            let got = m
                .intersect(ray, f64::INFINITY)
                .map(|h| (m.source_triangle(h.part), h.t));
            agree(got, want).map_err(|e| TestCaseError::fail(format!("{kind}: {ray:?}: {e}")))?;
            // Any hit, walked either way the coherence hint chooses.
            for coherence in [Coherence::Incoherent, Coherence::Coherent] {
                let any = m.intersect_any_as(ray, f64::INFINITY, coherence).is_some();
                prop_assert_eq!(
                    any,
                    got.is_some(),
                    "{}: any-hit disagrees ({:?})",
                    kind,
                    coherence
                );
                // A shorter segment: any-hit and closest-hit agree there too.
                if let Some((_, t)) = want {
                    let short = t * 0.5;
                    prop_assert_eq!(
                        m.intersect_any_as(ray, short, coherence).is_some(),
                        m.intersect(ray, short).is_some()
                    );
                }
            }
        }
    }
    Ok(())
}

fn scene_of(spheres: &[(Vec3, f64)], polygons: &[Vec<Vec3>], kind: AccelKind) -> Scene {
    let mut b = SceneBuilder::default();
    let m = b.add_material("m", Material::default());
    for (i, &(c, r)) in spheres.iter().enumerate() {
        b.add_object(
            format!("s{i}"),
            Shape::Sphere(Sphere::new(c, r)),
            Transform::IDENTITY,
            m,
        );
    }
    for (i, p) in polygons.iter().enumerate() {
        if let Ok(poly) = Polygon::new(p.clone()) {
            b.add_object(
                format!("p{i}"),
                Shape::Polygon(Box::new(poly)),
                Transform::IDENTITY,
                m,
            );
        }
    }
    b.build_with(kind)
}

/// A planar polygon: points around a centre in a random plane, at random radii (so
/// sometimes concave).
fn polygon() -> impl Strategy<Value = Vec<Vec3>> {
    (
        vec3(10.0),
        direction(),
        prop::collection::vec(0.2..3.0f64, 3..8),
    )
        .prop_map(|(c, n, radii)| {
            let n = n.normalized();
            let u = if n.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
            let u = (u - n * n.dot(u)).normalized();
            let v = n.cross(u);
            let k = radii.len() as f64;
            radii
                .iter()
                .enumerate()
                .map(|(i, &r)| {
                    let a = i as f64 / k * std::f64::consts::TAU;
                    c + (u * a.cos() + v * a.sin()) * r
                })
                .collect()
        })
}

proptest! {
    #![proptest_config(config(64))]

    #[test]
    fn triangle_soups_agree(
        triangles in prop::collection::vec(triangle(), 1..60),
        rays in rays(),
    ) {
        check_mesh(&triangles, &rays)?;
    }

    #[test]
    fn spheres_and_polygons_agree(
        spheres in prop::collection::vec((vec3(10.0), 0.01..3.0f64), 0..30),
        polygons in prop::collection::vec(polygon(), 0..30),
        rays in rays(),
    ) {
        check_scene(&spheres, &polygons, &rays)?;
    }

    /// A small model under and beside polygons as large as the scene: the grid and the
    /// octree test those on every ray instead of filing them.
    #[test]
    fn model_in_a_stadium_agrees(
        spheres in prop::collection::vec((vec3(2.0), 0.01..0.5f64), 10..60),
        walls in prop::collection::vec((vec3(3.0), direction(), 30.0..60.0f64), 1..4),
        triangles in prop::collection::vec(triangle(), 1..60),
        rays in rays(),
    ) {
        let walls: Vec<Vec<Vec3>> = walls
            .iter()
            .map(|&(c, n, r)| {
                let n = n.normalized();
                let u = if n.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
                let u = (u - n * n.dot(u)).normalized();
                let v = n.cross(u);
                vec![c + u * r, c + v * r, c - u * r, c - v * r]
            })
            .collect();
        check_scene(&spheres, &walls, &rays)?;
        // The same in a mesh: triangles with two as large as the scene.
        let mut soup: Vec<[Vec3; 3]> = triangles.iter().map(|t| t.map(|p| p * 0.2)).collect();
        soup.push([Vec3::new(-50.0, -1.0, -50.0), Vec3::new(50.0, -1.0, -50.0), Vec3::new(0.0, -1.0, 50.0)]);
        soup.push([Vec3::new(-50.0, -50.0, 2.0), Vec3::new(50.0, -50.0, 2.0), Vec3::new(0.0, 50.0, 2.5)]);
        check_mesh(&soup, &rays)?;
    }
}

/// Every structure finds brute force's closest hit among spheres and polygons, and any-hit
/// agrees about occlusion, on the rays given and on rays that start on a sphere.
fn check_scene(
    spheres: &[(Vec3, f64)],
    polygons: &[Vec<Vec3>],
    rays: &[Ray],
) -> Result<(), TestCaseError> {
    let oracle = scene_of(spheres, polygons, AccelKind::None);
    // Rays that start on a sphere.
    let mut all = rays.to_vec();
    for (&(c, r), ray) in spheres.iter().zip(rays) {
        all.push(Ray::new(c + ray.direction.normalized() * r, ray.direction));
    }
    for kind in FAST {
        let scene = scene_of(spheres, polygons, kind);
        prop_assert_eq!(scene.geometry.accel_kind(), kind);
        for ray in &all {
            let want = oracle
                .geometry
                .intersect(ray, f64::INFINITY)
                .map(|(p, h)| (p, h.t));
            let got = scene
                .geometry
                .intersect(ray, f64::INFINITY)
                .map(|(p, h)| (p, h.t));
            agree(got, want).map_err(|e| TestCaseError::fail(format!("{kind}: {e}")))?;
            for coherence in [Coherence::Incoherent, Coherence::Coherent] {
                prop_assert_eq!(
                    scene.geometry.occluded(ray, f64::INFINITY, coherence),
                    got.is_some()
                );
            }
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(config(8))]

    /// Larger soups make deeper trees and finer grids.
    #[test]
    fn large_triangle_soups_agree(
        triangles in prop::collection::vec(triangle(), 300..800),
        rays in rays(),
    ) {
        check_mesh(&triangles, &rays)?;
    }

    /// Small triangles in a few far-apart clusters: most of the grid's macro cells are
    /// empty, so rays cross them in jumps and resume cell by cell inside full ones.
    #[test]
    fn clustered_triangle_soups_agree(
        clusters in prop::collection::vec(
            (vec3(10.0), prop::collection::vec((vec3(0.8), vec3(0.3), vec3(0.3)), 100..300)),
            2..5,
        ),
        rays in rays(),
    ) {
        let triangles: Vec<[Vec3; 3]> = clusters
            .iter()
            .flat_map(|(center, tris)| {
                tris.iter().map(move |&(c, a, b)| [*center + c, *center + c + a, *center + c + b])
            })
            .collect();
        check_mesh(&triangles, &rays)?;
    }
}

#[test]
fn empty_scene_misses() {
    for kind in AccelKind::ALL {
        let scene = scene_of(&[], &[], kind);
        let ray = Ray::new(Vec3::ZERO, Vec3::new(0.3, -0.2, 1.0));
        assert!(
            scene.geometry.intersect(&ray, f64::INFINITY).is_none(),
            "{kind}"
        );
        assert!(
            !scene
                .geometry
                .occluded(&ray, f64::INFINITY, Coherence::Incoherent),
            "{kind}"
        );
    }
}

#[test]
fn accelerator_names_parse() {
    for kind in AccelKind::ALL {
        assert_eq!(kind.name().parse::<AccelKind>(), Ok(kind));
    }
    assert!("kd-tree".parse::<AccelKind>().unwrap_err().contains("bvh"));
}
