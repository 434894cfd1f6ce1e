//! glTF 2.0 scenes (`plenum render model.gltf` / `.glb`), on small files written here:
//! buffers in data URIs, files and GLB chunks, the node hierarchy and instancing, cameras and
//! handedness, punctual lights, the metallic–roughness materials, and located errors.

mod common;

use common::{bright_centre, load_files, native, number, png};

use common::integrators::{draw, path_settings};
use plenum_core::integrator::ColorMode;
use plenum_scene::LoadedScene;
use toml::Table;

fn base64(bytes: &[u8]) -> String {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for i in 0..4 {
            if i <= c.len() {
                out.push(A[(n >> (18 - 6 * i) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A unit square in the xy plane facing +z (two triangles): its buffer, positions then
/// 16-bit indices.
fn square() -> Vec<u8> {
    let mut b = Vec::new();
    for p in [
        [-0.5f32, -0.5, 0.0],
        [0.5, -0.5, 0.0],
        [0.5, 0.5, 0.0],
        [-0.5, 0.5, 0.0],
    ] {
        for x in p {
            b.extend(x.to_le_bytes());
        }
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        b.extend(i.to_le_bytes());
    }
    b
}

/// A glTF document around the square's buffer at `uri`: the scene's `roots` (node indices),
/// `nodes`, `materials`, and extra top-level members (`cameras`, `extensions`, …).
fn document(uri: &str, roots: &str, nodes: &str, materials: &str, extra: &str) -> String {
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [{roots}]}}],
  "nodes": [{nodes}],
  "meshes": [{{"name": "square", "primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 0}}]}}],
  "materials": [{materials}],
  "buffers": [{{"byteLength": 60, "uri": "{uri}"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": 12}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-0.5, -0.5, 0], "max": [0.5, 0.5, 0]}},
    {{"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ]{extra}
}}"#,
    )
}

fn data_uri() -> String {
    format!("data:application/octet-stream;base64,{}", base64(&square()))
}

fn load(text: &str) -> LoadedScene {
    load_files(&[("scene.gltf", text.as_bytes())]).unwrap_or_else(|e| panic!("{e}"))
}

const GREY: &str =
    r#"{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0}}"#;

#[test]
fn nodes_place_one_mesh_many_times() {
    // Two nodes use the mesh: translated by +2 in x, and by −2 under a parent scaled by 2.
    let l = load(&document(
        &data_uri(),
        "0, 1",
        r#"{"mesh": 0, "translation": [2, 0, 0]},
           {"scale": [2, 2, 2], "children": [2]},
           {"mesh": 0, "translation": [-1, 0, 0]}"#,
        GREY,
        "",
    ));
    let t = native(&l);
    let objects = t["objects"].as_array().unwrap();
    assert_eq!(objects.len(), 2);
    // Instanced: one mesh table, referenced twice.
    assert_eq!(t["meshes"].as_table().unwrap().len(), 1, "{t}");
    let b = l.scene.geometry.bounds();
    assert!(
        (b.min.x + 3.0).abs() < 1e-6 && (b.max.x - 2.5).abs() < 1e-6,
        "{b:?}"
    );
    assert!(
        (b.max.y - 1.0).abs() < 1e-6,
        "the scaled copy is 2 high: {b:?}"
    );
    // No camera and no light: a framing camera and a sky, each said.
    assert_eq!(l.warnings.len(), 1, "{:?}", l.warnings);
    assert!(l.warnings[0].contains("no lights"), "{:?}", l.warnings);
}

#[test]
fn the_camera_looks_down_minus_z_with_x_to_the_right() {
    // A camera 4 units up +z looking back at the origin; an emissive square at x = +1.2
    // appears in the right half, one at y = +1.2 in the top half.
    let picture = |x: f64, y: f64| {
        let l = load(&document(
            &data_uri(),
            "0, 1",
            &format!(
                r#"{{"mesh": 0, "translation": [{x}, {y}, 0]}},
                   {{"camera": 0, "translation": [0, 0, 4]}}"#
            ),
            r#"{"emissiveFactor": [1, 1, 1], "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]}}"#,
            r#", "cameras": [{"type": "perspective", "perspective": {"yfov": 1.0, "aspectRatio": 1.0, "znear": 0.1}}]"#,
        ));
        assert!(l.warnings.is_empty(), "{:?}", l.warnings);
        let mut l = l;
        l.defaults.width = 32;
        l.defaults.height = 32;
        let image = draw(&l, &path_settings(&l, 1, ColorMode::Rgb, 3));
        bright_centre(&image, 32)
    };
    let (x, y) = picture(1.2, 0.0);
    assert!(
        x > 20.0 && (y - 15.5).abs() < 2.0,
        "a square at +x lands at ({x}, {y})"
    );
    let (x, y) = picture(0.0, 1.2);
    assert!(
        (x - 15.5).abs() < 2.0 && y < 12.0,
        "a square at +y lands at ({x}, {y})"
    );
}

#[test]
fn metallic_roughness_materials_map_onto_plenums() {
    let materials = [
        r#"{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.2, 0.1, 1], "metallicFactor": 0, "roughnessFactor": 0.5}}"#,
        r#"{"pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.6, 0.2, 1], "metallicFactor": 1, "roughnessFactor": 0.2}}"#,
        r#"{"pbrMetallicRoughness": {"metallicFactor": 0.25}}"#,
        r#"{"pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0}, "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1}, "KHR_materials_ior": {"ior": 1.45}}}"#,
        r#"{"emissiveFactor": [1, 0.5, 0.25], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}}}"#,
    ];
    let kinds: Vec<Table> = materials
        .iter()
        .map(|m| {
            let l = load(&document(&data_uri(), "0", r#"{"mesh": 0}"#, m, ""));
            let t = native(&l);
            let name = t["objects"][0]["material"].as_str().unwrap().to_string();
            let mut m = t["materials"][&name].as_table().unwrap().clone();
            if let Some(e) = t["objects"][0].get("emission") {
                m.insert("emission".into(), e.clone());
            }
            m
        })
        .collect();
    // A dielectric base: a coat over the base colour, α = roughness².
    assert_eq!(kinds[0]["type"].as_str(), Some("coateddiffuse"));
    let r: Vec<f64> = kinds[0]["reflectance"]
        .as_array()
        .unwrap()
        .iter()
        .map(number)
        .collect();
    assert_eq!(
        r,
        [0.800000011920929, 0.20000000298023224, 0.10000000149011612]
    );
    assert!((number(&kinds[0]["roughness"][0]) - 0.25).abs() < 1e-12);
    assert!((number(&kinds[0]["eta"]) - 1.5).abs() < 1e-12);
    // A metal: the base colour as its reflectance.
    assert_eq!(kinds[1]["type"].as_str(), Some("conductor"));
    assert!(kinds[1].contains_key("reflectance"), "{:?}", kinds[1]);
    // In between: the metal with probability `metallic`.
    assert_eq!(kinds[2]["type"].as_str(), Some("mix"));
    assert_eq!(number(&kinds[2]["amount"]), 0.25);
    // Transmission: glass of the given index.
    assert_eq!(kinds[3]["type"].as_str(), Some("dielectric"));
    assert!((number(&kinds[3]["eta"]) - 1.45).abs() < 1e-6);
    // Emission times its strength: an area light on the mesh.
    let e: Vec<f64> = kinds[4]["emission"]
        .as_array()
        .unwrap()
        .iter()
        .map(number)
        .collect();
    assert_eq!(e, [4.0, 2.0, 1.0]);
}

#[test]
fn punctual_lights_shine_along_minus_z_of_their_node() {
    let l = load(&document(
        &data_uri(),
        "0, 1, 2",
        r#"{"mesh": 0},
           {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [0, 3, 0]},
           {"extensions": {"KHR_lights_punctual": {"light": 1}}, "rotation": [-0.7071068, 0, 0, 0.7071068]}"#,
        GREY,
        r#", "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1, 0.5, 0.5], "intensity": 10},
            {"type": "directional", "intensity": 2}
        ]}}"#,
    ));
    let t = native(&l);
    let lights = t["lights"].as_array().unwrap();
    let point = lights
        .iter()
        .find(|x| x["type"].as_str() == Some("point"))
        .unwrap();
    let at: Vec<f64> = point["position"]
        .as_array()
        .unwrap()
        .iter()
        .map(number)
        .collect();
    assert!((at[1] - 3.0).abs() < 1e-9, "{at:?}");
    let sun = lights
        .iter()
        .find(|x| x["type"].as_str() == Some("directional"))
        .unwrap();
    // −z turned −90° about x points down, −y.
    let d: Vec<f64> = sun["direction"]
        .as_array()
        .unwrap()
        .iter()
        .map(number)
        .collect();
    assert!(
        d[0].abs() < 1e-6 && (d[1] + 1.0).abs() < 1e-6 && d[2].abs() < 1e-6,
        "{d:?}"
    );
}

#[test]
fn buffers_are_read_from_files_and_glb_chunks_alike() {
    let reference = native(&load(&document(
        &data_uri(),
        "0",
        r#"{"mesh": 0}"#,
        GREY,
        "",
    )));
    // The buffer in a file beside the glTF (its name escaped as a URI).
    let text = document("my%20square.bin", "0", r#"{"mesh": 0}"#, GREY, "");
    let l = load_files(&[
        ("scene.gltf", text.as_bytes()),
        ("my square.bin", &square()),
    ])
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(native(&l)["objects"], reference["objects"]);
    // The same as a GLB: a JSON chunk and a BIN chunk, each padded to 4 bytes.
    let json = document("", "0", r#"{"mesh": 0}"#, GREY, "").replace(r#", "uri": """#, "");
    let mut json = json.into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let bin = square();
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend((total as u32).to_le_bytes());
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&json);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(&bin);
    let l = load_files(&[("scene.glb", &glb)]).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(native(&l)["objects"], reference["objects"]);
}

#[test]
fn bad_files_are_refused_with_where() {
    let err = |text: &str| match load_files(&[("scene.gltf", text.as_bytes())]) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e,
    };
    // Malformed JSON: its line and column.
    let e = err("{\n  \"asset\": {\"version\": \"2.0\"},\n  \"nodes\": [,]\n}");
    assert_eq!(e.line, 3, "{e}");
    assert!(e.message.contains("malformed glTF"), "{e}");
    // An accessor reaching past its buffer view.
    let text = document(&data_uri(), "0", r#"{"mesh": 0}"#, GREY, "")
        .replace(r#""count": 4"#, r#""count": 40"#);
    let e = err(&text);
    assert!(e.message.contains("accessors[0]"), "{e}");
    // A buffer file that is not there.
    let e = err(&document("missing.bin", "0", r#"{"mesh": 0}"#, GREY, ""));
    assert!(
        e.message.contains("buffers[0]") && e.message.contains("missing.bin"),
        "{e}"
    );
    // A node that contains itself.
    let text = document(
        &data_uri(),
        "0",
        r#"{"mesh": 0, "children": [0]}"#,
        GREY,
        "",
    );
    let e = err(&text);
    assert!(e.message.contains("nodes"), "{e}");
}

/// An orthographic camera is one: its view 2·ymag high and 2·xmag wide (the image's aspect
/// follows), with no warning.
#[test]
fn an_orthographic_camera_keeps_its_extent() {
    let l = load(&document(
        &data_uri(),
        "0, 1",
        r#"{"mesh": 0}, {"camera": 0, "translation": [0, 0, 4]}"#,
        r#"{"emissiveFactor": [1, 1, 1]}"#,
        r#", "cameras": [{"type": "orthographic", "orthographic": {"xmag": 3.0, "ymag": 1.5, "znear": 0.1, "zfar": 10}}]"#,
    ));
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    assert_eq!(l.scene.camera.orthographic, Some(3.0));
    assert_eq!((l.defaults.width, l.defaults.height), (960, 480));
}

/// A unit square (uvs over [0, 1]², glTF's v down the image) with material `front` and the
/// PNG `image` as texture 0, filling an orthographic view from z = 4; behind it at z = −1 a
/// square ten times larger emits 1.
fn textured_square(front: &str, image: &[u8]) -> LoadedScene {
    let mut buffer = Vec::new();
    let corners = [[-0.5f32, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]];
    for [x, y] in corners {
        for c in [x, y, 0.0] {
            buffer.extend(c.to_le_bytes());
        }
    }
    for [x, y] in corners {
        for c in [x + 0.5, 0.5 - y] {
            buffer.extend(c.to_le_bytes());
        }
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        buffer.extend(i.to_le_bytes());
    }
    let image = base64(image);
    let text = format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0, 1, 2]}}],
  "nodes": [
    {{"mesh": 0}},
    {{"mesh": 1, "translation": [0, 0, -1], "scale": [10, 10, 10]}},
    {{"camera": 0, "translation": [0, 0, 4]}}
  ],
  "meshes": [
    {{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "indices": 2, "material": 0}}]}},
    {{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 2, "material": 1}}]}}
  ],
  "materials": [{front}, {{"emissiveFactor": [1, 1, 1], "pbrMetallicRoughness": {{"baseColorFactor": [0, 0, 0, 1]}}}}],
  "images": [{{"uri": "data:image/png;base64,{image}"}}],
  "textures": [{{"source": 0}}],
  "cameras": [{{"type": "orthographic", "orthographic": {{"xmag": 0.5, "ymag": 0.5, "znear": 0.1, "zfar": 10}}}}],
  "buffers": [{{"byteLength": 92, "uri": "data:application/octet-stream;base64,{}"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": 32}}, {{"buffer": 0, "byteOffset": 80, "byteLength": 12}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-0.5, -0.5, 0], "max": [0.5, 0.5, 0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ]
}}"#,
        base64(&buffer)
    );
    let mut l = load(&text);
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    l.defaults.width = 32;
    l.defaults.height = 32;
    l
}

#[test]
fn alpha_modes_cut_the_surface_out() {
    // The lamp shows where the front square is cut away.
    // Alpha 0 in the image's top-left and bottom-right texels, 255 in the others.
    let texels = [0u8, 0, 0, 0, 9, 9, 9, 255, 9, 9, 9, 255, 0, 0, 0, 0];
    let png = png(2, 2, 4, &texels);
    let picture = |front: &str, spp: u32| {
        let l = textured_square(front, &png);
        draw(&l, &path_settings(&l, spp, ColorMode::Rgb, 3))
    };
    // Black and metallic: the square reflects nothing.
    let black = |alpha: &str| {
        format!(
            r#"{{{alpha} "pbrMetallicRoughness": {{"baseColorFactor": [0, 0, 0, FACTOR], "baseColorTexture": {{"index": 0}}}}}}"#
        )
    };
    let green = |image: &[[f32; 3]], x: usize, y: usize| image[y * 32 + x][1];
    // MASK by the texture's alpha: the lamp shows in the top-left and bottom-right.
    let image = picture(&black(r#""alphaMode": "MASK","#).replace("FACTOR", "1"), 1);
    for (x, y, lamp) in [(8, 8, true), (24, 24, true), (24, 8, false), (8, 24, false)] {
        let want = if lamp { 1.0 } else { 0.0 };
        assert!(
            (green(&image, x, y) - want).abs() < 1e-3,
            "({x}, {y}): {}",
            green(&image, x, y)
        );
    }
    // The factor's alpha multiplies the texture's: 0.4 < the cutoff 0.6 cuts it all away.
    let image = picture(
        &black(r#""alphaMode": "MASK", "alphaCutoff": 0.6,"#).replace("FACTOR", "0.4"),
        1,
    );
    assert!(image.iter().all(|p| (p[1] - 1.0).abs() < 1e-3));
    // OPAQUE (the default) ignores alpha: the lamp is hidden.
    let image = picture(&black("").replace("FACTOR", "0.4"), 1);
    assert!(image.iter().all(|p| p[1] == 0.0));
    // BLEND with a coverage of 0.25 where the texture is opaque and 0 where it is not: the
    // lamp is seen by 3/4 of the rays in two quadrants and all of them in the others, so the
    // image's mean is 0.875. 32 × 32 × 16 = 16,384 samples, half of them random:
    // σ = √(0.75·0.25/8192)/2 = 0.0024; 5σ.
    let image = picture(
        &black(r#""alphaMode": "BLEND","#).replace("FACTOR", "0.25"),
        16,
    );
    let mean = image.iter().map(|p| p[1] as f64).sum::<f64>() / image.len() as f64;
    assert!((mean - 0.875).abs() < 5.0 * 0.0024, "mean {mean}");
}

#[test]
fn the_metallic_roughness_texture_varies_both() {
    // Green is roughness, blue metallic, stored linearly (not sRGB), times the factors
    // (roughness 0.5, metallic 1). Texels from the image's top-left: (rough 1, metal 0),
    // (rough 0, metal 1), (rough 0.2, metal 0.6), (rough 0.6, metal 0.2).
    let texels = [0u8, 255, 0, 0, 0, 255, 0, 51, 153, 0, 153, 51];
    let l = textured_square(
        r#"{"pbrMetallicRoughness": {"roughnessFactor": 0.5, "metallicFactor": 1, "metallicRoughnessTexture": {"index": 0}}}"#,
        &png(2, 2, 3, &texels),
    );
    use plenum_core::material::{FloatTexture, Material};
    use plenum_core::math::Vec3;
    use plenum_core::texture::TextureCoords;
    let m = &l.scene.materials[l.scene.geometry.primitives[0].material as usize];
    let Material::Mix { materials, amount } = m else {
        panic!("expected a mix of dielectric and metal: {m:?}");
    };
    let Material::Conductor(metal) = &l.scene.materials[materials[1] as usize] else {
        panic!("expected the metal second");
    };
    // Plenum's (u, v) has v up: the image's top-left texel is at (0.25, 0.75).
    let at = |u: f64, v: f64| TextureCoords::new([u, v], Vec3::ZERO);
    for ((u, v), rough, metallic) in [
        ((0.25, 0.75), 1.0, 0.0),
        ((0.75, 0.75), 0.0, 1.0),
        ((0.25, 0.25), 0.2, 0.6),
        ((0.75, 0.25), 0.6, 0.2),
    ] {
        let a = metal.roughness.u.evaluate(&at(u, v));
        let want = (rough * 0.5f64).powi(2);
        assert!((a - want).abs() < 1e-6, "({u}, {v}): α {a}, want {want}");
        let k = amount.evaluate(&at(u, v));
        assert!((k - metallic).abs() < 1e-6, "({u}, {v}): metallic {k}");
    }
    assert!(matches!(metal.roughness.v, FloatTexture::Texture(_)));
}

#[test]
fn texture_transforms_map_the_uvs_as_the_extensions_examples_say() {
    // An 8 × 8 image of four quadrants: red top-left, green top-right, blue bottom-left,
    // white bottom-right.
    let mut texels = Vec::new();
    for y in 0..8 {
        for x in 0..8 {
            texels.extend(match (x < 4, y < 4) {
                (true, true) => [255, 0, 0],
                (false, true) => [0, 255, 0],
                (true, false) => [0, 0, 255],
                (false, false) => [255, 255, 255],
            });
        }
    }
    let image = png(8, 8, 3, &texels);
    let base_colour = |transform: &str| {
        let l = textured_square(
            &format!(
                r#"{{"pbrMetallicRoughness": {{"metallicFactor": 1, "baseColorTexture": {{"index": 0{transform}}}}}}}"#
            ),
            &image,
        );
        use plenum_core::material::{ConductorSpec, Material};
        let m = &l.scene.materials[l.scene.geometry.primitives[0].material as usize];
        let Material::Conductor(c) = m else {
            panic!("{m:?}")
        };
        let ConductorSpec::Reflectance(r) = &c.spec else {
            panic!("{c:?}")
        };
        r.clone()
    };
    use plenum_core::math::Vec3;
    use plenum_core::texture::TextureCoords;
    // Plenum's (u, v), v up: (0.3, 0.7) is glTF's (0.3, 0.3), in the top-left quadrant.
    let at = |u: f64, v: f64| TextureCoords::new([u, v], Vec3::ZERO);
    let rgb = |t: &plenum_core::material::SpectralTexture, u, v| {
        let c = t.rgb(&at(u, v));
        [c.r, c.g, c.b].map(|x| (x * 100.0).round() / 100.0)
    };
    let plain = base_colour("");
    assert_eq!(rgb(&plain, 0.3, 0.7), [1.0, 0.0, 0.0]);
    assert_eq!(rgb(&plain, 0.7, 0.3), [1.0, 1.0, 1.0]);
    // "This example utilizes only the lower left quadrant of the source image, rotated
    // clockwise 90°": blue everywhere inside (away from the quadrant's blended edges).
    let quadrant = base_colour(
        r#", "extensions": {"KHR_texture_transform": {"offset": [0, 1], "rotation": 1.57079632679, "scale": [0.5, 0.5]}}"#,
    );
    for (u, v) in [(0.2, 0.2), (0.8, 0.2), (0.5, 0.5), (0.2, 0.8), (0.8, 0.8)] {
        assert_eq!(rgb(&quadrant, u, v), [0.0, 0.0, 1.0], "({u}, {v})");
    }
    // "This example inverts the T axis": the top-left of the square shows the bottom-left.
    let flipped = base_colour(
        r#", "extensions": {"KHR_texture_transform": {"offset": [0, 1], "scale": [1, -1]}}"#,
    );
    assert_eq!(rgb(&flipped, 0.3, 0.7), [0.0, 0.0, 1.0]);
    assert_eq!(rgb(&flipped, 0.7, 0.3), [0.0, 1.0, 0.0]);
}

#[test]
fn the_normal_texture_turns_the_shading_normal_in_its_tangent_frame() {
    // The textured square faces +z with glTF's u along +x and v down (−y). Tangent-space x
    // follows u and y points up the image (+y here); the texels are linear, and `scale`
    // multiplies x and y. Tilts of about 30°: (191 → 0.498, 221 → 0.733). Texels are
    // decoded to f32, hence the tolerance of 1e-6.
    use plenum_core::math::{Ray, Vec3};
    let shading_normal = |material: &str, image: &[u8], x: f64| {
        let l = textured_square(material, image);
        assert!(l.warnings.is_empty(), "{:?}", l.warnings);
        let ray = Ray::new(Vec3::new(x, 0.1, 3.0), -Vec3::Z);
        let (prim, hit) = l.scene.geometry.intersect(&ray, f64::INFINITY).unwrap();
        assert_eq!(prim, 0);
        l.scene.geometry.interaction(&ray, prim, &hit).shading_n
    };
    let decode = |b: u8| 2.0 * b as f64 / 255.0 - 1.0;
    let unit = |x: f64, y: f64, z: f64| Vec3::new(x, y, z).normalized();
    let plain = r#"{"normalTexture": {"index": 0}}"#;
    let right = png(1, 1, 3, &[191, 128, 221]);
    let got = shading_normal(plain, &right, 0.0);
    let want = unit(decode(191), decode(128), decode(221));
    assert!((got - want).length() < 1e-6, "{got:?} vs {want:?}");
    let up = png(1, 1, 3, &[128, 191, 221]);
    let got = shading_normal(plain, &up, 0.0);
    let want = unit(decode(128), decode(191), decode(221));
    assert!((got - want).length() < 1e-6, "up: {got:?} vs {want:?}");
    let half = r#"{"normalTexture": {"index": 0, "scale": 0.5}}"#;
    let got = shading_normal(half, &right, 0.0);
    let want = unit(0.5 * decode(191), 0.5 * decode(128), decode(221));
    assert!((got - want).length() < 1e-6, "scale ½: {got:?} vs {want:?}");
    // KHR_texture_transform on the normal texture: a 2 × 1 image tilted right on its left
    // texel and left on its right one, shifted by half its width.
    let both = png(2, 1, 3, &[191, 128, 221, 64, 128, 221]);
    let got = shading_normal(plain, &both, -0.25);
    assert!(got.x > 0.4, "{got:?}");
    let shifted = r#"{"normalTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"offset": [0.5, 0]}}}}"#;
    let got = shading_normal(shifted, &both, -0.25);
    let want = unit(decode(64), decode(128), decode(221));
    assert!((got - want).length() < 1e-6, "shifted: {got:?} vs {want:?}");
}

#[test]
fn the_emissive_texture_times_its_factor_is_the_radiance() {
    // Quadrants red, green / blue, white (sRGB 255, linear 1), each 2 × 2 texels so that
    // filtering inside them keeps their colour; the factor (1, 0.5, 2) times strength 1.5.
    let (r, g, b, w) = ([255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255]);
    let rows = [[r, r, g, g], [r, r, g, g], [b, b, w, w], [b, b, w, w]];
    let texels: Vec<u8> = rows.iter().flatten().flatten().copied().collect();
    let l = textured_square(
        r#"{"emissiveFactor": [1, 0.5, 2], "emissiveTexture": {"index": 0},
            "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 1.5}},
            "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]}}"#,
        &png(4, 4, 3, &texels),
    );
    let image = draw(&l, &path_settings(&l, 1, ColorMode::Rgb, 3));
    // glTF's (0, 0) is the image's top-left corner, on the square's top-left corner.
    let k = [1.5, 0.75, 3.0];
    for ((x, y), want) in [
        ((8, 8), [k[0], 0.0, 0.0]),
        ((24, 8), [0.0, k[1], 0.0]),
        ((8, 24), [0.0, 0.0, k[2]]),
        ((24, 24), k),
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

/// A square facing +z with normals and the tangent `tangent` at every vertex, its
/// material a normal map of the one texel `texel`: the shading normal at its centre.
fn normal_from_tangents(tangent: [f32; 4], texel: [u8; 3]) -> plenum_core::math::Vec3 {
    use plenum_core::math::{Ray, Vec3};
    let corners = [[-0.5f32, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]];
    let mut buffer = Vec::new();
    let mut put = |values: &[f32]| values.iter().for_each(|v| buffer.extend(v.to_le_bytes()));
    corners.iter().for_each(|[x, y]| put(&[*x, *y, 0.0]));
    corners.iter().for_each(|_| put(&[0.0, 0.0, 1.0]));
    corners.iter().for_each(|[x, y]| put(&[x + 0.5, 0.5 - y]));
    corners.iter().for_each(|_| put(&tangent));
    for i in [0u16, 1, 2, 0, 2, 3] {
        buffer.extend(i.to_le_bytes());
    }
    let image = base64(&png(1, 1, 3, &texel));
    let text = format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scenes": [{{"nodes": [0]}}],
  "nodes": [{{"mesh": 0}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "TANGENT": 3}}, "indices": 4, "material": 0}}]}}],
  "materials": [{{"normalTexture": {{"index": 0}}}}],
  "images": [{{"uri": "data:image/png;base64,{image}"}}],
  "textures": [{{"source": 0}}],
  "buffers": [{{"byteLength": 204, "uri": "data:application/octet-stream;base64,{}"}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 96, "byteLength": 32}}, {{"buffer": 0, "byteOffset": 128, "byteLength": 64}},
    {{"buffer": 0, "byteOffset": 192, "byteLength": 12}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-0.5, -0.5, 0], "max": [0.5, 0.5, 0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"}},
    {{"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC4"}},
    {{"bufferView": 4, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ]
}}"#,
        base64(&buffer)
    );
    let l = load(&text);
    assert!(
        l.warnings.iter().all(|w| !w.contains("TANGENT")),
        "{:?}",
        l.warnings
    );
    let ray = Ray::new(Vec3::new(0.1, 0.1, 3.0), -Vec3::Z);
    let (prim, hit) = l.scene.geometry.intersect(&ray, f64::INFINITY).unwrap();
    l.scene.geometry.interaction(&ray, prim, &hit).shading_n
}

#[test]
fn tangent_attributes_give_the_normal_map_its_frame() {
    // Tangent-space x along the given tangent, y along n × t times its w: a tangent along
    // +y turns a map tilted to +x toward +y; with w = −1 a map tilted up (+y) leans to +x
    // (n × t = −x, turned over). With the tangent along +x, what the uvs give.
    use plenum_core::math::Vec3;
    let decode = |b: u8| 2.0 * b as f64 / 255.0 - 1.0;
    // 128 decodes to a hair above 0.
    let (tilt, flat, z) = (decode(191), decode(128), decode(221));
    let unit = |x: f64, y: f64| Vec3::new(x, y, z).normalized();
    for (tangent, texel, want) in [
        ([0.0, 1.0, 0.0, 1.0], [191, 128, 221], unit(-flat, tilt)),
        ([0.0, 1.0, 0.0, -1.0], [128, 191, 221], unit(tilt, flat)),
        ([0.0, 1.0, 0.0, 1.0], [128, 191, 221], unit(-tilt, flat)),
        ([1.0, 0.0, 0.0, 1.0], [191, 128, 221], unit(tilt, flat)),
        ([1.0, 0.0, 0.0, 1.0], [128, 191, 221], unit(flat, tilt)),
    ] {
        let got = normal_from_tangents(tangent, texel);
        assert!(
            (got - want).length() < 1e-6,
            "tangent {tangent:?}, texel {texel:?}: {got:?} vs {want:?}"
        );
    }
}

#[test]
fn khr_materials_specular_scales_the_coats_reflectance() {
    // F0 = ((ior − 1)/(ior + 1))² = 0.04 at ior 1.5; the coat gets the ior whose F0 is
    // that times the colour factor's mean times the specular factor.
    let coat_eta = |specular: &str| {
        let m = format!(
            r#"{{"pbrMetallicRoughness": {{"metallicFactor": 0}}, "extensions": {{"KHR_materials_specular": {specular}}}}}"#
        );
        let l = load(&document(&data_uri(), "0", r#"{"mesh": 0}"#, &m, ""));
        let t = native(&l);
        let name = t["objects"][0]["material"].as_str().unwrap().to_string();
        let m = t["materials"][&name].as_table().unwrap().clone();
        assert_eq!(m["type"].as_str(), Some("coateddiffuse"));
        // Only the material's warnings (not those of the missing camera and lights).
        let warnings: Vec<String> = l
            .warnings
            .into_iter()
            .filter(|w| w.contains("materials["))
            .collect();
        (number(&m["eta"]), warnings)
    };
    let ior_of = |f0: f64| (1.0 + f0.sqrt()) / (1.0 - f0.sqrt());
    let (eta, warnings) = coat_eta(r#"{"specularFactor": 0.5}"#);
    assert!((eta - ior_of(0.02)).abs() < 1e-6, "{eta}");
    assert!(warnings.is_empty(), "{warnings:?}");
    // No specular reflection at all: a coat that does not reflect.
    let (eta, _) = coat_eta(r#"{"specularFactor": 0}"#);
    assert!((eta - 1.0).abs() < 1e-12, "{eta}");
    // A grey colour factor scales F0 too; a coloured one by its mean, with a warning.
    let (eta, warnings) = coat_eta(r#"{"specularColorFactor": [0.25, 0.25, 0.25]}"#);
    assert!(
        (eta - ior_of(0.01)).abs() < 1e-6 && warnings.is_empty(),
        "{eta}"
    );
    let (eta, warnings) = coat_eta(r#"{"specularColorFactor": [1, 0.5, 0]}"#);
    assert!((eta - ior_of(0.02)).abs() < 1e-6, "{eta}");
    assert!(
        warnings.len() == 1
            && warnings[0].contains("materials[0]")
            && warnings[0].contains("coloured"),
        "{warnings:?}"
    );
    // The defaults change nothing.
    let (eta, warnings) = coat_eta("{}");
    assert!((eta - 1.5).abs() < 1e-12 && warnings.is_empty());
}

#[test]
fn textures_read_the_texture_coordinate_set_they_name() {
    // The square with two uv sets: TEXCOORD_0 all (0, 0), TEXCOORD_1 the square's own
    // ((x + ½, ½ − y) in glTF's v-down uv). The material's textures read set 1, so the
    // mesh carries set 1; an emissive texture reading set 0 is warned about.
    use plenum_core::math::{Ray, Vec3};
    let corners = [[-0.5f32, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]];
    let mut buffer = Vec::new();
    for [x, y] in corners {
        for c in [x, y, 0.0] {
            buffer.extend(c.to_le_bytes());
        }
    }
    for _ in corners {
        buffer.extend([0u8; 8]);
    }
    for [x, y] in corners {
        for c in [x + 0.5, 0.5 - y] {
            buffer.extend(c.to_le_bytes());
        }
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        buffer.extend(i.to_le_bytes());
    }
    let image = base64(&png(1, 1, 3, &[200, 100, 50]));
    let doc = |material: &str| {
        format!(
            r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0]}}],
  "nodes": [{{"mesh": 0}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 2}}, "indices": 3, "material": 0}}]}}],
  "materials": [{material}],
  "images": [{{"uri": "data:image/png;base64,{image}"}}],
  "textures": [{{"source": 0}}],
  "buffers": [{{"byteLength": 124, "uri": "data:application/octet-stream;base64,{}"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": 32}}, {{"buffer": 0, "byteOffset": 80, "byteLength": 32}}, {{"buffer": 0, "byteOffset": 112, "byteLength": 12}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-0.5, -0.5, 0], "max": [0.5, 0.5, 0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ]
}}"#,
            base64(&buffer)
        )
    };
    let uv_at = |l: &LoadedScene, x: f64, y: f64| {
        let ray = Ray::new(Vec3::new(x, y, 3.0), -Vec3::Z);
        let (prim, hit) = l.scene.geometry.intersect(&ray, f64::INFINITY).unwrap();
        l.scene.geometry.interaction(&ray, prim, &hit).uv
    };
    let near = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() + (a[1] - b[1]).abs() < 1e-6;
    // Set 1, named by the textureInfo or by KHR_texture_transform's texCoord.
    for base in [
        r#"{"index": 0, "texCoord": 1}"#,
        r#"{"index": 0, "extensions": {"KHR_texture_transform": {"texCoord": 1}}}"#,
    ] {
        let l = load(&doc(&format!(
            r#"{{"pbrMetallicRoughness": {{"baseColorTexture": {base}}}}}"#
        )));
        assert!(
            !l.warnings.iter().any(|w| w.contains("materials[")),
            "{:?}",
            l.warnings
        );
        // Plenum's v is up: (x + ½, y + ½).
        assert!(
            near(uv_at(&l, 0.2, -0.1), [0.7, 0.4]),
            "{:?}",
            uv_at(&l, 0.2, -0.1)
        );
    }
    // Without texCoord, set 0.
    let l = load(&doc(
        r#"{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}"#,
    ));
    assert!(near(uv_at(&l, 0.2, -0.1), [0.0, 1.0]));
    // Two sets in one material: the first texture's, and a located warning for the other.
    let l = load(&doc(
        r#"{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1}}, "emissiveFactor": [1, 1, 1], "emissiveTexture": {"index": 0}}"#,
    ));
    assert!(near(uv_at(&l, 0.2, -0.1), [0.7, 0.4]));
    let about: Vec<&String> = l
        .warnings
        .iter()
        .filter(|w| w.contains("materials["))
        .collect();
    assert!(
        about.len() == 1
            && about[0].contains("materials[0].emissiveTexture")
            && about[0].contains("TEXCOORD_1"),
        "{:?}",
        l.warnings
    );
}

/// scenes/cornell-box.toml written as glTF: each mesh its own, the walls' materials
/// diffuse (a coat that reflects nothing: `KHR_materials_specular` with factor 0), the
/// light a one-sided emissive surface (`doubleSided` false) of the same radiance (factor
/// times strength), the camera where the native one is.
fn cornell_box_gltf() -> LoadedScene {
    let meshes = common::integrators::cornell_meshes();
    let (mut buffer, mut views, mut accessors, mut gltf_meshes, mut materials, mut nodes) = (
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
    );
    for (i, m) in meshes.iter().enumerate() {
        let start = buffer.len();
        let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
        for p in &m.positions {
            for k in 0..3 {
                let x = p[k] as f32;
                buffer.extend(x.to_le_bytes());
                lo[k] = lo[k].min(x);
                hi[k] = hi[k].max(x);
            }
        }
        let middle = buffer.len();
        for t in &m.triangles {
            for i in t {
                buffer.extend((*i as u16).to_le_bytes());
            }
        }
        while buffer.len() % 4 != 0 {
            buffer.push(0);
        }
        views.push(format!(
            r#"{{"buffer": 0, "byteOffset": {start}, "byteLength": {}}}"#,
            middle - start
        ));
        views.push(format!(
            r#"{{"buffer": 0, "byteOffset": {middle}, "byteLength": {}}}"#,
            m.triangles.len() * 6
        ));
        accessors.push(format!(
            r#"{{"bufferView": {}, "componentType": 5126, "count": {}, "type": "VEC3", "min": {lo:?}, "max": {hi:?}}}"#,
            2 * i,
            m.positions.len()
        ));
        accessors.push(format!(
            r#"{{"bufferView": {}, "componentType": 5123, "count": {}, "type": "SCALAR"}}"#,
            2 * i + 1,
            m.triangles.len() * 3
        ));
        gltf_meshes.push(format!(
            r#"{{"primitives": [{{"attributes": {{"POSITION": {}}}, "indices": {}, "material": {i}}}]}}"#,
            2 * i,
            2 * i + 1
        ));
        let [r, g, b] = m.reflectance;
        let emission = m.emission.map_or(String::new(), |e| {
            let strength = e[0].max(e[1]).max(e[2]);
            format!(
                r#", "emissiveFactor": [{}, {}, {}], "extensions": {{"KHR_materials_emissive_strength": {{"emissiveStrength": {strength}}}, "KHR_materials_specular": {{"specularFactor": 0}}}}"#,
                e[0] / strength,
                e[1] / strength,
                e[2] / strength
            )
        });
        let specular = match m.emission {
            None => r#", "extensions": {"KHR_materials_specular": {"specularFactor": 0}}"#,
            Some(_) => "",
        };
        materials.push(format!(
            r#"{{"name": "{}", "doubleSided": false, "pbrMetallicRoughness": {{"baseColorFactor": [{r}, {g}, {b}, 1], "metallicFactor": 0, "roughnessFactor": 0}}{emission}{specular}}}"#,
            m.name
        ));
        nodes.push(format!(r#"{{"name": "{}", "mesh": {i}}}"#, m.name));
    }
    nodes.push(r#"{"camera": 0, "translation": [0, 0, 3.9]}"#.to_string());
    let roots: Vec<String> = (0..nodes.len()).map(|i| i.to_string()).collect();
    let text = format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "extensionsUsed": ["KHR_materials_specular", "KHR_materials_emissive_strength"],
  "scene": 0,
  "scenes": [{{"nodes": [{}]}}],
  "nodes": [{}],
  "meshes": [{}],
  "materials": [{}],
  "cameras": [{{"type": "perspective", "perspective": {{"yfov": {}, "aspectRatio": 1, "znear": 0.01}}}}],
  "buffers": [{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{}"}}],
  "bufferViews": [{}],
  "accessors": [{}]
}}"#,
        roots.join(", "),
        nodes.join(", "),
        gltf_meshes.join(", "),
        materials.join(", "),
        39.3077f64.to_radians(),
        buffer.len(),
        base64(&buffer),
        views.join(", "),
        accessors.join(", ")
    );
    let mut l = load(&text);
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    // glTF carries no render settings: the native box's.
    let native_box = common::integrators::load_cornell_box();
    let d = &native_box.defaults;
    (l.defaults.width, l.defaults.height) = (d.width, d.height);
    (l.defaults.max_depth, l.defaults.rr_depth) = (d.max_depth, d.rr_depth);
    l
}

/// The glTF Cornell box: diffuse walls (a coat of index 1 over the base colour), a
/// one-sided light of the native radiance.
#[test]
fn a_cornell_box_in_gltf_reads_as_the_native_one() {
    let l = cornell_box_gltf();
    let t = native(&l);
    let objects = t["objects"].as_array().unwrap();
    assert_eq!(objects.len(), 8);
    let light = objects
        .iter()
        .find(|o| o.get("emission").is_some())
        .unwrap();
    let e: Vec<f64> = light["emission"]
        .as_array()
        .unwrap()
        .iter()
        .map(number)
        .collect();
    for (got, want) in e.iter().zip([18.387, 13.9873, 6.75357]) {
        assert!((got - want).abs() < 1e-4, "{e:?}");
    }
    assert_eq!(
        light.get("two_sided").and_then(|v| v.as_bool()),
        Some(false),
        "{light:?}"
    );
    for o in objects {
        let m = &t["materials"][o["material"].as_str().unwrap()];
        assert_eq!(m["type"].as_str(), Some("coateddiffuse"), "{m:?}");
        assert!((number(&m["eta"]) - 1.0).abs() < 1e-12, "{m:?}");
    }
}

#[test]
#[ignore = "full suite (cargo test -- --include-ignored): over 10 s"]
fn a_cornell_box_in_gltf_matches_mitsubas_render() {
    common::integrators::cbox_z_test_of(
        &cornell_box_gltf(),
        plenum_core::integrator::IntegratorKind::Path,
        ColorMode::Rgb,
        "reference.exr",
        "reference-variance.exr",
        16,
        |_| {},
    );
}
