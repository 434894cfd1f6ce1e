//! Normal and bump maps (`scene::Bump`): every shape's ∂p/∂u and ∂p/∂v agree with its (u, v)
//! map, and a map turns the shading normal of hits on a placed object as its texels say.

use plenum_core::color::Color;
use plenum_core::geometry::{
    Cone, Cuboid, Cylinder, Disk, HitRecord, Plane, Polygon, Polyhedron, Shape, Sphere,
    TriangleMesh,
};
use plenum_core::material::{FloatTexture, Material};
use plenum_core::math::{Ray, Transform, Vec3};
use plenum_core::scene::{Bitangent, Bump, SceneBuilder};
use plenum_core::texture::{ImageTexture, Texture};
use std::sync::Arc;

/// Checks ∂p/∂u and ∂p/∂v at the hit of `ray` on `shape` against differences of the
/// shape's own (u, v): a ray from the same origin toward p + h·∂p/∂u must meet the surface
/// where (u, v) has moved by (h, 0), to first order in h.
fn check_derivatives(what: &str, shape: &Shape, ray: Ray) {
    let hit = shape
        .intersect(&ray, f64::INFINITY)
        .unwrap_or_else(|| panic!("{what}: no hit"));
    let g = shape.surface(&ray, &hit, true);
    let dp = shape.uv_derivatives(&hit, &g);
    for (k, d) in dp.iter().enumerate() {
        // Meshes are intersected in f32: a longer step (their map is linear, so exact).
        let h = if matches!(shape, Shape::Mesh(_)) {
            1e-2
        } else {
            1e-6
        };
        let toward = Ray::new(ray.origin, g.p + *d * h - ray.origin);
        let hit2: HitRecord = shape
            .intersect(&toward, f64::INFINITY)
            .unwrap_or_else(|| panic!("{what}: the shifted ray misses"));
        assert_eq!(hit2.part, hit.part, "{what}: another part");
        let g2 = shape.surface(&toward, &hit2, true);
        let du = [(g2.uv[0] - g.uv[0]) / h, (g2.uv[1] - g.uv[1]) / h];
        let want = if k == 0 { [1.0, 0.0] } else { [0.0, 1.0] };
        for a in 0..2 {
            assert!(
                (du[a] - want[a]).abs() < 1e-3,
                "{what}: ∂(u, v)/∂{} along ∂p/∂{}: {du:?}",
                ["u", "v"][a],
                ["u", "v"][k]
            );
        }
    }
}

fn from(o: [f64; 3], to: [f64; 3]) -> Ray {
    let o = Vec3::new(o[0], o[1], o[2]);
    Ray::new(o, Vec3::new(to[0], to[1], to[2]) - o)
}

#[test]
fn every_shapes_uv_derivatives_follow_its_uv_map() {
    let sphere = Shape::Sphere(Sphere::new(Vec3::new(0.5, -0.2, 0.1), 1.5));
    check_derivatives("sphere", &sphere, from([3.0, 1.0, 4.0], [0.5, 0.0, 0.0]));
    let plane = Shape::Plane(Plane::new(
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::new(0.2, 0.3, 1.0).normalized(),
    ));
    check_derivatives("plane", &plane, from([0.3, 0.4, 3.0], [0.1, 0.0, -1.0]));
    let disk = Shape::Disk(Disk::new(Vec3::new(1.0, 0.0, 0.0), Vec3::Y, 2.0));
    check_derivatives("disk", &disk, from([0.0, 3.0, 0.5], [1.7, 0.0, 0.6]));
    let cuboid = Shape::Cuboid(Cuboid::new(
        Vec3::new(-1.0, -2.0, -0.5),
        Vec3::new(2.0, 1.0, 3.0),
    ));
    check_derivatives("cuboid", &cuboid, from([5.0, 0.2, 0.4], [0.0, -0.3, 1.2]));
    check_derivatives(
        "cuboid top",
        &cuboid,
        from([0.2, 0.1, 9.0], [0.4, -0.5, 0.0]),
    );
    let cylinder = Shape::Cylinder(Cylinder::new(1.0, 2.0, true));
    check_derivatives(
        "cylinder",
        &cylinder,
        from([4.0, 1.0, 0.7], [0.0, 0.0, 1.1]),
    );
    check_derivatives(
        "cylinder cap",
        &cylinder,
        from([0.2, 0.3, 6.0], [0.1, -0.2, 2.0]),
    );
    let cone = Shape::Cone(Cone {
        radius0: 1.5,
        radius1: 0.5,
        height: 2.0,
        capped: false,
        inside_only: false,
        partial: None,
    });
    check_derivatives("cone", &cone, from([4.0, 2.0, 1.0], [0.0, 0.0, 0.8]));
    let square = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
    let polygon = Polygon::new(square.map(|[x, y]| Vec3::new(x, y, 0.5)).to_vec()).unwrap();
    check_derivatives(
        "polygon",
        &Shape::Polygon(Box::new(polygon)),
        from([0.2, 0.3, 4.0], [-0.3, 0.2, 0.5]),
    );
    let corners: Vec<Vec3> = (0..8)
        .map(|i| Vec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
        .collect();
    let faces = vec![
        vec![0, 2, 3, 1],
        vec![4, 5, 7, 6],
        vec![0, 1, 5, 4],
        vec![2, 6, 7, 3],
        vec![0, 4, 6, 2],
        vec![1, 3, 7, 5],
    ];
    let cube = Polyhedron::new(&corners, &faces).unwrap();
    check_derivatives(
        "polyhedron",
        &Shape::Polyhedron(Box::new(cube)),
        from([0.4, 0.3, 5.0], [0.5, 0.6, 0.5]),
    );
    // A mesh whose uvs are turned, stretched and mirrored against its positions, and one
    // without uvs.
    let positions = vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(2.0, 0.0, 0.5),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let uvs = vec![[0.3, 0.2], [0.1, 0.9], [-0.8, 0.0]];
    let mesh = TriangleMesh::new(positions.clone(), vec![[0, 1, 2]], vec![], uvs).unwrap();
    check_derivatives(
        "mesh",
        &Shape::Mesh(Arc::new(mesh)),
        from([0.5, 0.3, 3.0], [0.5, 0.3, 0.0]),
    );
    let bare = TriangleMesh::new(positions, vec![[0, 1, 2]], vec![], vec![]).unwrap();
    check_derivatives(
        "mesh without uvs",
        &Shape::Mesh(Arc::new(bare)),
        from([0.5, 0.3, 3.0], [0.5, 0.3, 0.0]),
    );
}

/// One texel that encodes the unit normal `n` (each component c as (1 + c)/2).
fn normal_texel(n: Vec3) -> Arc<ImageTexture> {
    let c = Color::new((1.0 + n.x) / 2.0, (1.0 + n.y) / 2.0, (1.0 + n.z) / 2.0);
    Arc::new(ImageTexture::new(1, 1, vec![c], [1.0, 1.0]).unwrap())
}

#[test]
fn a_normal_map_turns_the_shading_normal_of_a_placed_object_in_its_tangent_frame() {
    // A square in the xy plane with u along x and v along y, turned 90° about z and moved:
    // u then runs along world y and v along −x. A normal tilted 30° toward +u in tangent
    // space is tilted toward world +y; the geometric normal stays.
    let (s, c) = (0.5f64, 0.75f64.sqrt());
    let mut b = SceneBuilder::default();
    let m = b.add_material("bumped", Material::default());
    b.set_bump(
        m,
        Bump::NormalMap {
            image: normal_texel(Vec3::new(s, 0.0, c)),
            scale: 1.0,
            bitangent: Bitangent::AlongV,
        },
    );
    let plain = b.add_material("plain", Material::default());
    let quad = |z: f64| {
        let positions = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
            .map(|[x, y]| Vec3::new(x, y, z))
            .to_vec();
        let uvs = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let mesh = TriangleMesh::new(positions, vec![[0, 1, 2], [0, 2, 3]], vec![], uvs);
        Shape::Mesh(Arc::new(mesh.unwrap()))
    };
    let place = Transform::translate(Vec3::new(3.0, 0.0, 0.0))
        .after(&Transform::rotate(Vec3::Z, 90.0).unwrap());
    b.add_object("bumped", quad(0.0), place, m);
    b.add_object("plain", quad(-1.0), place, plain);
    let scene = b.build();
    let ray = Ray::new(Vec3::new(2.5, 0.5, 4.0), -Vec3::Z);
    let (prim, hit) = scene.geometry.intersect(&ray, f64::INFINITY).unwrap();
    let it = scene.geometry.interaction(&ray, prim, &hit);
    assert!((it.n - Vec3::Z).length() < 1e-12, "{:?}", it.n);
    let want = Vec3::new(0.0, s, c);
    assert!((it.shading_n - want).length() < 1e-9, "{:?}", it.shading_n);
    // Objects of other materials keep their normals.
    let below = Ray::new(Vec3::new(2.5, 0.5, -0.5), -Vec3::Z);
    let (prim, hit) = scene.geometry.intersect(&below, f64::INFINITY).unwrap();
    let it = scene.geometry.interaction(&below, prim, &hit);
    assert_eq!(scene.geometry.names[prim as usize], "plain");
    assert!((it.shading_n - Vec3::Z).length() < 1e-12);
}

#[test]
fn a_bump_map_on_a_sphere_tilts_the_normal_by_the_heights_slope() {
    // A height that grows with v (from the north pole down) on a sphere of radius 2: at the
    // equator ∂p/∂v has length π·r, so a height slope dh/dv = k tilts the normal by
    // atan(k / (π r)) toward the north pole (up, +y).
    let r = 2.0;
    let k = 0.6;
    // A solid texture would do as well; a 2 × 1 image with texels at v = 0.25 and 0.75
    // (rows from the top, so the first row is v = 0.75) is linear in v between them.
    let ramp = ImageTexture::new(
        1,
        2,
        vec![Color::gray(0.75 * k), Color::gray(0.25 * k)],
        [1.0, 1.0],
    )
    .unwrap();
    let mut b = SceneBuilder::default();
    let m = b.add_material("bumped", Material::default());
    b.set_bump(
        m,
        Bump::HeightMap {
            height: FloatTexture::Texture(Texture::Image(Arc::new(ramp))),
            scale: 1.0,
        },
    );
    b.add_object(
        "ball",
        Shape::Sphere(Sphere::new(Vec3::ZERO, r)),
        Transform::IDENTITY,
        m,
    );
    let scene = b.build();
    let ray = Ray::new(Vec3::new(0.0, 0.0, 10.0), -Vec3::Z);
    let (prim, hit) = scene.geometry.intersect(&ray, f64::INFINITY).unwrap();
    let it = scene.geometry.interaction(&ray, prim, &hit);
    let tilt = (k / (std::f64::consts::PI * r)).atan();
    let want = Vec3::new(0.0, tilt.sin(), tilt.cos());
    assert!(
        (it.shading_n - want).length() < 1e-6,
        "{:?} vs {want:?}",
        it.shading_n
    );
}
