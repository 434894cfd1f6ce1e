//! Scene features end to end: image textures, OBJ files beside the scene, instancing, and
//! refraction between nested media.

use plenum_core::geometry::Shape;
use plenum_core::integrator::RayKind;
use plenum_core::render::{render, trace_pixel, RenderSettings};
use plenum_core::sampling::PixelSampler;
use plenum_core::{Color, Vec3};
use plenum_scene::{load_scene, parse_scene, LoadedScene};
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// A fresh folder per test, removed with what it holds when the test ends.
fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("plenum-scene-{name}-"))
        .tempdir()
        .unwrap()
}

fn settings(l: &LoadedScene) -> RenderSettings {
    RenderSettings {
        width: l.defaults.width,
        height: l.defaults.height,
        sampler: PixelSampler::grid_for(1),
        ..Default::default()
    }
}

/// A 2×2 PNG texture on a square that exactly fills a 2×2 image: each pixel shows its
/// texel, decoded from sRGB to linear.
#[test]
fn image_texture_is_read_relative_to_the_scene_and_decoded_to_linear() {
    let tmp = temp_dir("texture");
    let dir = tmp.path();
    let texels = [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.2, 0.2, 0.2],
    ];
    plenum_image::write_image(&dir.join("tex.png"), 2, 2, &texels, 0.0).unwrap();
    std::fs::write(
        dir.join("scene.toml"),
        r#"
[camera]
position = [0.5, 0.5, 1]
look_at = [0.5, 0.5, 0]
fov = 53.13010235415598
resolution = [2, 2]
[materials.picture]
diffuse = 0
emissive = { texture = "image", file = "tex.png" }
[[objects]]
type = "polygon"
material = "picture"
vertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
"#,
    )
    .unwrap();
    let loaded = load_scene(&dir.join("scene.toml")).unwrap_or_else(|e| panic!("{e}"));
    let film = render(
        &loaded.scene,
        &settings(&loaded),
        &AtomicBool::new(false),
        &|_, _| {},
    )
    .film;
    // One pixel per texel: each pixel centre is a texel centre, where bilinear
    // interpolation returns the texel itself. Top-left is texel 0.
    let at = |x, y| film.get(x, y);
    let near = |c: Color, t: [f32; 3]| {
        (c.r - t[0] as f64).abs() < 0.01
            && (c.g - t[1] as f64).abs() < 0.01
            && (c.b - t[2] as f64).abs() < 0.01
    };
    assert!(near(at(0, 0), texels[0]), "{:?}", at(0, 0));
    assert!(near(at(1, 0), texels[1]), "{:?}", at(1, 0));
    assert!(near(at(0, 1), texels[2]), "{:?}", at(0, 1));
    // 0.2 linear survives the 8-bit sRGB round trip to within a percent.
    assert!(near(at(1, 1), texels[3]), "{:?}", at(1, 1));
}

#[test]
fn obj_meshes_load_beside_the_scene_and_instances_share_them() {
    let tmp = temp_dir("instances");
    let dir = tmp.path();
    std::fs::write(
        dir.join("tri.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nf 1//1 2//2 3//3\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("scene.toml"),
        r#"
[meshes.tri]
file = "tri.obj"
[[objects]]
type = "mesh"
mesh = "tri"
[[objects]]
type = "mesh"
mesh = "tri"
transform = [{ translate = [2, 0, 0] }]
[[objects]]
type = "mesh"
mesh = "tri"
transform = [{ rotate = { axis = [0, 0, 1], degrees = 90 } }, { scale = 3 }]
"#,
    )
    .unwrap();
    let loaded = load_scene(&dir.join("scene.toml")).unwrap_or_else(|e| panic!("{e}"));
    let meshes: Vec<_> = loaded
        .scene
        .geometry
        .primitives
        .iter()
        .map(|p| match &p.shape {
            Shape::Mesh(m) => m.clone(),
            _ => panic!("expected meshes"),
        })
        .collect();
    assert_eq!(meshes.len(), 3);
    assert!(std::sync::Arc::ptr_eq(&meshes[0], &meshes[1]));
    assert!(std::sync::Arc::ptr_eq(&meshes[0], &meshes[2]));
    // Bounds: the third copy is rotated 90° and scaled by 3.
    let b = loaded.scene.geometry.bounds();
    assert!(
        (b.min.x + 3.0).abs() < 1e-9 && (b.max.x - 3.0).abs() < 1e-9,
        "{b:?}"
    );
}

/// A ray through a glass ball holding a water ball: at every interface the refracted ray
/// obeys Snell's law with the indices of the media on either side (glass inside glass).
#[test]
fn nested_media_refract_with_the_right_index_pairs() {
    let loaded = parse_scene(
        Path::new("nested.toml"),
        r#"
[camera]
position = [0, 0, 10]
look_at = [0, 0, 0]
fov = 30
resolution = [41, 41]
[materials.glass]
diffuse = 0
transmissive = 1
ior = 1.5
[materials.water]
diffuse = 0
transmissive = 1
ior = 1.33
[[objects]]
type = "sphere"
name = "glass"
radius = 2
material = "glass"
[[objects]]
type = "sphere"
name = "water"
radius = 1.2
material = "water"
"#,
        Path::new("."),
    )
    .unwrap();
    // A pixel right of centre whose ray crosses both balls off-axis.
    let (tree, _) = trace_pixel(&loaded.scene, &settings(&loaded), 23, 20);
    let chain: Vec<_> = tree
        .nodes
        .iter()
        .filter(|n| matches!(n.kind, RayKind::Camera | RayKind::Refracted))
        .collect();
    let names: Vec<_> = chain
        .iter()
        .map(|n| n.object.clone().unwrap_or_default())
        .collect();
    assert_eq!(
        names,
        ["glass", "water", "water", "glass", ""],
        "path through the balls"
    );
    let radius = |name: &str| if name == "glass" { 2.0 } else { 1.2 };
    let pairs = [(1.0, 1.5), (1.5, 1.33), (1.33, 1.5), (1.5, 1.0)];
    for (i, &(eta_i, eta_t)) in pairs.iter().enumerate() {
        let (incoming, outgoing) = (chain[i], chain[i + 1]);
        let p = outgoing.origin;
        let n = p / radius(&names[i]);
        assert!((p.length() - radius(&names[i])).abs() < 1e-9);
        let sin = |d: Vec3| d.cross(n).length();
        let (si, st) = (sin(incoming.direction), sin(outgoing.direction));
        assert!(si > 0.05, "the test needs oblique incidence");
        assert!(
            (eta_i * si - eta_t * st).abs() < 1e-9,
            "interface {i}: {eta_i}·{si} ≠ {eta_t}·{st}"
        );
    }
}

/// From inside a glass slab, a ray beyond the critical angle (41.8° for η = 1.5) is totally
/// reflected and the refracted weight goes to the reflected ray; below it, it refracts out.
#[test]
fn total_internal_reflection_moves_the_refracted_weight_to_reflection() {
    let slab = |look_at: &str, fresnel: bool| {
        parse_scene(
            Path::new("slab.toml"),
            &format!(
                r#"
[camera]
position = [0, 0, 0]
look_at = {look_at}
up = [0, 0, 1]
resolution = [3, 3]
[materials.glass]
diffuse = 0
transmissive = 0.8
reflective = 0.1
ior = 1.5
fresnel = {fresnel}
[[objects]]
type = "box"
name = "slab"
min = [-100, -1, -100]
max = [100, 1, 100]
material = "glass"
"#
            ),
            Path::new("."),
        )
        .unwrap()
    };
    let children = |tree: &plenum_core::integrator::RayTree, kind| {
        tree.children(0)
            .filter(|&c| tree.nodes[c].kind == kind)
            .count()
    };
    // 84° from the normal: beyond the critical angle.
    let grazing = slab("[10, 1, 0]", false);
    let (tree, _) = trace_pixel(&grazing.scene, &settings(&grazing), 1, 1);
    assert!(tree.nodes[0].total_internal_reflection);
    assert_eq!(children(&tree, RayKind::Refracted), 0);
    let reflected = tree
        .children(0)
        .find(|&c| tree.nodes[c].kind == RayKind::Reflected)
        .unwrap();
    assert!(
        (tree.nodes[reflected].weight.r - 0.9).abs() < 1e-12,
        "k_r + k_t"
    );
    // With Fresnel weights, total internal reflection is reported too, and F = 1 sends
    // the whole reflective tint (white by default) to the reflected ray.
    let fresnel = slab("[10, 1, 0]", true);
    let (tree, _) = trace_pixel(&fresnel.scene, &settings(&fresnel), 1, 1);
    assert!(tree.nodes[0].total_internal_reflection);
    let reflected = tree
        .children(0)
        .find(|&c| tree.nodes[c].kind == RayKind::Reflected)
        .unwrap();
    assert!(
        (tree.nodes[reflected].weight.r - 0.1).abs() < 1e-12,
        "F·k_r with F = 1"
    );
    // 5.7° from the normal: it leaves the glass.
    let steep = slab("[0.1, 1, 0]", false);
    let (tree, _) = trace_pixel(&steep.scene, &settings(&steep), 1, 1);
    assert!(!tree.nodes[0].total_internal_reflection);
    assert_eq!(children(&tree, RayKind::Refracted), 1);
}

/// A glass pane (a polygon: a sheet with no inside) lets a ray through unbent and leaves
/// the medium alone, so a glass ball behind it still refracts from air (η 1) into glass.
#[test]
fn thin_sheets_do_not_change_the_medium() {
    let loaded = parse_scene(
        Path::new("pane.toml"),
        r#"
[camera]
position = [0, 0, 10]
look_at = [0, 0, 0]
fov = 30
resolution = [41, 41]
[materials.glass]
diffuse = 0
transmissive = 1
ior = 1.5
[[objects]]
type = "polygon"
name = "pane"
material = "glass"
vertices = [[-5, -5, 5], [5, -5, 5], [5, 5, 5], [-5, 5, 5]]
[[objects]]
type = "sphere"
name = "ball"
radius = 2
material = "glass"
"#,
        Path::new("."),
    )
    .unwrap();
    let (tree, _) = trace_pixel(&loaded.scene, &settings(&loaded), 25, 20);
    let chain: Vec<_> = tree
        .nodes
        .iter()
        .filter(|n| matches!(n.kind, RayKind::Camera | RayKind::Refracted))
        .collect();
    let names: Vec<_> = chain
        .iter()
        .map(|n| n.object.clone().unwrap_or_default())
        .collect();
    assert_eq!(names, ["pane", "ball", "ball", ""]);
    assert!(
        (chain[1].direction - chain[0].direction).length() < 1e-12,
        "unbent through the pane"
    );
    for (i, (eta_i, eta_t)) in [(1.0, 1.5), (1.5, 1.0)].into_iter().enumerate() {
        let (incoming, outgoing) = (chain[i + 1], chain[i + 2]);
        let n = outgoing.origin / 2.0;
        let sin = |d: Vec3| d.cross(n).length();
        assert!(sin(incoming.direction) > 0.05);
        assert!((eta_i * sin(incoming.direction) - eta_t * sin(outgoing.direction)).abs() < 1e-9);
    }
}

/// A mirror triangle whose vertex normals lean: the reflected ray follows the shading
/// normal, so smooth meshes reflect smoothly.
#[test]
fn mirrors_reflect_about_the_shading_normal() {
    let loaded = parse_scene(
        Path::new("smooth.toml"),
        r#"
[camera]
position = [0, 0, 5]
look_at = [0, 0, 0]
fov = 30
resolution = [3, 3]
[materials.mirror]
diffuse = 0
reflective = 1
[[objects]]
type = "mesh"
material = "mirror"
positions = [[-10, -10, 0], [10, -10, 0], [0, 10, 0]]
normals = [[0.5, 0, 1], [0.5, 0, 1], [0.5, 0, 1]]
indices = [[0, 1, 2]]
"#,
        Path::new("."),
    )
    .unwrap();
    let (tree, _) = trace_pixel(&loaded.scene, &settings(&loaded), 1, 1);
    let reflected = &tree.nodes[tree
        .children(0)
        .find(|&c| tree.nodes[c].kind == RayKind::Reflected)
        .unwrap()];
    let ns = Vec3::new(0.5, 0.0, 1.0).normalized();
    let d = Vec3::new(0.0, 0.0, -1.0);
    let want = d - ns * (2.0 * d.dot(ns));
    assert!(
        (reflected.direction - want).length() < 1e-9,
        "{:?}",
        reflected.direction
    );
}

/// Per-vertex materials follow the vertices they were given to on a mesh its BVH reorders:
/// a strip whose left half's vertices glow red and right half's green, the vertices listed
/// out of order, shows pure red on the left and pure green on the right. (Until 2026-12 the
/// BVH renumbered a mesh's vertices, and the materials landed on the wrong ones.)
#[test]
fn vertex_materials_stay_with_their_vertices() {
    let columns = 33;
    // Vertex (i, j) is listed at `id`: the columns interleaved, odd ones first.
    let id = |i: usize, j: usize| {
        let slot = if i % 2 == 1 {
            i / 2
        } else {
            columns / 2 + i / 2
        };
        2 * slot + j
    };
    let mut positions = vec![String::new(); 2 * columns];
    let mut materials = vec![""; 2 * columns];
    for i in 0..columns {
        let x = -8.0 + 16.0 * i as f64 / (columns - 1) as f64;
        for j in 0..2 {
            positions[id(i, j)] = format!("[{x}, {}, 0]", 2.0 * j as f64 - 1.0);
            materials[id(i, j)] = if x < 0.0 { "\"r\"" } else { "\"g\"" };
        }
    }
    let indices: Vec<String> = (0..columns - 1)
        .flat_map(|i| {
            let (a, b, c, d) = (id(i, 0), id(i + 1, 0), id(i + 1, 1), id(i, 1));
            [format!("[{a}, {b}, {c}]"), format!("[{a}, {c}, {d}]")]
        })
        .collect();
    let text = format!(
        r#"
[camera]
position = [0, 0, 20]
look_at = [0, 0, 0]
fov = 6
resolution = [16, 3]
[materials.r]
diffuse = 0
emissive = [1, 0, 0]
[materials.g]
diffuse = 0
emissive = [0, 1, 0]
[[objects]]
type = "mesh"
positions = [{}]
indices = [{}]
vertex_materials = [{}]
"#,
        positions.join(", "),
        indices.join(", "),
        materials.join(", ")
    );
    let loaded = parse_scene(Path::new("strip.toml"), &text, Path::new("."))
        .unwrap_or_else(|e| panic!("{e}"));
    for x in (0..5).chain(11..16) {
        let (_, c) = trace_pixel(&loaded.scene, &settings(&loaded), x, 1);
        let (want_r, want_g) = if x < 8 { (1.0, 0.0) } else { (0.0, 1.0) };
        assert!(
            (c.r - want_r).abs() < 1e-6 && (c.g - want_g).abs() < 1e-6 && c.b == 0.0,
            "pixel {x}: {c:?}"
        );
    }
}

/// Per-vertex materials blend across a triangle by barycentric weight: at the centroid of a
/// triangle whose corners glow red, green and blue, the colour is one third of each.
#[test]
fn vertex_materials_blend_across_triangles() {
    let loaded = parse_scene(
        Path::new("blend.toml"),
        r#"
[camera]
position = [0, 0, 5]
look_at = [0, 0, 0]
fov = 30
resolution = [3, 3]
[materials.r]
diffuse = 0
emissive = [1, 0, 0]
[materials.g]
diffuse = 0
emissive = [0, 1, 0]
[materials.b]
diffuse = 0
emissive = [0, 0, 1]
[[objects]]
type = "mesh"
positions = [[-3, -3, 0], [6, -3, 0], [-3, 6, 0]]
indices = [[0, 1, 2]]
vertex_materials = ["r", "g", "b"]
"#,
        Path::new("."),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let (_, c) = trace_pixel(&loaded.scene, &settings(&loaded), 1, 1);
    // Triangles are intersected in f32, so barycentric weights carry f32 rounding.
    for v in [c.r, c.g, c.b] {
        assert!((v - 1.0 / 3.0).abs() < 1e-6, "{c:?}");
    }
}

/// An orthographic camera: its rays are parallel, so a ball of radius 1 spans the same
/// 2 / (4 / 64) = 32 pixels of a view 4 units high at any distance (a perspective camera's
/// shrinks with distance); the scene writes back as it reads; the keys that mean nothing
/// to it (a field of view, a lens) are located errors, and so is a height ≤ 0.
#[test]
fn an_orthographic_camera_sees_sizes_at_any_distance_alike() {
    let width_of_ball = |camera: &str| {
        let text = format!(
            "background = [1, 1, 1]\n[camera]\nposition = [0, 0, {camera}\nlook_at = [0, 0, 0]\nresolution = [64, 64]\n\
             [materials.black]\ndiffuse = 0\nambient = 0\n\
             [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"black\"\n"
        );
        let l = parse_scene(Path::new("ortho.toml"), &text, Path::new(".")).unwrap();
        let mut s = settings(&l);
        s.sampler = PixelSampler::new(plenum_core::sampling::SamplerKind::Grid, 1);
        let image = render(&l.scene, &s, &AtomicBool::new(false), &|_, _| {}).film;
        let row = 32;
        let dark = (0..64).filter(|&x| image.get(x, row).g < 0.5).count();
        (dark, l)
    };
    for distance in ["5]\northographic = 4", "50]\northographic = 4"] {
        let (dark, l) = width_of_ball(distance);
        assert_eq!(dark, 32, "{distance}");
        let written = plenum_scene::to_toml(&l.scene, &l.defaults);
        assert!(written.contains("orthographic = 4.0"), "{written}");
        let again = parse_scene(Path::new("again.toml"), &written, Path::new(".")).unwrap();
        assert_eq!(again.scene.camera.orthographic, Some(4.0));
    }
    let (near, _) = width_of_ball("5]\nfov = 53.13");
    let (far, _) = width_of_ball("50]\nfov = 53.13");
    assert!(near > 2 * far, "perspective: {near} pixels near, {far} far");
    for (keys, says) in [
        (
            "orthographic = 4\nfov = 30",
            "an orthographic camera has no `fov`",
        ),
        (
            "orthographic = 4\naperture = 0.1",
            "an orthographic camera has no `aperture`",
        ),
        (
            "orthographic = -1",
            "expected the orthographic view's height",
        ),
    ] {
        let text = format!("[camera]\n{keys}\n");
        let e = parse_scene(Path::new("bad.toml"), &text, Path::new("."))
            .err()
            .unwrap_or_else(|| panic!("{keys}: accepted"))
            .to_string();
        assert!(e.contains(says) && e.contains("bad.toml:"), "{e}");
    }
}

/// An image's `wrap` continues it past its edges, one mode for both axes or one for each;
/// an unknown mode is a located error.
#[test]
fn image_wrap_modes_in_the_native_format() {
    use plenum_core::material::Material;
    use plenum_core::texture::TextureCoords;
    let tmp = temp_dir("wrap");
    let dir = tmp.path();
    plenum_image::write_image(&dir.join("two.png"), 2, 1, &[[0.2; 3], [0.8; 3]], 0.0).unwrap();
    let scene = |wrap: &str| {
        format!(
            r#"[materials.m]
diffuse = {{ texture = "image", file = "two.png", wrap = {wrap} }}
[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 1
material = "m"
"#
        )
    };
    // u = −0.25 and 1.25: the centres of the texels just outside; v = 1.5 outside too.
    for (wrap, want) in [
        (r#""repeat""#, [0.8, 0.2]),
        (r#""clamp""#, [0.2, 0.8]),
        (r#""mirror""#, [0.2, 0.8]),
        (r#""black""#, [0.0, 0.0]),
        (r#"["clamp", "black"]"#, [0.0, 0.0]),
        (r#"["clamp", "repeat"]"#, [0.2, 0.8]),
    ] {
        std::fs::write(dir.join("scene.toml"), scene(wrap)).unwrap();
        let l = load_scene(&dir.join("scene.toml")).unwrap_or_else(|e| panic!("{e}"));
        let Material::Phong(p) =
            &l.scene.materials[l.scene.geometry.primitives[0].material as usize]
        else {
            panic!("expected a Phong material");
        };
        for (u, want) in [-0.25, 1.25].into_iter().zip(want) {
            let at = TextureCoords::new([u, 1.5], Vec3::ZERO);
            let got = p.diffuse.evaluate(&at).g;
            assert!((got - want).abs() < 0.01, "{wrap} at u = {u}: {got}");
        }
    }
    std::fs::write(dir.join("scene.toml"), scene(r#""tile""#)).unwrap();
    let e = match load_scene(&dir.join("scene.toml")) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e,
    };
    assert!(
        e.message.contains("unknown wrap `tile`") && e.to_string().contains(":2:"),
        "{e}"
    );
}

/// The noise, dots, directionmix and mapped textures and a quadric's `uv_map` in the native
/// format; what they take wrongly is a located error.
#[test]
fn mapped_and_procedural_textures_in_the_native_format() {
    use plenum_core::material::Material;
    use plenum_core::texture::{noise, TextureCoords};
    let scene = |diffuse: &str, extra: &str| {
        format!(
            "[materials.m]\ndiffuse = {diffuse}\n[[objects]]\ntype = \"sphere\"\nradius = 1\nmaterial = \"m\"\n{extra}"
        )
    };
    let diffuse = |text: &str| {
        let l = parse_scene(Path::new("scene.toml"), text, Path::new("."))
            .unwrap_or_else(|e| panic!("{e}"));
        let Material::Phong(p) =
            &l.scene.materials[l.scene.geometry.primitives[0].material as usize]
        else {
            panic!("expected a Phong material");
        };
        (p.diffuse.clone(), l)
    };
    // (u, v) scaled by 2 and moved by ½ along u: (0.1, 0.1) is (0.7, 0.2), an even square;
    // (0.3, 0.1) is (1.1, 0.2), an odd one (unmapped, both would be even).
    let (t, _) = diffuse(&scene(
        r#"{ texture = "mapped", mapping = "uv", scale = [2, 2], delta = [0.5, 0], of = { texture = "checker" } }"#,
        "",
    ));
    assert_eq!(
        t.evaluate(&TextureCoords::new([0.1, 0.1], Vec3::ZERO)),
        Color::WHITE
    );
    assert_eq!(
        t.evaluate(&TextureCoords::new([0.3, 0.1], Vec3::ZERO)),
        Color::BLACK
    );
    // fBm in a space moved by (0, 0, 3): looked up at p − (0, 0, 3).
    let (t, _) = diffuse(&scene(
        r#"{ texture = "mapped", mapping = "solid", transform = { translate = [0, 0, 3] }, of = { texture = "fbm", omega = 0.6, octaves = 3 } }"#,
        "",
    ));
    let p = Vec3::new(0.2, 0.7, 3.4);
    let want = noise::fbm(Vec3::new(0.2, 0.7, 0.4), 0.6, 3);
    assert!((t.evaluate(&TextureCoords::new([0.0; 2], p)).r - want).abs() < 1e-12);
    // Dots: red in them, the plane green.
    let (t, _) = diffuse(&scene(
        r#"{ texture = "dots", inside = [1, 0, 0], outside = [0, 1, 0] }"#,
        "",
    ));
    let mut seen = [false; 2];
    for i in 0..400 {
        let uv = [i as f64 * 0.37, i as f64 * 0.11];
        let c = t.evaluate(&TextureCoords::new(uv, Vec3::ZERO));
        seen[(c == Color::new(1.0, 0.0, 0.0)) as usize] = true;
        assert!(
            c == Color::new(1.0, 0.0, 0.0) || c == Color::new(0.0, 1.0, 0.0),
            "{c:?}"
        );
    }
    assert_eq!(seen, [true, true]);
    // A sphere with pbrt's (u, v): +x is (0, ½).
    let (_, l) = diffuse(&scene("[1, 1, 1]", "uv_map = \"pbrt\"\n"));
    assert_eq!(
        l.scene.geometry.primitives[0]
            .shape
            .uv_at(Vec3::new(1.0, 0.0, 0.0), 0),
        [0.0, 0.5]
    );
    for (diffuse, extra, says) in [
        (
            r#"{ texture = "fbm", octaves = 40 }"#,
            "",
            "at most 32 octaves",
        ),
        (
            r#"{ texture = "mapped", mapping = "uv", transform = { translate = [1, 0, 0] }, of = [1, 1, 1] }"#,
            "",
            "the `uv` mapping takes no `transform`",
        ),
        (
            r#"{ texture = "mapped", mapping = "conical", of = [1, 1, 1] }"#,
            "",
            "unknown mapping `conical`",
        ),
        (
            r#"{ texture = "directionmix", textures = [[1, 1, 1]], direction = [0, 1, 0] }"#,
            "",
            "expected two textures or colours, found 1",
        ),
        ("[1, 1, 1]", "uv_map = \"maya\"\n", "unknown uv_map `maya`"),
    ] {
        let e = parse_scene(
            Path::new("bad.toml"),
            &scene(diffuse, extra),
            Path::new("."),
        )
        .err()
        .unwrap_or_else(|| panic!("{diffuse} {extra}: accepted"))
        .to_string();
        assert!(e.contains(says) && e.contains("bad.toml:"), "{e}");
    }
}
