use super::*;
use crate::limits::MAX_NESTING;
use plenum_core::geometry::Shape;
use plenum_core::light::{Attenuation, Light};
use plenum_core::scene::Scene;

fn read(text: &str) -> Result<(Scene, RenderDefaults, Vec<String>), SceneError> {
    parse(Path::new("t.ray"), text, Path::new(".")).map(|(b, d, w)| (b.build(), d, w))
}

fn constant(t: &Texture) -> Color {
    match t {
        Texture::Constant(c) => *c,
        _ => panic!("constant expected"),
    }
}

#[test]
fn lexical_rules() {
    let text = "SBT-raytracer 1.0\r\n/* block\r\ncomment */ // line\r\ncamera { position = (.5, -0.0, 1e-005); aspectratio = 2; }\r\n";
    let (scene, defaults, _) = read(text).unwrap();
    assert_eq!(scene.camera.position, Vec3::new(0.5, 0.0, 1e-5));
    assert_eq!((defaults.width, defaults.height), (512, 256));
    assert!(read("SBT-raytracer 2.0\n")
        .unwrap_err()
        .message
        .contains("version"));
    assert!(read("camera {}\n").unwrap_err().message.contains("header"));
    let e =
        read("SBT-raytracer 1.0\nsphere { material = { diffuse = (1, 1, 1) } } @\n").unwrap_err();
    assert_eq!((e.line, e.column), (2, 47));
}

#[test]
fn dialects_differ_in_reflective_default_and_attenuation() {
    // B: reflective defaults to zero; missing coefficients are 0, 0, 1.
    let b = "SBT-raytracer 1.0\npoint_light { position = (0, 0, 1); colour = (1, 1, 1); constant_attenuation_coeff = 0.25; }\nsphere { material = { specular = (0.5, 0.5, 0.5); shininess = 0.5; }; }\n";
    let (scene, _, _) = read(b).unwrap();
    assert_eq!(
        constant(&scene.materials[0].phong().unwrap().reflective),
        Color::BLACK
    );
    assert_eq!(scene.materials[0].phong().unwrap().shininess, 64.0);
    match &scene.lights[0] {
        Light::Point { attenuation, .. } => assert_eq!(
            (
                attenuation.constant,
                attenuation.linear,
                attenuation.quadratic
            ),
            (0.25, 0.0, 1.0)
        ),
        _ => panic!(),
    }
    // A (a named top-level material): reflective = specular; lights without falloff.
    let a = "SBT-raytracer 1.0\nmaterial { name = \"shiny\"; specular = (0.5, 0.5, 0.5); shininess = 76.8; }\npoint_light { position = (0, 0, 1); color = (1, 1, 1); }\nsphere { material = shiny; }\n";
    let (scene, _, _) = read(a).unwrap();
    assert_eq!(
        constant(&scene.materials[0].phong().unwrap().reflective),
        Color::gray(0.5)
    );
    assert_eq!(scene.materials[0].phong().unwrap().shininess, 76.8);
    match &scene.lights[0] {
        Light::Point { attenuation, .. } => assert_eq!(*attenuation, Attenuation::default()),
        _ => panic!(),
    }
    // A requires a material on every primitive.
    let e = read("SBT-raytracer 1.0\nmaterial { name = m; }\nbox { }\n").unwrap_err();
    assert!(e.message.contains("needs a material"), "{}", e.message);
}

#[test]
fn transforms_nest_outside_in_with_radians() {
    let text = "SBT-raytracer 1.0\ntranslate(10, 0, 0, rotate(0, 0, 1, 1.5707963267948966, scale(2, 1, 1, sphere { })))\n";
    let (scene, _, _) = read(text).unwrap();
    let b = scene.geometry.bounds();
    // Scaled along x to 2, turned onto y, then moved: x in [9, 11], y in [-2, 2].
    assert!(
        (b.min.x - 9.0).abs() < 1e-9 && (b.max.y - 2.0).abs() < 1e-9,
        "{b:?}"
    );
    let m = "SBT-raytracer 1.0\ntransform((1,0,0,5),(0,1,0,0),(0,0,1,0),(0,0,0,1), box { });\n";
    let (scene, _, _) = read(m).unwrap();
    assert!((scene.geometry.bounds().min.x - 4.5).abs() < 1e-12);
}

#[test]
fn meshes_quaternions_and_warnings() {
    let text = "SBT-raytracer 1.0\ncamera { quaternian = (0.7071067811865476, 0, 0.7071067811865476, 0); focus = 3; }\npolymesh { points = ((0,0,0),(1,0,0),(1,1,0),(0,1,0)); faces = ((0,1,2,3)); gennormals; }\n";
    let (scene, _, warnings) = read(text).unwrap();
    // A quarter turn about y: the default −z view becomes −x.
    let view = (scene.camera.look_at - scene.camera.position).normalized();
    assert!((view - -Vec3::X).length() < 1e-9, "{view:?}");
    assert_eq!(warnings.len(), 1);
    assert!(warnings[0].contains("unknown field `focus`"));
    match &scene.geometry.primitives[0].shape {
        Shape::Mesh(m) => assert_eq!(m.triangle_count(), 2),
        _ => panic!(),
    }
    let e = read(
        "SBT-raytracer 1.0\ntrimesh { points = ((0,0,0),(1,0,0),(1,1,0)); faces = ((0,1,3)); }\n",
    )
    .unwrap_err();
    assert!(e.message.contains("out of range"));
    assert_eq!((e.line, e.column), (2, 61));
}

#[test]
fn deep_nesting_is_a_located_error_not_a_stack_overflow() {
    // 100 000 levels overflowed the stack before nesting was bounded.
    for (open, close) in [("translate(0,0,0,", ")"), ("{", "}")] {
        let n = 100_000;
        let text = format!(
            "SBT-raytracer 1.0\nscale(1,{}sphere {{}}{})\n",
            open.repeat(n),
            close.repeat(n)
        );
        let e = read(&text).unwrap_err();
        assert!(e.message.contains("deeper than 256"), "{}", e.message);
        assert_eq!(e.line, 2);
        assert_eq!(e.column, "scale(1,".len() + 255 * open.len() + 1);
    }
    // As deep as allowed still reads.
    let text = format!(
        "SBT-raytracer 1.0\n{}sphere {{}}{}\n",
        "translate(1,0,0,".repeat(MAX_NESTING - 1),
        ")".repeat(MAX_NESTING - 1)
    );
    let (scene, _, _) = read(&text).unwrap();
    assert_eq!(scene.geometry.primitives.len(), 1);
}
