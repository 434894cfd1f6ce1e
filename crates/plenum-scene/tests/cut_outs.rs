//! Cut-outs and partial shapes in the native format: `alpha` (a number or a texture, an
//! image's alpha channel among them) and `alpha_cutoff` on objects; `z_min`, `z_max`,
//! `inner_radius` and `phi_max` on quadrics; normal and bump maps on physical materials
//! (`normal_map`, `bump`); their located errors, and `plenum convert` writing them back.

mod common;

use common::integrators::{draw, path_settings};
use common::{load_files, png};
use plenum_core::integrator::ColorMode;
use plenum_scene::SceneError;

/// A unit square at z = 0 filling an orthographic view from z = 4, cut by `alpha`, in front
/// of a lamp of radiance 1 at z = −1.
fn scene(alpha: &str) -> String {
    format!(
        r#"[camera]
position = [0, 0, 4]
look_at = [0, 0, 0]
orthographic = 1.0
resolution = [32, 32]

[materials.black]
type = "diffuse"
reflectance = 0.0

[[objects]]
type = "polygon"
name = "lamp"
vertices = [[-5, -5, -1], [5, -5, -1], [5, 5, -1], [-5, 5, -1]]
emission = 1.0

[[objects]]
type = "polygon"
name = "square"
material = "black"
vertices = [[-0.5, -0.5, 0], [0.5, -0.5, 0], [0.5, 0.5, 0], [-0.5, 0.5, 0]]
{alpha}
"#
    )
}

/// A 2 × 2 RGBA image: alpha 0 in its top-left and bottom-right texels, 1 in the others.
fn diagonal_png() -> Vec<u8> {
    png(
        2,
        2,
        4,
        &[0, 0, 0, 0, 9, 9, 9, 255, 9, 9, 9, 255, 0, 0, 0, 0],
    )
}

fn error(toml: &str) -> SceneError {
    match load_files(&[("scene.toml", toml.as_bytes()), ("a.png", &diagonal_png())]) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e,
    }
}

#[test]
fn an_images_alpha_channel_cuts_by_its_cutoff() {
    let text = scene(
        "alpha = { texture = \"image\", file = \"a.png\", channel = \"alpha\" }\nalpha_cutoff = 0.5",
    );
    let l = load_files(&[("scene.toml", text.as_bytes()), ("a.png", &diagonal_png())])
        .unwrap_or_else(|e| panic!("{e}"));
    let image = draw(&l, &path_settings(&l, 1, ColorMode::Rgb, 3));
    let at = |x: usize, y: usize| image[y * 32 + x][1];
    // The image's (0, 0) is its bottom-left, at the polygon's first vertex: its cut texels
    // land on the view's top-left and bottom-right.
    for (x, y, lamp) in [(8, 8, true), (24, 24, true), (24, 8, false), (8, 24, false)] {
        let want = if lamp { 1.0 } else { 0.0 };
        assert!((at(x, y) - want).abs() < 1e-3, "({x}, {y}): {}", at(x, y));
    }
    // Without `channel`, the colour is read: dark everywhere (9/255 or 0), below the cutoff
    // everywhere, so the whole square is cut away.
    let text = scene("alpha = { texture = \"image\", file = \"a.png\" }\nalpha_cutoff = 0.5");
    let l = load_files(&[("scene.toml", text.as_bytes()), ("a.png", &diagonal_png())]).unwrap();
    let image = draw(&l, &path_settings(&l, 1, ColorMode::Rgb, 3));
    assert!(image.iter().all(|p| (p[1] - 1.0).abs() < 1e-3));
}

#[test]
fn a_constant_alpha_is_a_coverage_and_survives_convert() {
    let text = scene("alpha = 0.25");
    let l = load_files(&[("scene.toml", text.as_bytes())]).unwrap();
    // 32 × 32 × 16 samples: σ = √(0.75·0.25/16384) = 0.0034; 5σ.
    let image = draw(&l, &path_settings(&l, 16, ColorMode::Rgb, 3));
    let mean = image.iter().map(|p| p[1] as f64).sum::<f64>() / image.len() as f64;
    assert!((mean - 0.75).abs() < 5.0 * 0.0034, "mean {mean}");
    let written = plenum_scene::to_toml(&l.scene, &l.defaults);
    assert!(written.contains("alpha = 0.25"), "{written}");
    let text = scene(
        "alpha = { texture = \"checker\", even = 1.0, odd = 0.0, scale = 2.0 }\nalpha_cutoff = 0.5",
    );
    let l = load_files(&[("scene.toml", text.as_bytes())]).unwrap();
    let written = plenum_scene::to_toml(&l.scene, &l.defaults);
    assert!(
        written.contains("alpha = { texture = \"checker\"")
            && written.contains("alpha_cutoff = 0.5"),
        "{written}"
    );
}

#[test]
fn bad_alphas_are_located_errors() {
    let at_square = |e: &SceneError, line: usize, what: &str| {
        let s = e.to_string();
        assert!(s.contains(&format!(":{line}:")) && s.contains(what), "{s}");
    };
    // The square's extra keys start on line 22.
    at_square(&error(&scene("alpha = 1.5")), 22, "between 0 and 1");
    at_square(&error(&scene("alpha_cutoff = 0.5")), 22, "needs an `alpha`");
    at_square(
        &error(&scene(
            "alpha = { texture = \"image\", file = \"a.png\", channel = \"red\" }",
        )),
        22,
        "unknown channel",
    );
    let rgb_only = png(1, 1, 3, &[1, 2, 3]);
    let text = scene("alpha = { texture = \"image\", file = \"b.png\", channel = \"alpha\" }");
    let e = match load_files(&[("scene.toml", text.as_bytes()), ("b.png", &rgb_only)]) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e,
    };
    at_square(&e, 22, "no alpha channel");
    // An emitting object cannot be cut out.
    let e = error(&scene("").replace("emission = 1.0", "emission = 1.0\nalpha = 0.5"));
    let s = e.to_string();
    assert!(s.contains(":16:") && s.contains("cannot be cut out"), "{s}");
}

/// A scene of one object after the lamp and material of [`scene`].
fn one(object: &str) -> String {
    format!(
        "[materials.grey]\ntype = \"diffuse\"\n\n[[lights]]\ntype = \"point\"\nposition = [0, 5, 5]\n\n[[objects]]\nmaterial = \"grey\"\n{object}\n"
    )
}

#[test]
fn partial_quadrics_read_render_and_convert() {
    use plenum_core::geometry::Shape;
    let text = one("type = \"sphere\"\nradius = 2\nz_min = -1\nz_max = 1.5\nphi_max = 90");
    let l = load_files(&[("scene.toml", text.as_bytes())]).unwrap();
    let Shape::Sphere(s) = &l.scene.geometry.primitives[0].shape else {
        panic!()
    };
    let p = s.partial.unwrap();
    assert_eq!((p.z_min, p.z_max), (-1.0, 1.5));
    assert!((p.phi_max - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    let written = plenum_scene::to_toml(&l.scene, &l.defaults);
    for key in ["z_min = -1.0", "z_max = 1.5", "phi_max = 90.0"] {
        assert!(written.contains(key), "{key} in {written}");
    }
    let text =
        one("type = \"disk\"\nnormal = [0, 0, 1]\nradius = 2\ninner_radius = 0.5\nphi_max = 270");
    let l = load_files(&[("scene.toml", text.as_bytes())]).unwrap();
    let Shape::Disk(d) = &l.scene.geometry.primitives[0].shape else {
        panic!()
    };
    assert_eq!(d.partial.unwrap().inner_radius, 0.5);
    let written = plenum_scene::to_toml(&l.scene, &l.defaults);
    assert!(
        written.contains("inner_radius = 0.5") && written.contains("phi_max = 270"),
        "{written}"
    );
    for kind in ["cylinder", "cone"] {
        let text = one(&format!(
            "type = \"{kind}\"\ntop = [0, 0, 1]\nradius = 1\nphi_max = 180"
        ));
        let l = load_files(&[("scene.toml", text.as_bytes())]).unwrap();
        let shape = &l.scene.geometry.primitives[0].shape;
        assert!(!shape.is_closed(), "a swept {kind} is open");
        let written = plenum_scene::to_toml(&l.scene, &l.defaults);
        assert!(written.contains("phi_max = 180.0"), "{written}");
    }
    // 360 is the whole turn: nothing is cut, and a closed sphere stays closed.
    let text = one("type = \"sphere\"\nradius = 1\nphi_max = 360");
    let l = load_files(&[("scene.toml", text.as_bytes())]).unwrap();
    assert!(l.scene.geometry.primitives[0].shape.is_closed());
}

#[test]
fn bad_cuts_are_located_errors() {
    let error = |object: &str| match load_files(&[("scene.toml", one(object).as_bytes())]) {
        Ok(_) => panic!("expected an error for {object}"),
        Err(e) => e.to_string(),
    };
    // The object's keys start on line 10; each error points at the key that is wrong.
    for (object, what, line) in [
        (
            "type = \"sphere\"\nradius = 1\nphi_max = 0",
            "phi_max in (0, 360]",
            12,
        ),
        (
            "type = \"sphere\"\nradius = 1\nphi_max = 400",
            "phi_max in (0, 360]",
            12,
        ),
        (
            "type = \"sphere\"\nradius = 1\nz_min = 0.5\nz_max = 0.2",
            "z_max > z_min",
            13,
        ),
        (
            "type = \"disk\"\nnormal = [0, 0, 1]\nradius = 1\ninner_radius = 1",
            "inner_radius below",
            13,
        ),
        (
            "type = \"sphere\"\nradius = 1\nemission = 1.0\nphi_max = 90",
            "cannot be partial",
            13,
        ),
    ] {
        let e = error(object);
        let at = format!("scene.toml:{line}:");
        assert!(e.contains(what) && e.contains(&at), "{object}: {e}");
    }
}

#[test]
fn normal_and_bump_maps_on_physical_materials_turn_the_shading_normal() {
    use plenum_core::math::{Ray, Vec3};
    // The square of `scene` faces +z with u along +x and v along +y, one unit of each.
    let with = |material: &str| {
        scene("").replace(
            "[materials.black]\ntype = \"diffuse\"\nreflectance = 0.0",
            &format!("[materials.black]\ntype = \"diffuse\"\nreflectance = 0.0\n{material}"),
        )
    };
    let tilted = png(1, 1, 3, &[191, 128, 221]);
    let ramp = png(2, 1, 3, &[0, 0, 0, 255, 255, 255]);
    let load = |material: &str| {
        let text = with(material);
        let files = [
            ("scene.toml", text.as_bytes()),
            ("n.png", &tilted[..]),
            ("ramp.png", &ramp[..]),
        ];
        load_files(&files)
    };
    let shading_normal = |material: &str| {
        let l = load(material).unwrap_or_else(|e| panic!("{e}"));
        let ray = Ray::new(Vec3::new(0.0, 0.1, 3.0), -Vec3::Z);
        let (prim, hit) = l.scene.geometry.intersect(&ray, f64::INFINITY).unwrap();
        assert_eq!(l.scene.geometry.names[prim as usize], "square");
        l.scene.geometry.interaction(&ray, prim, &hit).shading_n
    };
    let decode = |b: u8| 2.0 * b as f64 / 255.0 - 1.0;
    let got = shading_normal("normal_map = \"n.png\"");
    let want = Vec3::new(decode(191), decode(128), decode(221)).normalized();
    assert!((got - want).length() < 1e-6, "{got:?} vs {want:?}");
    let got = shading_normal("normal_map = \"n.png\"\nnormal_scale = 0");
    assert!((got - Vec3::Z).length() < 1e-9, "{got:?}");
    // Heights 0 and 1 at u = 0.25 and 0.75, times 0.1: a slope of 0.2 toward +x.
    let got = shading_normal(
        "bump = { texture = \"image\", file = \"ramp.png\", encoding = \"linear\" }\nbump_scale = 0.1",
    );
    let want = Vec3::new(-0.2, 0.0, 1.0).normalized();
    assert!((got - want).length() < 1e-6, "{got:?} vs {want:?}");
    // Located errors.
    for (material, message, line) in [
        ("normal_map = \"n.png\"\nbump = 0.5", "not both", ":11:"),
        ("bump_scale = 2", "without a `bump`", ":10:"),
        (
            "bump = { texture = \"image\", file = \"ramp.png\", encoding = \"gamma\" }",
            "unknown encoding",
            ":10:",
        ),
        ("normal_map = \"missing.png\"", "missing.png", ":10:"),
    ] {
        let Err(e) = load(material) else {
            panic!("{material}: expected an error");
        };
        assert!(
            e.message.contains(message) && e.to_string().contains(line),
            "{material}: {e}"
        );
    }
    // `plenum convert` cannot name the image: it says so on the object.
    let l = load("normal_map = \"n.png\"").unwrap();
    let written = plenum_scene::to_toml(&l.scene, &l.defaults);
    assert!(
        written.contains("normal or bump map is not written"),
        "{written}"
    );
}
