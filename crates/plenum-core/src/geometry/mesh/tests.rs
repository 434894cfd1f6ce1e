use super::watertight::*;
use super::*;
use crate::accel::simd::{Avx, F4};
use crate::accel::Coherence;

#[test]
fn barycentrics_and_distance() {
    let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let ray = Ray::new(Vec3::new(0.25, 0.5, 2.0), -Vec3::Z);
    let (t, b1, b2) = intersect_triangle(&ray, 1e9, tri).unwrap();
    assert!((t - 2.0).abs() < 1e-15);
    assert!((b1 - 0.25).abs() < 1e-15 && (b2 - 0.5).abs() < 1e-15);
    let miss = Ray::new(Vec3::new(0.75, 0.5, 2.0), -Vec3::Z);
    assert!(intersect_triangle(&miss, 1e9, tri).is_none());
}

#[test]
fn shared_edge_is_watertight() {
    // Two triangles sharing the diagonal of a square: a ray exactly through the diagonal
    // must hit at least one of them.
    let (a, b, c, d) = (Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y);
    for i in 0..=100 {
        let s = i as f64 / 100.0;
        let ray = Ray::new(Vec3::new(s, s, 1.0), Vec3::new(1e-3, -2e-3, -1.0));
        let hit1 = intersect_triangle(&ray, 1e9, [a, b, c]);
        let hit2 = intersect_triangle(&ray, 1e9, [a, c, d]);
        if (0.01..=0.99).contains(&s) {
            assert!(hit1.is_some() || hit2.is_some(), "gap at s = {s}");
        }
    }
}

/// A bumpy square of `n` × `n` quads, two triangles each, its coordinates exact in f32.
fn sheet(n: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let positions = (0..=n)
        .flat_map(|j| (0..=n).map(move |i| (i, j)))
        .map(|(i, j)| Vec3::new(i as f64, j as f64, ((i * 7 + j * 3) % 5) as f64 * 0.125))
        .collect();
    let v = |i: u32, j: u32| j * (n + 1) + i;
    let triangles = (0..n)
        .flat_map(|j| (0..n).map(move |i| (i, j)))
        .flat_map(|(i, j)| {
            [
                [v(i, j), v(i + 1, j), v(i + 1, j + 1)],
                [v(i, j), v(i + 1, j + 1), v(i, j + 1)],
            ]
        })
        .collect();
    (positions, triangles)
}

#[test]
fn every_layout_keeps_the_triangles_and_their_numbering() {
    let (positions, triangles) = sheet(13);
    let normals = vec![Vec3::Z; positions.len()];
    let kept = TriangleMesh::new(positions.clone(), triangles.clone(), normals, vec![]).unwrap();
    let bare = TriangleMesh::new(positions.clone(), triangles.clone(), vec![], vec![]).unwrap();
    let corners = |t: &[u32; 3]| t.map(|i| positions[i as usize]);
    for kind in [
        AccelKind::Bvh,
        AccelKind::Grid,
        AccelKind::Octree,
        AccelKind::None,
    ] {
        // Back and forth between blocks and the indexed layout.
        let kept = kept
            .with_accel(kind)
            .with_accel(AccelKind::Octree)
            .with_accel(kind);
        assert_eq!(
            kept.indexed(),
            (positions.clone(), triangles.clone()),
            "{kind}"
        );
        let bare = bare.with_accel(kind);
        let (vertices, tris) = bare.indexed();
        assert_eq!(
            vertices.len(),
            positions.len(),
            "{kind}: shared corners merged"
        );
        for (t, u) in triangles.iter().zip(&tris) {
            assert_eq!(corners(t), u.map(|i| vertices[i as usize]), "{kind}");
        }
        for mesh in [&kept, &bare] {
            assert_eq!(mesh.triangles().count(), triangles.len(), "{kind}");
            for (part, tri) in mesh.triangles() {
                let source = mesh.source_triangle(part) as usize;
                assert_eq!(tri, corners(&triangles[source]), "{kind}");
            }
        }
        let (part, _) = kept.triangles().nth(5).unwrap();
        let source = kept.source_triangle(part) as usize;
        assert_eq!(kept.vertex_indices(part), Some(triangles[source]), "{kind}");
        assert_eq!(bare.vertex_indices(part), None, "{kind}");
    }
}

#[test]
fn leaves_the_build_cannot_split_by_position_still_take_one_test() {
    // Twelve triangles about one centroid, each tilted about x by its own angle: no
    // split by position separates them, yet every leaf must fit the one test of
    // `search_leaf_avx`; rays off the centroid meet them at different distances.
    let count = 12;
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for k in 0..count {
        let angle = 0.1 * k as f64 - 0.55;
        let (sin, cos) = angle.sin_cos();
        let tilted = |x: f64, y: f64| Vec3::new(x, y * cos, y * sin);
        let first = positions.len() as u32;
        positions.extend([tilted(-1.0, -1.0), tilted(2.0, -1.0), tilted(-1.0, 2.0)]);
        triangles.push([first, first + 1, first + 2]);
    }
    let mesh = TriangleMesh::new(positions, triangles, vec![], vec![]).unwrap();
    assert!(
        matches!(&mesh.accel, Accel::None(_)),
        "a new mesh is in no structure yet"
    );
    let mesh = mesh.with_accel(AccelKind::Bvh);
    let Accel::Bvh(bvh) = &mesh.accel else {
        panic!("a BVH was asked for")
    };
    assert!(bvh.is_embedded());
    let leaves = bvh.embedded_leaves();
    assert!(leaves.len() > 1 && leaves.iter().all(|&(_, n)| n <= 2 * LANES));
    let brute = mesh.with_accel(AccelKind::None);
    for i in 0..40 {
        // Never through the line all twelve share (y = z = 0), where they tie.
        let y = -0.87 + 0.05 * i as f64;
        let ray = Ray::new(Vec3::new(0.1, y, -5.0), Vec3::new(0.01, 0.02, 1.0));
        let (hit, expected) = (mesh.intersect(&ray, 1e9), brute.intersect(&ray, 1e9));
        let hit_source = hit.map(|h| (mesh.source_triangle(h.part), h.t));
        let expected_source = expected.map(|h| (brute.source_triangle(h.part), h.t));
        assert_eq!(hit_source, expected_source, "y = {y}");
        assert_eq!(
            mesh.intersect_any(&ray, 1e9).is_some(),
            hit.is_some(),
            "y = {y}"
        );
    }
}

#[test]
fn blocks_tested_in_pairs_give_the_hits_of_blocks_tested_alone() {
    // Bit for bit, whatever the CPU: eight lanes compute what four do. Rays from above
    // at random (seed 11), and rays straight down through vertices, where the edge
    // functions are zero and the f64 test decides. Without AVX both sides test alone.
    let (positions, triangles) = sheet(24);
    let mesh = TriangleMesh::new(positions, triangles, vec![], vec![]).unwrap();
    let mut rng = crate::sampling::Rng::new(11, 0);
    let mut rays: Vec<Ray> = (0..3000)
        .map(|_| {
            let mut u = || rng.uniform();
            let origin = Vec3::new(u() * 30.0 - 3.0, u() * 30.0 - 3.0, 0.3 + u() * 4.0);
            let target = Vec3::new(u() * 24.0, u() * 24.0, 0.0);
            Ray::new(origin, target - origin)
        })
        .collect();
    rays.extend((0..25).map(|i| Ray::new(Vec3::new(i as f64, 7.0, 3.0), -Vec3::Z)));
    for kind in [AccelKind::Bvh, AccelKind::Grid, AccelKind::Octree] {
        let mesh = mesh.with_accel(kind);
        let mut hits = 0;
        for ray in &rays {
            let incoherent = Coherence::Incoherent;
            let alone = mesh.search::<true>(ray, f64::INFINITY, None, incoherent);
            let paired = mesh.search::<true>(ray, f64::INFINITY, Avx::detect(), incoherent);
            assert_eq!(paired, alone, "{kind}: {ray:?}");
            for coherence in [Coherence::Incoherent, Coherence::Coherent] {
                let any_alone = mesh.search::<false>(ray, f64::INFINITY, None, coherence);
                let any_paired = mesh.search::<false>(ray, f64::INFINITY, Avx::detect(), coherence);
                assert_eq!(any_paired.is_some(), alone.is_some(), "{kind}: {ray:?}");
                assert_eq!(any_alone.is_some(), alone.is_some(), "{kind}: {ray:?}");
            }
            hits += alone.is_some() as usize;
        }
        assert!(hits > 2000, "{kind}: {hits} hits");
    }
}

#[test]
fn a_bvh_with_its_blocks_apart_finds_the_hits_of_one_with_them_among_its_nodes() {
    // What a mesh too large to embed (some 40 million triangles) gets, here by a limit of
    // no bytes. Rays from above at random (seed 12).
    let (positions, triangles) = sheet(24);
    let normals = vec![Vec3::Z; positions.len()];
    let among = TriangleMesh::new(positions, triangles.clone(), normals, vec![])
        .unwrap()
        .with_accel(AccelKind::Bvh);
    let apart = among.rebuilt(AccelKind::Bvh, 0);
    assert!(matches!(&among.accel, Accel::Bvh(b) if b.is_embedded()));
    assert!(matches!(&apart.accel, Accel::Bvh(b) if !b.is_embedded()));
    assert_eq!(apart.indexed(), among.indexed());
    for (part, _) in apart.triangles() {
        let source = apart.source_triangle(part) as usize;
        assert_eq!(apart.vertex_indices(part), Some(triangles[source]));
    }
    let mut rng = crate::sampling::Rng::new(12, 0);
    let mut hits = 0;
    for _ in 0..3000 {
        let mut u = || rng.uniform();
        let origin = Vec3::new(u() * 30.0 - 3.0, u() * 30.0 - 3.0, 0.3 + u() * 4.0);
        let ray = Ray::new(origin, Vec3::new(u() * 24.0, u() * 24.0, 0.0) - origin);
        let found = |mesh: &TriangleMesh| {
            let hit = mesh.intersect(&ray, f64::INFINITY);
            let any = mesh.intersect_any(&ray, f64::INFINITY).is_some();
            (
                hit.map(|h| (h.t, h.u, h.v, mesh.source_triangle(h.part))),
                any,
            )
        };
        assert_eq!(found(&apart), found(&among), "{ray:?}");
        hits += found(&among).1 as usize;
    }
    assert!(hits > 2000, "{hits} hits");
}

#[test]
fn a_ray_leaving_a_triangle_misses_it_and_a_far_one_hits_it() {
    // Random triangles of every size (seed 5) whose centroid is a point exactly in f32,
    // corners too: a ray from the centroid, either way, has a distance of pure rounding
    // noise, which only pbrt's bound rejects (the cheap bound must leave it to that). A
    // ray from afar to the same point is settled by the cheap bound, at the distance
    // the f64 test finds.
    let mut rng = crate::sampling::Rng::new(5, 0);
    // Multiples of 1/16 under 1024, offsets of quarters times 2^-2..2^6: all sums fit in
    // f32's 24 bits.
    let mut multiples = |of: f64, below: f64| {
        let mut m = || ((rng.uniform() - 0.5) * 2.0 * below / of).round() * of;
        Vec3::new(m(), m(), m())
    };
    let exact = |p: Vec3| Vec3::new(p.x as f32 as f64, p.y as f32 as f64, p.z as f32 as f64);
    let mut far_hits = 0;
    for _ in 0..2000 {
        let centre = multiples(1.0 / 16.0, 1024.0);
        let scale = 2f64.powi(multiples(1.0, 4.5).x as i32 + 2);
        let (a, b) = (multiples(0.25, 2.0) * scale, multiples(0.25, 2.0) * scale);
        let away = multiples(1.0 / 1024.0, 0.5);
        if a.cross(b).length() < 1e-3 * scale * scale {
            continue;
        }
        let tri = [centre + a, centre + b, centre - a - b];
        assert_eq!(tri.map(exact), tri);
        let mesh = TriangleMesh::new(tri.to_vec(), vec![[0, 1, 2]], vec![], vec![]).unwrap();
        for d in [away, -away] {
            let leaving = Ray::new(centre, d);
            assert_eq!(
                mesh.intersect(&leaving, f64::INFINITY),
                None,
                "{tri:?} {d:?}"
            );
            assert_eq!(mesh.intersect_any(&leaving, f64::INFINITY), None, "{tri:?}");
        }
        let from = exact(centre + away * (scale * 10.0));
        let arriving = Ray::new(from, centre - from);
        // Not grazing, where a distance is ill-conditioned.
        let cos = a.cross(b).normalized().dot(arriving.direction.normalized());
        if cos.abs() < 0.2 {
            continue;
        }
        if let Some((t, _, _)) = intersect_triangle(&arriving, f64::INFINITY, tri) {
            let hit = mesh.intersect(&arriving, f64::INFINITY).expect("a far hit");
            assert!((hit.t - t).abs() <= 1e-5 * t, "{} against {t}", hit.t);
            assert!(mesh.intersect_any(&arriving, f64::INFINITY).is_some());
            far_hits += 1;
        }
    }
    assert!(far_hits > 1000, "{far_hits} far hits");
}

#[test]
fn the_cheap_bound_on_t_implies_pbrts_and_settles_far_small_triangles() {
    // Random sheared triangles (seed 11), four at a time, at distances 10⁻³..10³ and
    // across the ray 10⁻⁶..10 times as wide, tilted: wherever the cheap test settles a
    // lane with t > 0, pbrt's bound δt < t holds too, as the leaf test computes it. And
    // of the triangles at least 10⁻³ as wide as they are far, seen within 60° of head on
    // and not slivers, it settles all but 0.1 % (a bound in M³, M the largest coordinate
    // of all, settled 81 % of them).
    let mut rng = crate::sampling::Rng::new(11, 0);
    let mut uniform = move || rng.uniform() as f32;
    let (mut head_on, mut head_on_settled, mut settled_lanes) = (0, 0, 0);
    for _ in 0..20_000 {
        let mut corners = [[[0.0f32; 4]; 3]; 3]; // corner, axis, lane
        let mut head_on_lanes = 0u32;
        for lane in 0..4 {
            let distance = 10f32.powf(uniform() * 6.0 - 3.0);
            let ratio = 10f32.powf(uniform() * 7.0 - 6.0);
            let width = distance * ratio;
            let tilt = [uniform() * 2.0 - 1.0, uniform() * 2.0 - 1.0];
            for corner in &mut corners {
                let x = (uniform() * 2.0 - 1.0) * width;
                let y = (uniform() * 2.0 - 1.0) * width;
                corner[0][lane] = x;
                corner[1][lane] = y;
                corner[2][lane] = distance + tilt[0] * x + tilt[1] * y;
            }
            // Within 60° of head on: |tilt| < √3.
            if ratio > 1e-3 && tilt[0] * tilt[0] + tilt[1] * tilt[1] < 3.0 {
                head_on_lanes |= 1 << lane;
            }
        }
        let [a, b, c] = corners.map(|corner| corner.map(F4::from_array));
        let [e0, e1, e2] = edge_functions(a, b, c);
        let det = e0.add(e1).add(e2);
        let t_scaled = e0.mul(a[2]).add(e1.mul(b[2])).add(e2.mul(c[2]));
        let t = t_scaled.div(det);
        let extent = [0, 1, 2].map(|axis| max_abs(a[axis], b[axis], c[axis]));
        let zero = F4::splat(0.0);
        let positive = zero.lt(t) & !det.eq(zero);
        let settled = clear_of_origin_cheaply((), extent, t_scaled) & positive;
        let beyond = beyond_error_bound((), extent, [e0, e1, e2], det, t);
        assert_eq!(settled & !beyond, 0, "{corners:?}");
        settled_lanes += settled.count_ones();
        // Not a sliver: the projected area at least a tenth of the extent squared.
        let across = extent[0].max(extent[1]);
        let sliver = det.abs().lt(across.mul(across).mul(F4::splat(0.1)));
        let counted = head_on_lanes & positive & !sliver;
        head_on += counted.count_ones();
        head_on_settled += (counted & settled).count_ones();
    }
    assert!(settled_lanes > 20_000, "{settled_lanes} lanes settled");
    assert!(head_on > 5_000, "{head_on}");
    assert!(
        head_on_settled as f64 >= 0.999 * head_on as f64,
        "{head_on_settled} of {head_on} settled"
    );
}

#[test]
fn large_triangles_kept_out_of_cells_are_still_hit() {
    // A small sheet above a ground of two triangles forty times as wide: the grid and
    // the octree test the ground on every ray, from the first run of their slots.
    let (mut positions, mut triangles) = sheet(8);
    let n = positions.len() as u32;
    positions.extend([
        Vec3::new(-160.0, -160.0, -4.0),
        Vec3::new(160.0, -160.0, -4.0),
        Vec3::new(160.0, 160.0, -4.0),
        Vec3::new(-160.0, 160.0, -4.0),
    ]);
    triangles.extend([[n, n + 1, n + 2], [n, n + 2, n + 3]]);
    let mesh = TriangleMesh::new(positions, triangles, vec![], vec![]).unwrap();
    let oracle = mesh.with_accel(AccelKind::None);
    for kind in [AccelKind::Bvh, AccelKind::Grid, AccelKind::Octree] {
        let m = mesh.with_accel(kind);
        let mut ground = 0;
        for i in 0..400 {
            let (x, y) = ((i % 20) as f64 * 1.7 - 12.0, (i / 20) as f64 * 1.7 - 12.0);
            let ray = Ray::new(Vec3::new(x, y, 10.0), Vec3::new(0.01, 0.02, -1.0));
            let name = |m: &TriangleMesh, h: Option<HitRecord>| {
                h.map(|h| (m.source_triangle(h.part), h.t))
            };
            let want = name(&oracle, oracle.intersect(&ray, f64::INFINITY));
            assert_eq!(
                name(&m, m.intersect(&ray, f64::INFINITY)),
                want,
                "{kind}: {i}"
            );
            assert_eq!(
                m.intersect_any(&ray, f64::INFINITY).is_some(),
                want.is_some()
            );
            ground += usize::from(want.is_some_and(|(source, _)| source >= 128));
        }
        assert!(ground > 200, "{kind}: {ground} rays reach the ground");
    }
}

#[test]
fn a_bvh_mesh_takes_at_most_64_bytes_a_triangle() {
    // The budget of the acceleration issue, vertices, indices and nodes included.
    let (positions, triangles) = sheet(100);
    let mesh = TriangleMesh::new(positions, triangles, vec![], vec![])
        .unwrap()
        .with_accel(AccelKind::Bvh);
    let per_triangle = mesh.memory_bytes() as f64 / mesh.triangle_count() as f64;
    assert!(per_triangle <= 64.0, "{per_triangle} bytes a triangle");
}

#[test]
fn mesh_normals_and_validation() {
    let mesh = TriangleMesh::new(
        vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        vec![[0, 1, 2]],
        vec![],
        vec![],
    )
    .unwrap();
    let ray = Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z);
    let hit = mesh.intersect(&ray, 1e9).unwrap();
    assert_eq!(mesh.surface(&ray, &hit).n, Vec3::Z);
    assert!(!mesh.is_closed());
    let tetrahedron = TriangleMesh::new(
        vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        vec![],
        vec![],
    )
    .unwrap();
    assert!(tetrahedron.is_closed());
    assert_eq!(
        TriangleMesh::new(vec![Vec3::ZERO], vec![[0, 1, 2]], vec![], vec![]).unwrap_err(),
        MeshError::IndexOutOfRange {
            triangle: 0,
            index: 1,
            vertices: 1
        }
    );
}
