//! Fuzz targets, one per reader: any bytes give a scene or an error, never a panic, an
//! abort, a hang or a huge allocation. Under `cargo test` bolero runs each on random inputs
//! for a short while; the same bodies run for longer under cargo-fuzz (`fuzz/`, see
//! docs/robustness.md).

use std::path::Path;

/// The reader for `extension` on arbitrary bytes. Relative paths inside resolve against a
/// folder that does not exist, so a mutated file name reads nothing.
fn read(extension: &str, bytes: &[u8]) {
    let path = Path::new("/nonexistent-plenum-fuzz").join(format!("input.{extension}"));
    if let Err(e) = plenum_scene::read_scene(&path, extension, bytes.to_vec()) {
        // Every error shows: its display must not panic either.
        let _ = e.to_string();
    }
}

#[test]
fn toml() {
    bolero::check!().for_each(|bytes: &[u8]| read("toml", bytes));
}

#[test]
fn nff() {
    bolero::check!().for_each(|bytes: &[u8]| read("nff", bytes));
}

#[test]
fn ray() {
    bolero::check!().for_each(|bytes: &[u8]| read("ray", bytes));
}

#[test]
fn obj() {
    bolero::check!().for_each(|bytes: &[u8]| read("obj", bytes));
}

#[test]
fn mtl() {
    bolero::check!().for_each(|bytes: &[u8]| {
        let path = Path::new("/nonexistent-plenum-fuzz/input.mtl");
        let _ = plenum_scene::read_material_library(path, bytes.to_vec());
    });
}

#[test]
fn ply() {
    bolero::check!().for_each(|bytes: &[u8]| read("ply", bytes));
}

/// Structured inputs reach deeper than random bytes: a valid header and records of random
/// numbers, counts and keywords.
#[test]
fn ply_records() {
    bolero::check!()
        .with_type::<(u8, Vec<(u8, i32)>)>()
        .for_each(|(format, values)| {
            let format = ["ascii", "binary_little_endian", "binary_big_endian"][*format as usize % 3];
            let mut bytes = format!("ply\nformat {format} 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n").into_bytes();
            for (kind, v) in values {
                match (format, kind % 2) {
                    ("ascii", _) => bytes.extend(format!("{v} ").bytes()),
                    (_, 0) => bytes.push(*v as u8),
                    _ => bytes.extend(v.to_le_bytes()),
                }
            }
            read("ply", &bytes);
        });
}

#[test]
fn xml() {
    bolero::check!().for_each(|bytes: &[u8]| read("xml", bytes));
}

/// Mitsuba scenes of random elements, nested at random but well formed: parameters,
/// references (forward, unknown, to themselves), substitutions and transforms reach the
/// plugin layer.
#[test]
fn xml_elements() {
    // Containers: opened, and closed later by a pop or at the end.
    const OPEN: &[(&str, &str)] = &[
        ("<shape type=\"sphere\">", "</shape>"),
        ("<shape type=\"rectangle\" id=\"r\">", "</shape>"),
        ("<shape type=\"cylinder\">", "</shape>"),
        (
            "<shape type=\"obj\"><string name=\"filename\" value=\"m.obj\"/>",
            "</shape>",
        ),
        ("<bsdf type=\"diffuse\" id=\"a\">", "</bsdf>"),
        ("<bsdf type=\"twosided\" id=\"t\">", "</bsdf>"),
        ("<bsdf type=\"blendbsdf\" id=\"b\">", "</bsdf>"),
        ("<bsdf type=\"roughconductor\">", "</bsdf>"),
        ("<bsdf type=\"plastic\">", "</bsdf>"),
        ("<emitter type=\"area\">", "</emitter>"),
        ("<emitter type=\"point\">", "</emitter>"),
        ("<emitter type=\"spot\">", "</emitter>"),
        (
            "<emitter type=\"envmap\"><string name=\"filename\" value=\"e.exr\"/>",
            "</emitter>",
        ),
        ("<sensor type=\"perspective\">", "</sensor>"),
        (
            "<sensor type=\"thinlens\"><float name=\"aperture_radius\" value=\"V\"/>",
            "</sensor>",
        ),
        ("<film type=\"hdrfilm\">", "</film>"),
        ("<integrator type=\"path\">", "</integrator>"),
        (
            "<texture type=\"checkerboard\" name=\"reflectance\">",
            "</texture>",
        ),
    ];
    const LEAF: &[&str] = &[
        "<ref id=\"a\"/>",
        "<ref id=\"b\"/>",
        "<ref id=\"t\"/>",
        "<ref name=\"bsdf\" id=\"x\"/>",
        "<float name=\"radius\" value=\"V\"/>",
        "<float name=\"alpha\" value=\"V\"/>",
        "<float name=\"weight\" value=\"V\"/>",
        "<float name=\"fov\" value=\"$f\"/>",
        "<default name=\"f\" value=\"V\"/>",
        "<integer name=\"width\" value=\"V\"/>",
        "<integer name=\"max_depth\" value=\"V\"/>",
        "<rgb name=\"reflectance\" value=\"V V V\"/>",
        "<rgb name=\"radiance\" value=\"V\"/>",
        "<spectrum name=\"radiance\" value=\"400:V, 500:V\"/>",
        "<point name=\"center\" x=\"V\" y=\"V\" z=\"V\"/>",
        "<point name=\"p1\" value=\"V\"/>",
        "<transform name=\"to_world\"><scale value=\"V\"/><rotate y=\"1\" angle=\"V\"/></transform>",
        "<transform name=\"to_world\"><lookat origin=\"0 0 V\" target=\"0 0 0\" up=\"0 1 0\"/></transform>",
        "<transform name=\"to_world\"><matrix value=\"V 0 0 0 0 V 0 0 0 0 V 0 0 0 0 1\"/></transform>",
        "<rfilter type=\"gaussian\"/>",
        "<sampler type=\"stratified\"><integer name=\"sample_count\" value=\"V\"/></sampler>",
        "<include filename=\"other.xml\"/>",
    ];
    bolero::check!()
        .with_type::<Vec<(u8, i16)>>()
        .for_each(|items| {
            let mut text = String::from("<scene version=\"3.0.0\">");
            let mut open = Vec::new();
            for (piece, v) in items {
                let value = format!("{}", *v as f64 / 100.0);
                let i = *piece as usize;
                match i % 3 {
                    0 => {
                        let (start, end) = OPEN[i / 3 % OPEN.len()];
                        text.push_str(&start.replace('V', &value));
                        open.push(end);
                    }
                    1 => text.push_str(open.pop().unwrap_or("")),
                    _ => text.push_str(&LEAF[i / 3 % LEAF.len()].replace('V', &value)),
                }
            }
            while let Some(end) = open.pop() {
                text.push_str(end);
            }
            text.push_str("</scene>");
            read("xml", text.as_bytes());
        });
}

#[test]
fn gltf() {
    bolero::check!().for_each(|bytes: &[u8]| {
        read("gltf", bytes);
        read("glb", bytes);
    });
}

/// A valid glTF (a square in an embedded buffer, a camera, a light, a material) with random
/// bytes overwritten: counts, offsets, indices, types and nesting go wrong in every way a
/// file can be damaged, past the JSON parser.
#[test]
fn gltf_mutations() {
    const VALID: &str = r#"{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1, 2]}],
"nodes": [{"mesh": 0, "translation": [1, 0, 0], "children": [3]}, {"camera": 0, "translation": [0, 0, 4]},
{"extensions": {"KHR_lights_punctual": {"light": 0}}}, {"mesh": 0, "scale": [2, 2, 2]}],
"cameras": [{"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}}],
"extensions": {"KHR_lights_punctual": {"lights": [{"type": "spot", "intensity": 5}]}},
"meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 2}, "indices": 1, "material": 0}]}],
"materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0.5}, "emissiveFactor": [0, 0, 0]}],
"buffers": [{"byteLength": 60, "uri": "data:application/octet-stream;base64,AAAAvwAAAL8AAAAAAAAAPwAAAL8AAAAAAAAAPwAAAD8AAAAAAAAAvwAAAD8AAAAAAAABAAIAAAACAAMA"}],
"bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
"accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-0.5, -0.5, 0], "max": [0.5, 0.5, 0]},
{"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC2", "byteOffset": 4}]}"#;
    bolero::check!()
        .with_type::<Vec<(u16, u8)>>()
        .for_each(|edits| {
            let mut bytes = VALID.as_bytes().to_vec();
            for (at, b) in edits.iter().take(8) {
                let i = *at as usize % bytes.len();
                // Digits and structure more often than arbitrary bytes.
                bytes[i] = match b % 4 {
                    0 => b'0' + b % 10,
                    1 => b"[]{},:\"-"[(*b as usize / 4) % 8],
                    _ => *b,
                };
            }
            read("gltf", &bytes);
        });
}

#[test]
fn pbrt() {
    bolero::check!().for_each(|bytes: &[u8]| read("pbrt", bytes));
}

/// pbrt-v4 statements of random directives, parameters and numbers: the graphics state's
/// stack, transformations (at the start and end times too), `Attribute`, named materials
/// and objects, meshes with bad indices, the orthographic camera.
#[test]
fn pbrt_statements() {
    const PIECES: &[&str] = &[
        "AttributeBegin\n",
        "AttributeEnd\n",
        "Translate V V V\n",
        "Scale V V V\n",
        "Rotate V 0 1 0\n",
        "LookAt 0 0 V  0 0 0  0 1 0\n",
        "ConcatTransform [ V 0 0 0 0 V 0 0 0 0 V 0 0 0 0 1 ]\n",
        "ReverseOrientation\n",
        "Camera \"perspective\" \"float fov\" V\n",
        "Film \"rgb\" \"integer xresolution\" V \"integer yresolution\" 8\n",
        "WorldBegin\n",
        "Material \"diffuse\" \"rgb reflectance\" [ V V V ]\n",
        "MakeNamedMaterial \"m\" \"string type\" \"conductor\" \"float roughness\" V\n",
        "NamedMaterial \"m\"\n",
        "Texture \"t\" \"spectrum\" \"checkerboard\" \"float uscale\" V\n",
        "Material \"coateddiffuse\" \"texture reflectance\" \"t\" \"float g\" V\n",
        "AreaLightSource \"diffuse\" \"blackbody L\" V\n",
        "LightSource \"spot\" \"float coneangle\" V \"point3 to\" [ V 0 1 ]\n",
        "LightSource \"infinite\" \"rgb L\" [ V V V ]\n",
        "Shape \"sphere\" \"float radius\" V\n",
        "Shape \"disk\" \"float radius\" V\n",
        "Shape \"cylinder\" \"float zmax\" V\n",
        "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 V 0 ] \"integer indices\" [ 0 1 V ]\n",
        "Shape \"bilinearmesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 1 1 V ]\n",
        "ObjectBegin \"o\"\n",
        "ObjectEnd\n",
        "ObjectInstance \"o\"\n",
        "Include \"other.pbrt\"\n",
        "ActiveTransform StartTime\n",
        "ActiveTransform EndTime\n",
        "ActiveTransform All\n",
        "TransformTimes 0 V\n",
        "CoordinateSystem \"c\"\n",
        "CoordSysTransform \"c\"\n",
        "Attribute \"shape\" \"float radius\" V\n",
        "Attribute \"light\" \"float scale\" V\n",
        "Camera \"orthographic\" \"float screenwindow\" [ -V V -1 1 ] \"float shutterclose\" V\n",
    ];
    bolero::check!()
        .with_type::<Vec<(u8, i16)>>()
        .for_each(|items| {
            let mut text = String::new();
            for (piece, v) in items {
                let value = format!("{}", *v as f64 / 100.0);
                text.push_str(&PIECES[*piece as usize % PIECES.len()].replace('V', &value));
            }
            read("pbrt", text.as_bytes());
        });
}
