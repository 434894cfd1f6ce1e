//! Cut-outs (`Primitive::alpha`): rays pass a cut-away part as if nothing were there, for
//! nearest hits and shadow rays, on meshes placed by a transform and on analytic shapes.

use plenum_core::accel::{AccelKind, Coherence};
use plenum_core::color::Color;
use plenum_core::geometry::{Polygon, Shape, TriangleMesh};
use plenum_core::material::{FloatTexture, Material};
use plenum_core::math::{Ray, Transform, Vec3};
use plenum_core::scene::{Alpha, Scene, SceneBuilder};
use plenum_core::texture::Texture;
use std::sync::Arc;

/// Quads over [0, 1]² with (u, v) = (x, y), one at each height in `zs`, in one mesh.
fn stacked_quads(zs: &[f64]) -> TriangleMesh {
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    let mut triangles = Vec::new();
    for &z in zs {
        let base = positions.len() as u32;
        for (x, y) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            positions.push(Vec3::new(x, y, z));
            uvs.push([x, y]);
        }
        triangles.push([base, base + 1, base + 2]);
        triangles.push([base, base + 2, base + 3]);
    }
    TriangleMesh::new(positions, triangles, vec![], uvs).unwrap()
}

/// A checkerboard of 4 × 4 squares over the unit square: 0 on even squares, 1 on odd.
fn checker() -> FloatTexture {
    FloatTexture::Texture(Texture::Checker2d {
        even: Color::gray(0.0),
        odd: Color::gray(1.0),
        scale: 4.0,
    })
}

/// `mesh` cut by `alpha` and moved by `placement`, over an opaque floor at z = −10.
fn scene(mesh: TriangleMesh, alpha: Alpha, placement: Transform, kind: AccelKind) -> Scene {
    let mut b = SceneBuilder::default();
    let m = b.add_material("m", Material::default());
    b.add_object("cut", Shape::Mesh(Arc::new(mesh)), placement, m);
    b.set_last_alpha(alpha);
    let floor = Polygon::new(vec![
        Vec3::new(-50.0, -50.0, -10.0),
        Vec3::new(50.0, -50.0, -10.0),
        Vec3::new(50.0, 50.0, -10.0),
        Vec3::new(-50.0, 50.0, -10.0),
    ])
    .unwrap();
    b.add_object(
        "floor",
        Shape::Polygon(Box::new(floor)),
        Transform::IDENTITY,
        m,
    );
    b.build_with(kind)
}

fn down_at(x: f64, y: f64) -> Ray {
    Ray::new(Vec3::new(x, y, 5.0), Vec3::new(0.0, 0.0, -1.0))
}

#[test]
fn a_checkerboard_cutoff_lets_rays_through_its_even_squares_only() {
    let offset = Vec3::new(2.0, -3.0, 0.5);
    for kind in [AccelKind::Bvh, AccelKind::Grid, AccelKind::None] {
        let alpha = Alpha {
            texture: checker(),
            cutoff: Some(0.5),
        };
        let s = scene(
            stacked_quads(&[0.0]),
            alpha,
            Transform::translate(offset),
            kind,
        );
        for i in 0..8 {
            for j in 0..8 {
                let (u, v) = ((i as f64 + 0.5) / 8.0, (j as f64 + 0.5) / 8.0);
                let ray = down_at(u + offset.x, v + offset.y);
                let odd = ((u * 4.0).floor() + (v * 4.0).floor()) as i32 % 2 == 1;
                let (prim, hit) = s.geometry.intersect(&ray, f64::INFINITY).unwrap();
                let name = &s.geometry.names[prim as usize];
                if odd {
                    assert_eq!(name, "cut", "{kind:?} ({u}, {v})");
                    assert!((hit.t - 4.5).abs() < 1e-9, "{}", hit.t);
                } else {
                    assert_eq!(name, "floor", "{kind:?} ({u}, {v})");
                    assert!((hit.t - 15.0).abs() < 1e-9, "{}", hit.t);
                }
                // A shadow ray toward the floor is blocked exactly where the quad is.
                assert_eq!(
                    s.geometry.occluded(&ray, 14.0, Coherence::Incoherent),
                    odd,
                    "{kind:?} ({u}, {v})"
                );
            }
        }
    }
}

#[test]
fn a_ray_passes_every_cut_layer_of_one_mesh_to_the_first_kept_one() {
    // Five layers of one mesh; the texture depends on (u, v) only, so a cutoff above every
    // value but the kept one's is needed: use the height through the object point instead,
    // cutting every layer above z = −2.
    let texture = FloatTexture::Texture(Texture::Checker3d {
        even: Color::gray(0.0),
        odd: Color::gray(1.0),
        scale: 0.25,
    });
    // Cubes of side 4 from the origin: z in [−4, 0) is odd (kept) for x, y in [0, 1);
    // z in [0, 4) even (cut).
    let mesh = stacked_quads(&[3.0, 2.5, 1.0, 0.5, -1.0, -3.0]);
    let alpha = Alpha {
        texture,
        cutoff: Some(0.5),
    };
    let s = scene(mesh, alpha, Transform::IDENTITY, AccelKind::Bvh);
    let (prim, hit) = s
        .geometry
        .intersect(&down_at(0.3, 0.6), f64::INFINITY)
        .unwrap();
    assert_eq!(s.geometry.names[prim as usize], "cut");
    // Triangle hits are found in f32: t to its precision.
    assert!(
        (hit.t - 6.0).abs() < 1e-6,
        "the layer at z = −1: t = {}",
        hit.t
    );
    // Within reach of the cut layers only, nothing is hit.
    assert!(s.geometry.intersect(&down_at(0.3, 0.6), 5.5).is_none());
    assert!(!s
        .geometry
        .occluded(&down_at(0.3, 0.6), 5.5, Coherence::Coherent));
    assert!(s
        .geometry
        .occluded(&down_at(0.3, 0.6), 6.5, Coherence::Coherent));
}

#[test]
fn stochastic_alpha_is_hit_as_often_as_its_coverage() {
    // 40,000 rays at distinct points (a 200 × 200 grid) through coverage 0.3: the hit
    // fraction's standard deviation is √(0.3·0.7/40000) = 0.0023; tolerance 5σ. The test is
    // deterministic (a hash of the hit and the direction), so it holds for any thread count.
    let alpha = Alpha::stochastic(FloatTexture::Constant(0.3));
    let s = scene(
        stacked_quads(&[0.0]),
        alpha,
        Transform::IDENTITY,
        AccelKind::Bvh,
    );
    let n = 200;
    let mut hits = 0;
    let mut blocked = 0;
    for i in 0..n {
        for j in 0..n {
            let ray = down_at((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
            let (prim, _) = s.geometry.intersect(&ray, f64::INFINITY).unwrap();
            hits += (s.geometry.names[prim as usize] == "cut") as usize;
            blocked += s.geometry.occluded(&ray, 14.0, Coherence::Incoherent) as usize;
        }
    }
    let total = (n * n) as f64;
    for (what, count) in [("hit", hits), ("blocked", blocked)] {
        let f = count as f64 / total;
        assert!((f - 0.3).abs() < 5.0 * 0.0023, "{what} fraction {f}");
    }
    // The same ray decides the same way each time (the hash, not a random stream).
    let ray = down_at(0.123, 0.456);
    let first = s.geometry.intersect(&ray, f64::INFINITY).map(|(p, _)| p);
    for _ in 0..10 {
        assert_eq!(
            s.geometry.intersect(&ray, f64::INFINITY).map(|(p, _)| p),
            first
        );
    }
}

#[test]
fn an_alpha_of_one_costs_nothing_and_of_zero_hides_the_shape() {
    let s = scene(
        stacked_quads(&[0.0]),
        Alpha::stochastic(FloatTexture::Constant(1.0)),
        Transform::IDENTITY,
        AccelKind::Bvh,
    );
    assert!(s.geometry.primitives[0].alpha.is_none());
    let s = scene(
        stacked_quads(&[0.0]),
        Alpha::stochastic(FloatTexture::Constant(0.0)),
        Transform::IDENTITY,
        AccelKind::Bvh,
    );
    let (prim, _) = s
        .geometry
        .intersect(&down_at(0.5, 0.5), f64::INFINITY)
        .unwrap();
    assert_eq!(s.geometry.names[prim as usize], "floor");
}
