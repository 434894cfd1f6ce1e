//! Mitsuba 3's XML scenes (`plenum render scene.xml`): the parser's semantics, the plugins'
//! mapping, handedness, located errors and warnings, and the six feature scenes of
//! ../shared/data/references/features read as their hand-made native ports.

mod common;

use common::{bright_centre, load_files, native, number, png};

use common::integrators::{draw, path_settings};
use plenum_core::integrator::ColorMode;
use plenum_scene::{load_scene, LoadedScene, SceneError};
use std::path::{Path, PathBuf};
use toml::{Table, Value};

fn load(text: &str) -> LoadedScene {
    load_files(&[("scene.xml", text.as_bytes())]).unwrap_or_else(|e| panic!("{e}"))
}

fn error(text: &str) -> SceneError {
    match load_files(&[("scene.xml", text.as_bytes())]) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e,
    }
}

fn scene(body: &str) -> String {
    format!("<scene version=\"3.0.0\">\n{body}\n</scene>\n")
}

/// A scene with a camera and a sky, so that only what is tested is warned about.
fn lit(body: &str) -> String {
    scene(&format!(
        "<sensor type=\"perspective\"/><emitter type=\"constant\"/>\n{body}"
    ))
}

/// The material table of object `i`.
fn material_of(t: &Table, i: usize) -> &Table {
    let name = t["objects"][i]["material"].as_str().unwrap();
    t["materials"][name].as_table().unwrap()
}

/// Whether two written scenes agree: numbers within 1e-6 (relative), files by their
/// canonical path, each object's material by value (the names may differ, and a port may
/// hold materials nothing uses).
fn same(a: &Value, b: &Value, at: &str) -> Result<(), String> {
    match (a, b) {
        (Value::Table(x), Value::Table(y)) => {
            let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
            for k in keys {
                match (x.get(k), y.get(k)) {
                    (Some(p), Some(q)) => same(p, q, &format!("{at}.{k}"))?,
                    _ => return Err(format!("{at}.{k}: in one scene only")),
                }
            }
            Ok(())
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => {
            for (i, (p, q)) in x.iter().zip(y).enumerate() {
                same(p, q, &format!("{at}[{i}]"))?;
            }
            Ok(())
        }
        (Value::String(x), Value::String(y)) => {
            let canonical = |s: &str| std::fs::canonicalize(s).ok();
            if x == y || (canonical(x).is_some() && canonical(x) == canonical(y)) {
                Ok(())
            } else {
                Err(format!("{at}: {x:?} and {y:?}"))
            }
        }
        (Value::Integer(_) | Value::Float(_), Value::Integer(_) | Value::Float(_)) => {
            let (p, q) = (number(a), number(b));
            if (p - q).abs() <= 1e-6 * p.abs().max(q.abs()).max(1.0) {
                Ok(())
            } else {
                Err(format!("{at}: {p} and {q}"))
            }
        }
        _ if a == b => Ok(()),
        _ => Err(format!("{at}: {a} and {b}")),
    }
}

/// `t` with each object's material written into it and the material list dropped.
fn by_value(mut t: Table) -> Table {
    let materials = t.remove("materials").unwrap();
    if let Some(Value::Array(objects)) = t.get_mut("objects") {
        for o in objects {
            let o = o.as_table_mut().unwrap();
            let m = materials[o["material"].as_str().unwrap()].clone();
            o.insert("material".into(), m);
        }
    }
    t
}

#[test]
fn the_feature_scenes_import_as_their_native_ports() {
    let features =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/references/features");
    if !features.is_dir() {
        common::missing("../shared/data/references/features");
        return;
    }
    for name in ["specular", "rough", "mis", "env", "delta", "lens"] {
        let xml =
            load_scene(&features.join(name).join("scene.xml")).unwrap_or_else(|e| panic!("{e}"));
        let port = load_scene(
            &Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("tests/references")
                .join(format!("{name}.toml")),
        )
        .unwrap();
        let (a, b) = (by_value(native(&xml)), by_value(native(&port)));
        if let Err(e) = same(&Value::Table(a), &Value::Table(b), name) {
            panic!("{name}: the XML and its port differ at {e}");
        }
        // Every property of these scenes has a counterpart: nothing is ignored.
        assert!(xml.warnings.is_empty(), "{name}: {:?}", xml.warnings);
    }
}

#[test]
fn defaults_substitutions_includes_and_forward_references() {
    let main = scene(
        r#"<default name="radius" value="0.25"/>
        <default name="kind" value="diffuse"/>
        <shape type="sphere" id="ball">
            <float name="radius" value="$radius"/>
            <point name="center" value="1, 2, 3"/>
            <ref id="paint"/>
        </shape>
        <bsdf type="$kind" id="paint">
            <rgb name="reflectance" value="0.1 0.2 0.3"/>
        </bsdf>
        <include filename="more.xml"/>"#,
    );
    let more = scene(
        r#"<shape type="disk" id="floor"><bsdf type="twosided"><bsdf type="diffuse"/></bsdf></shape>"#,
    );
    let l = load_files(&[("main.xml", main.as_bytes()), ("more.xml", more.as_bytes())])
        .unwrap_or_else(|e| panic!("{e}"));
    let t = native(&l);
    let objects = t["objects"].as_array().unwrap();
    assert_eq!(objects.len(), 2);
    assert_eq!(objects[0]["name"].as_str(), Some("ball"));
    assert_eq!(number(&objects[0]["radius"]), 0.25);
    let center: Vec<f64> = objects[0]["center"]
        .as_array()
        .unwrap()
        .iter()
        .map(number)
        .collect();
    assert_eq!(center, [1.0, 2.0, 3.0]);
    let paint = material_of(&t, 0);
    assert_eq!(paint["type"].as_str(), Some("diffuse"));
    let r: Vec<f64> = paint["reflectance"]
        .as_array()
        .unwrap()
        .iter()
        .map(number)
        .collect();
    assert_eq!(r, [0.1, 0.2, 0.3]);
    // One-sided, as Mitsuba's BSDFs are; the included floor is wrapped in twosided.
    assert_eq!(paint["two_sided"].as_bool(), Some(false));
    assert_eq!(objects[1]["name"].as_str(), Some("floor"));
    assert_ne!(
        material_of(&t, 1).get("two_sided").and_then(Value::as_bool),
        Some(false)
    );
}

#[test]
fn transforms_compose_in_the_order_written() {
    // Translate, then scale by 2: the unit rectangle's corner (1, 1, 0) lands at (4, 2, 0).
    let l = load(&scene(
        r#"<shape type="rectangle"><transform name="to_world">
            <translate x="1"/><scale value="2"/>
        </transform></shape>"#,
    ));
    let b = l.scene.geometry.bounds();
    assert!(
        (b.max.x - 4.0).abs() < 1e-12 && (b.max.y - 2.0).abs() < 1e-12,
        "{b:?}"
    );
    assert!(
        (b.min.x - 0.0).abs() < 1e-12 && (b.min.y + 2.0).abs() < 1e-12,
        "{b:?}"
    );
    // Rotations are right-handed: +x turned 90° about +z is +y.
    let l = load(&scene(
        r#"<shape type="sphere"><point name="center" x="1" y="0" z="0"/><float name="radius" value="0.1"/>
            <transform name="to_world"><rotate z="1" angle="90"/></transform></shape>"#,
    ));
    let b = l.scene.geometry.bounds();
    let c = (b.min + b.max) * 0.5;
    assert!(c.x.abs() < 1e-9 && (c.y - 1.0).abs() < 1e-9, "{c:?}");
}

#[test]
fn the_camera_keeps_mitsubas_handedness() {
    // Mitsuba's look-at frame has +x to the left of the view: looking along +z with +y up,
    // a lamp at x = +1 appears in the image's left half, one at y = +1 in its top half.
    let picture = |x: f64, y: f64, mirror: &str| {
        let l = load(&scene(&format!(
            r#"<sensor type="perspective">
                <float name="fov" value="60"/>
                <transform name="to_world">{mirror}<lookat origin="0 0 0" target="0 0 1" up="0 1 0"/></transform>
                <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/></film>
            </sensor>
            <shape type="sphere"><point name="center" x="{x}" y="{y}" z="4"/><float name="radius" value="0.5"/>
                <emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>"#
        )));
        let image = draw(&l, &path_settings(&l, 1, ColorMode::Rgb, 7));
        bright_centre(&image, 32)
    };
    let (x, y) = picture(1.0, 0.0, "");
    assert!(
        x < 12.0 && (y - 15.5).abs() < 2.0,
        "a lamp at +x lands at ({x}, {y})"
    );
    let (x, y) = picture(0.0, 1.0, "");
    assert!(
        (x - 15.5).abs() < 2.0 && y < 12.0,
        "a lamp at +y lands at ({x}, {y})"
    );
    // A sensor frame mirrored in its own x: the mirror image, as Mitsuba renders it.
    let (x, y) = picture(1.0, 0.0, r#"<scale x="-1"/>"#);
    assert!(
        x > 20.0 && (y - 15.5).abs() < 2.0,
        "mirrored, a lamp at +x lands at ({x}, {y})"
    );
}

#[test]
fn integrators_films_and_samplers_become_the_render_defaults() {
    let l = load(&scene(
        r#"<integrator type="path"><integer name="max_depth" value="6"/><integer name="rr_depth" value="4"/></integrator>
        <sensor type="thinlens">
            <float name="fov" value="30"/><string name="fov_axis" value="x"/>
            <float name="aperture_radius" value="0.1"/><float name="focus_distance" value="5"/>
            <sampler type="stratified"><integer name="sample_count" value="64"/></sampler>
            <film type="hdrfilm"><integer name="width" value="200"/><integer name="height" value="100"/>
                <rfilter type="tent"/></film>
        </sensor>"#,
    ));
    let d = &l.defaults;
    assert_eq!((d.width, d.height, d.spp), (200, 100, 64));
    assert_eq!((d.max_depth, d.rr_depth), (4, 2), "Mitsuba's depths less 2");
    assert_eq!(d.sampler, plenum_core::sampling::SamplerKind::Jittered);
    assert_eq!(d.filter, plenum_core::sampling::FilterKind::Tent);
    let t = native(&l);
    let camera = t["camera"].as_table().unwrap();
    assert_eq!(number(&camera["aperture"]), 0.1);
    assert_eq!(number(&camera["focus_distance"]), 5.0);
    // 30° across a 2:1 image: tan(v/2) = tan(15°)/2.
    let v = number(&camera["fov"]);
    assert!(((0.5 * v).to_radians().tan() - 15f64.to_radians().tan() / 2.0).abs() < 1e-9);
    // No film: Mitsuba's 768 × 576 and Gaussian filter; `direct` is Plenum's depth 0.
    let l = load(&scene(
        r#"<integrator type="direct"/><sensor type="perspective"/>"#,
    ));
    assert_eq!(
        (l.defaults.width, l.defaults.height, l.defaults.max_depth),
        (768, 576, 0)
    );
}

#[test]
fn materials_map_with_mitsubas_names_and_defaults() {
    let l = load(&scene(
        r#"<shape type="sphere"><bsdf type="dielectric"><string name="int_ior" value="water"/></bsdf></shape>
        <shape type="sphere"><bsdf type="conductor"><string name="material" value="Au"/></bsdf></shape>
        <shape type="sphere"><bsdf type="conductor"/></shape>
        <shape type="sphere"><bsdf type="roughconductor"><string name="distribution" value="ggx"/>
            <float name="alpha_u" value="0.3"/><float name="alpha_v" value="0.05"/></bsdf></shape>
        <shape type="sphere"><bsdf type="blendbsdf"><float name="weight" value="0.25"/>
            <bsdf type="diffuse"/><bsdf type="conductor"/></bsdf></shape>
        <shape type="sphere"/>"#,
    ));
    let t = native(&l);
    let water = material_of(&t, 0);
    assert!((number(&water["eta"]) - 1.3330 / 1.00028).abs() < 1e-12);
    // Gold's measured η and k, as the native format's `metal = "Au"` reads them.
    let gold = common::integrators::scene(
        "[materials.m]\ntype = \"conductor\"\nmetal = \"Au\"\n[[objects]]\ntype = \"sphere\"\nradius = 1\nmaterial = \"m\"\n",
    );
    let gold = native(&gold);
    let (a, b) = (material_of(&t, 1), material_of(&gold, 0));
    same(&a["eta"], &b["eta"], "eta").unwrap();
    same(&a["k"], &b["k"], "k").unwrap();
    // Mitsuba's default conductor is a perfect mirror.
    let r: Vec<f64> = material_of(&t, 2)["reflectance"]
        .as_array()
        .unwrap()
        .iter()
        .map(number)
        .collect();
    assert_eq!(r, [1.0, 1.0, 1.0]);
    let rough: Vec<f64> = material_of(&t, 3)["roughness"]
        .as_array()
        .unwrap()
        .iter()
        .map(number)
        .collect();
    assert!(
        (rough[0] - 0.3).abs() < 1e-12 && (rough[1] - 0.05).abs() < 1e-12,
        "{rough:?}"
    );
    assert_eq!(material_of(&t, 3)["remap_roughness"].as_bool(), Some(false));
    let mix = material_of(&t, 4);
    assert_eq!(mix["type"].as_str(), Some("mix"));
    assert_eq!(number(&mix["amount"]), 0.25);
    // A shape without a BSDF: diffuse 0.5, one-sided.
    let bare = material_of(&t, 5);
    assert_eq!(bare["type"].as_str(), Some("diffuse"));
    assert_eq!(bare["two_sided"].as_bool(), Some(false));
}

#[test]
fn version_0_6_names_are_upgraded() {
    let l = load(
        r#"<scene version="0.6.0"><sensor type="perspective"/><emitter type="constant"/>
            <shape type="sphere"><bsdf type="dielectric"><float name="intIOR" value="1.33"/><float name="extIOR" value="1"/></bsdf></shape>
            <shape type="sphere"><bsdf type="diffuse"><rgb name="diffuseReflectance" value="0.2"/></bsdf></shape>
        </scene>"#,
    );
    let t = native(&l);
    assert!((number(&material_of(&t, 0)["eta"]) - 1.33).abs() < 1e-12);
    let r: Vec<f64> = material_of(&t, 1)["reflectance"]
        .as_array()
        .unwrap()
        .iter()
        .map(number)
        .collect();
    assert_eq!(r, [0.2, 0.2, 0.2]);
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
}

#[test]
fn errors_name_the_line_and_column() {
    let e = error(&scene(
        r#"<shape type="sphere"><float name="radius" value="$r"/></shape>"#,
    ));
    assert_eq!((e.line, e.column), (2, 50), "{e}");
    assert!(e.message.contains("undefined parameter `$r`"), "{e}");

    let e = error(&scene(
        r#"<shape type="sphere"><flaot name="radius" value="1"/></shape>"#,
    ));
    assert_eq!((e.line, e.column), (2, 22), "{e}");
    assert!(e.to_string().contains("did you mean <float>?"), "{e}");

    let e = error(&scene(
        r#"<shape type="sphere"><ref id="nowhere"/></shape>"#,
    ));
    assert!(e.message.contains("no object has the id `nowhere`"), "{e}");

    let e = error("<scene>\n</scene>");
    assert!(e.message.contains("version"), "{e}");

    let e = error(&scene(
        r#"<shape type="sphere"><float name="radius" value="1"></shape>"#,
    ));
    assert_eq!(e.line, 2, "{e}");
    assert!(e.message.contains("malformed XML"), "{e}");

    let e = error(&scene(
        r#"<shape type="sphere"><float name="radius" value="-1"/></shape>"#,
    ));
    assert!(e.message.contains("expected `radius` > 0"), "{e}");

    let e = error(&scene(
        r#"<bsdf type="blendbsdf" id="loop"><ref id="loop"/><bsdf type="diffuse"/></bsdf>
        <shape type="sphere"><ref id="loop"/></shape>"#,
    ));
    assert!(e.message.contains("contains itself"), "{e}");

    let e = error(&scene(
        r#"<include filename="scene.xml"/><include filename="scene.xml"/>"#,
    ));
    assert!(e.message.contains("includes itself"), "{e}");

    let e = error(&scene(r#"<include filename="missing.xml"/>"#));
    assert!(e.message.contains("cannot read the included file"), "{e}");
}

#[test]
fn what_plenum_lacks_is_warned_where_it_is_written() {
    let l = load(&lit(r#"<shape type="sphere">
            <bsdf type="roughconductor"><float name="alpha" value="0.2"/></bsdf>
            <float name="sparkle" value="1"/>
        </shape>
        <medium type="homogeneous" id="fog"/>
        <shape type="bsplinecurve"><string name="filename" value="x.txt"/></shape>"#));
    let all = l.warnings.join("\n");
    assert_eq!(l.warnings.len(), 4, "{all}");
    assert!(all.contains(":4:13") && all.contains("Beckmann"), "{all}");
    assert!(
        all.contains(":5:13") && all.contains("`sparkle` of the shape `sphere` is not supported"),
        "{all}"
    );
    assert!(
        all.contains(":7:9") && all.contains("<medium> is not supported"),
        "{all}"
    );
    assert!(
        all.contains(":8:9") && all.contains("`bsplinecurve` shape is not supported"),
        "{all}"
    );
}

/// Mitsuba's orthographic sensor: [−1, 1] across x of its frame, scaled by its transform,
/// the film's aspect along y. A black ball of radius 0.5 at x = 1 under a white sky, seen
/// through a view 4 wide (scale 2) on a 64 × 32 film, darkens columns 40 to 55 of the middle
/// row, as Mitsuba 3.9.1's own render of this file does (`scalar_rgb`, checked 7 December
/// 2026).
#[test]
fn the_orthographic_sensor_sees_what_mitsuba_sees() {
    let l = load(
        r#"<scene version="3.0.0">
  <sensor type="orthographic">
    <transform name="to_world"><scale x="2" y="2"/><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="32"/><rfilter type="box"/></film>
  </sensor>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <shape type="sphere"><point name="center" x="1" y="0" z="0"/><float name="radius" value="0.5"/><bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf></shape>
</scene>"#,
    );
    assert_eq!(l.scene.camera.orthographic, Some(2.0));
    let image = draw(&l, &path_settings(&l, 4, ColorMode::Rgb, 1));
    let dark: Vec<usize> = (0..64).filter(|&x| image[16 * 64 + x][1] < 0.5).collect();
    assert_eq!(
        (dark.first(), dark.last(), dark.len()),
        (Some(&40), Some(&55), 16)
    );
}

/// A `mask` BSDF cuts its shapes out by its opacity (a coverage), also inside a `twosided`:
/// a black rectangle filling an orthographic view, of opacity 0.25, in front of a lamp of
/// radiance 1 lets three quarters of the rays reach the lamp.
#[test]
fn a_mask_cuts_its_shapes_out_by_opacity() {
    let picture = |bsdf: &str| {
        load(&format!(
            r#"<scene version="3.0.0">
  <sensor type="orthographic">
    <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/><rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle">
    <transform name="to_world"><scale value="10"/><translate z="-1"/></transform>
    <emitter type="area"><rgb name="radiance" value="1"/></emitter>
  </shape>
  <shape type="rectangle">{bsdf}</shape>
</scene>"#
        ))
    };
    let black = r#"<bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>"#;
    for bsdf in [
        format!(r#"<bsdf type="mask"><float name="opacity" value="0.25"/>{black}</bsdf>"#),
        format!(
            r#"<bsdf type="twosided"><bsdf type="mask"><float name="opacity" value="0.25"/>{black}</bsdf></bsdf>"#
        ),
        // Masks nested: 0.5 × 0.5.
        format!(
            r#"<bsdf type="mask"><float name="opacity" value="0.5"/><bsdf type="mask"><float name="opacity" value="0.5"/>{black}</bsdf></bsdf>"#
        ),
    ] {
        let l = picture(&bsdf);
        assert!(l.warnings.is_empty(), "{:?}", l.warnings);
        // 32 × 32 × 16 = 16,384 samples: σ = √(0.75·0.25/16384) = 0.0034; 5σ.
        let image = draw(&l, &path_settings(&l, 16, ColorMode::Rgb, 3));
        let mean = image.iter().map(|p| p[1] as f64).sum::<f64>() / image.len() as f64;
        assert!((mean - 0.75).abs() < 5.0 * 0.0034, "{bsdf}: mean {mean}");
    }
    // Without a mask the rectangle hides the lamp.
    let l = picture(black);
    let image = draw(&l, &path_settings(&l, 1, ColorMode::Rgb, 3));
    assert!(image.iter().all(|p| p[1] == 0.0));
    // A texture is an opacity too; an opacity above 1 is an error where it is written.
    let l = picture(&format!(
        r#"<bsdf type="mask"><texture type="checkerboard" name="opacity"/>{black}</bsdf>"#
    ));
    let alpha = l.scene.geometry.primitives.last().unwrap().alpha.as_ref();
    assert!(alpha.is_some_and(|a| a.needs_uv() && a.cutoff.is_none()));
    let e = error(&scene(&format!(
        r#"<shape type="rectangle"><bsdf type="mask">
  <float name="opacity" value="1.5"/>{black}</bsdf></shape>"#
    )));
    assert!(
        e.message.contains("between 0 and 1") && e.to_string().contains(":3:3"),
        "{e}"
    );
}

/// `normalmap` and `bumpmap` turn the shading normal: a diffuse rectangle facing an
/// orthographic camera, lit only by a directional light from 30° toward +x (one sample per
/// pixel is exact), is brighter by cos(30° − τ)/cos 30° under a normal tilted by τ toward
/// +u. Mitsuba 3.9.1 itself renders 1.1461 where this closed form gives 1.1516, its own
/// frame being the same (x along ∂p/∂u) but its normal map's response at oblique angles
/// slightly less; a bump of slope 1 away from the light, 0.2958 for cos 75°/cos 30° =
/// 0.2989.
#[test]
fn normal_and_bump_maps_turn_the_shading_normal() {
    let picture = |bsdf: &str| {
        let text = format!(
            r#"<scene version="3.0.0">
  <sensor type="orthographic">
    <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film>
  </sensor>
  <emitter type="directional"><vector name="direction" value="-0.5, 0, {z}"/><rgb name="irradiance" value="1"/></emitter>
  <shape type="rectangle">{bsdf}</shape>
</scene>"#,
            z = -(0.75f64.sqrt())
        );
        let tilt = png(1, 1, 3, &[191, 128, 221]);
        let ramp = png(2, 1, 3, &[0, 0, 0, 255, 255, 255]);
        let files = [
            ("scene.xml", text.as_bytes()),
            ("tilt.png", &tilt[..]),
            ("ramp.png", &ramp[..]),
        ];
        let l = load_files(&files).unwrap_or_else(|e| panic!("{e}"));
        assert!(l.warnings.is_empty(), "{:?}", l.warnings);
        let image = draw(&l, &path_settings(&l, 1, ColorMode::Rgb, 3));
        image[4 * 8 + 4][1] as f64
    };
    let diffuse = r#"<bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf>"#;
    let flat = picture(diffuse);
    assert!(flat > 0.01);
    let raw = |file: &str, name: &str| {
        format!(
            r#"<texture type="bitmap" name="{name}"><boolean name="raw" value="true"/><string name="filename" value="{file}"/></texture>"#
        )
    };
    let n = [191.0, 128.0, 221.0].map(|b: f64| 2.0 * b / 255.0 - 1.0);
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let cos30 = 0.75f64.sqrt();
    let want = flat * (0.5 * n[0] + cos30 * n[2]) / len / cos30;
    for bsdf in [
        format!(
            r#"<bsdf type="normalmap">{}{diffuse}</bsdf>"#,
            raw("tilt.png", "normalmap")
        ),
        format!(
            r#"<bsdf type="twosided"><bsdf type="normalmap">{}{diffuse}</bsdf></bsdf>"#,
            raw("tilt.png", "normalmap")
        ),
    ] {
        let got = picture(&bsdf);
        assert!((got - want).abs() < 1e-4 * want, "{bsdf}: {got} vs {want}");
    }
    // Heights 0 and 1 at u = 0.25 and 0.75 on a rectangle 2 wide, times `scale` 0.1: a
    // slope of 0.1, away from the light.
    let got = picture(&format!(
        r#"<bsdf type="bumpmap">{}<float name="scale" value="0.1"/>{diffuse}</bsdf>"#,
        raw("ramp.png", "height")
    ));
    let want = flat * (std::f64::consts::FRAC_PI_6 + 0.1f64.atan()).cos() / cos30;
    assert!((got - want).abs() < 1e-4 * want, "bumpmap: {got} vs {want}");
    // A normalmap without its texture is an error where it is written.
    let e = error(&scene(&format!(
        r#"<shape type="rectangle">
  <bsdf type="normalmap">{diffuse}</bsdf></shape>"#
    )));
    assert!(
        e.message.contains("normalmap") && e.to_string().contains(":3:3"),
        "{e}"
    );
}

/// A bitmap's `wrap_mode` continues it past its edges: repeated, mirrored or clamped.
#[test]
fn bitmap_wrap_modes() {
    use plenum_core::material::Material;
    use plenum_core::math::Vec3;
    use plenum_core::texture::TextureCoords;
    // Two texels, 0.2 and 0.8, read raw; u = −0.25 and 1.25 are the centres of the texels
    // just outside.
    let two = png(2, 1, 3, &[51, 51, 51, 204, 204, 204]);
    for (mode, want) in [
        ("repeat", [0.8, 0.2]),
        ("mirror", [0.2, 0.8]),
        ("clamp", [0.2, 0.8]),
    ] {
        let text = format!(
            r#"<scene version="3.0.0"><emitter type="constant"/><sensor type="perspective"/>
<shape type="sphere"><bsdf type="diffuse"><texture type="bitmap" name="reflectance">
<string name="filename" value="two.png"/><boolean name="raw" value="true"/><string name="wrap_mode" value="{mode}"/>
</texture></bsdf></shape></scene>"#
        );
        let l = load_files(&[("scene.xml", text.as_bytes()), ("two.png", &two[..])])
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(l.warnings.is_empty(), "{:?}", l.warnings);
        let Material::Diffuse(d) =
            &l.scene.materials[l.scene.geometry.primitives[0].material as usize]
        else {
            panic!("expected a diffuse material");
        };
        for (u, want) in [-0.25, 1.25].into_iter().zip(want) {
            let at = TextureCoords::new([u, 0.5], Vec3::ZERO);
            let got = d.reflectance.rgb(&at).g;
            assert!((got - want).abs() < 1e-6, "{mode} at u = {u}: {got}");
        }
    }
}

/// An `area` emitter's `radiance` may be a texture: a bitmap on a rectangle shows as the
/// rectangle's (u, v) places it, the bitmap's first row at v = 0 (the rectangle's bottom).
#[test]
fn a_bitmap_radiance_varies_over_the_emitter() {
    // Quadrants red, green / blue, white, each 2 × 2 texels (filtering keeps their colour).
    let (r, g, b, w) = ([255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255]);
    let rows = [[r, r, g, g], [r, r, g, g], [b, b, w, w], [b, b, w, w]];
    let texels: Vec<u8> = rows.iter().flatten().flatten().copied().collect();
    let lamp = png(4, 4, 3, &texels);
    let text = r#"<scene version="3.0.0">
  <sensor type="orthographic">
    <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/><rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle">
    <emitter type="area"><texture type="bitmap" name="radiance"><string name="filename" value="lamp.png"/></texture></emitter>
  </shape>
</scene>"#;
    let l = load_files(&[("scene.xml", text.as_bytes()), ("lamp.png", &lamp[..])])
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    let image = draw(&l, &path_settings(&l, 1, ColorMode::Rgb, 1));
    for ((x, y), want) in [
        ((8, 8), [0.0, 0.0, 1.0]),
        ((24, 8), [1.0, 1.0, 1.0]),
        ((8, 24), [1.0, 0.0, 0.0]),
        ((24, 24), [0.0, 1.0, 0.0]),
    ] {
        let got = image[y * 32 + x];
        for c in 0..3 {
            assert!(
                (got[c] as f64 - want[c]).abs() < 1e-3,
                "({x}, {y}): {got:?} for {want:?}"
            );
        }
    }
}

#[test]
fn spheres_disks_and_cylinders_have_mitsubas_uv() {
    // Mitsuba's (u, v) with v turned up (Plenum's textures have v up the image): a sphere's
    // u = φ/2π about z from +x, v = 1 − θ/π; a disk's u its radius, v = 1 − φ/2π; a
    // cylinder's u = φ/2π, v = 1 − z/length.
    use plenum_core::math::{Ray, Vec3};
    let textured =
        r#"<bsdf type="diffuse"><texture type="checkerboard" name="reflectance"/></bsdf>"#;
    let l = load(&lit(&format!(
        r#"<shape type="sphere"><point name="center" x="0" y="0" z="10"/><float name="radius" value="2"/>{textured}</shape>
<shape type="disk">{textured}</shape>
<shape type="cylinder"><point name="p0" x="5" y="0" z="0"/><point name="p1" x="5" y="0" z="4"/>{textured}</shape>"#
    )));
    let uv = |from: Vec3, to: Vec3| {
        let ray = Ray::new(from, to - from);
        let (prim, hit) = l.scene.geometry.intersect(&ray, f64::INFINITY).unwrap();
        l.scene.geometry.interaction(&ray, prim, &hit).uv
    };
    let near = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() + (a[1] - b[1]).abs() < 1e-9;
    let v = Vec3::new;
    // The sphere about (0, 0, 10): +x, and (0, √3, 11) (φ = π/2, θ = π/3).
    let got = uv(v(5.0, 0.0, 10.0), v(2.0, 0.0, 10.0));
    assert!(near(got, [0.0, 0.5]), "{got:?}");
    let got = uv(v(0.0, 5.0, 11.0), v(0.0, 3f64.sqrt(), 11.0));
    assert!(near(got, [0.25, 2.0 / 3.0]), "{got:?}");
    // The unit disk in z = 0, seen from above.
    let got = uv(v(-0.3, 0.4, 1.0), v(-0.3, 0.4, 0.0));
    let phi = 0.4f64.atan2(-0.3);
    assert!(
        near(got, [0.5, 1.0 - phi / (2.0 * std::f64::consts::PI)]),
        "{got:?}"
    );
    // The cylinder from (5, 0, 0) up to (5, 0, 4): its frame's x is +x, so (4, 0, 1) is
    // φ = π, a quarter of the way up.
    let got = uv(v(3.0, 0.0, 1.0), v(4.0, 0.0, 1.0));
    assert!(near(got, [0.5, 0.75]), "{got:?}");
}

/// scenes/cornell-box.toml written as Mitsuba 3 XML (each mesh an OBJ file shaded flat, as
/// the boxes share their corners between faces; Mitsuba's one-sided diffuse, a one-sided
/// area light, the path tracer's max_depth 8): the scene and its files.
fn cornell_box_xml() -> Vec<(String, Vec<u8>)> {
    let mut files = Vec::new();
    let mut shapes = String::new();
    for m in common::integrators::cornell_meshes() {
        let mut obj = String::new();
        for p in &m.positions {
            obj += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        }
        for t in &m.triangles {
            obj += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
        }
        let [r, g, b] = m.reflectance;
        let emitter = m.emission.map_or(String::new(), |[r, g, b]| {
            format!(
                r#"<emitter type="area"><rgb name="radiance" value="{r}, {g}, {b}"/></emitter>"#
            )
        });
        shapes += &format!(
            r#"<shape type="obj"><string name="filename" value="{0}.obj"/><boolean name="face_normals" value="true"/><bsdf type="diffuse"><rgb name="reflectance" value="{r}, {g}, {b}"/></bsdf>{emitter}</shape>
"#,
            m.name
        );
        files.push((format!("{}.obj", m.name), obj.into_bytes()));
    }
    let scene = format!(
        r#"<scene version="3.0.0">
<integrator type="path"><integer name="max_depth" value="8"/></integrator>
<sensor type="perspective">
  <float name="fov" value="39.3077"/>
  <transform name="to_world"><lookat origin="0, 0, 3.9" target="0, 0, 2.9" up="0, 1, 0"/></transform>
  <sampler type="independent"><integer name="sample_count" value="64"/></sampler>
  <film type="hdrfilm"><integer name="width" value="256"/><integer name="height" value="256"/><rfilter type="box"/></film>
</sensor>
{shapes}</scene>
"#
    );
    files.insert(0, ("scene.xml".to_string(), scene.into_bytes()));
    files
}

fn cornell_box() -> LoadedScene {
    let files = cornell_box_xml();
    let refs: Vec<(&str, &[u8])> = files.iter().map(|(n, b)| (n.as_str(), &b[..])).collect();
    load_files(&refs).unwrap_or_else(|e| panic!("{e}"))
}

/// The Cornell box in Mitsuba's XML reads as scenes/cornell-box.toml: the same settings
/// (max_depth 8 is Plenum's 6), camera, reflectances and light, without a warning.
#[test]
fn a_cornell_box_in_mitsubas_format_reads_as_the_native_one() {
    let l = cornell_box();
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    let native_box = common::integrators::load_cornell_box();
    let (d, e) = (&l.defaults, &native_box.defaults);
    assert_eq!(
        (d.spp, d.max_depth, d.filter, d.width, d.height),
        (e.spp, e.max_depth, e.filter, e.width, e.height)
    );
    let (a, b) = (native(&l), native(&native_box));
    for key in ["position", "look_at", "fov"] {
        let (x, y) = (&a["camera"][key], &b["camera"][key]);
        let flat = |v: &Value| match v.as_array() {
            Some(a) => a.iter().map(number).collect::<Vec<f64>>(),
            None => vec![number(v)],
        };
        let (x, y) = (flat(x), flat(y));
        assert!(
            x.iter().zip(&y).all(|(p, q)| (p - q).abs() < 1e-9),
            "{key}: {x:?} {y:?}"
        );
    }
    let objects = |t: &Table| t["objects"].as_array().unwrap().len();
    assert_eq!(objects(&a), objects(&b));
    let emitters = |t: &Table| {
        t["objects"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|o| {
                o.get("emission")
                    .map(|e| e.as_array().unwrap().iter().map(number).collect::<Vec<_>>())
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(emitters(&a), emitters(&b));
}

#[test]
#[ignore = "full suite (cargo test -- --include-ignored): over 10 s"]
fn a_cornell_box_in_mitsubas_format_matches_mitsubas_render() {
    common::integrators::cbox_z_test_of(
        &cornell_box(),
        plenum_core::integrator::IntegratorKind::Path,
        ColorMode::Rgb,
        "reference.exr",
        "reference-variance.exr",
        16,
        |_| {},
    );
}
