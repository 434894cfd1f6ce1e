//! Wavefront OBJ geometry: `v`, `vt`, `vn` and `f` records (polygons fanned into triangles,
//! negative indices counted from the end), with `usemtl` and `mtllib` recorded so a model can
//! be split by material (see [`crate::mtl`]). Groups and smoothing groups are read past.

use crate::diagnostics::SceneError;
use plenum_core::geometry::TriangleMesh;
use plenum_core::math::Vec3;
use std::collections::HashMap;
use std::path::Path;

/// An OBJ file read: one mesh per material used, and the material libraries it names.
pub struct ObjModel {
    /// (material name from `usemtl`, the triangles drawn with it).
    pub groups: Vec<(Option<String>, TriangleMesh)>,
    pub material_libraries: Vec<String>,
    /// One line per kind of statement read past.
    pub warnings: Vec<String>,
}

/// Parses OBJ text into one mesh of every triangle; errors are located in `path`.
#[cfg(test)]
pub fn parse_obj(path: &Path, text: &str) -> Result<TriangleMesh, SceneError> {
    let mut model = parse_obj_model(path, text, false)?;
    Ok(model.groups.remove(0).1)
}

/// Parses OBJ text; with `by_material`, one mesh per `usemtl` material.
pub fn parse_obj_model(path: &Path, text: &str, by_material: bool) -> Result<ObjModel, SceneError> {
    parse_obj_model_with(path, text, by_material, false)
}

/// [`parse_obj_model`], the meshes keeping their vertex indices if `keep_indices`, for data
/// given per vertex elsewhere (see `TriangleMesh::new_keeping_indices`).
pub(crate) fn parse_obj_model_with(
    path: &Path,
    text: &str,
    by_material: bool,
    keep_indices: bool,
) -> Result<ObjModel, SceneError> {
    let mut material_libraries = Vec::new();
    let mut material_names: Vec<Option<String>> = vec![None];
    let mut current_material = 0usize;
    let mut triangle_material: Vec<usize> = Vec::new();
    let mut skipped: Vec<(String, usize)> = Vec::new();
    let mut line_number = 0;
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    // OBJ indexes position, uv and normal separately; a mesh vertex is one distinct triple.
    let mut vertex_of: HashMap<(u32, u32, u32), u32> = HashMap::new();
    let mut out_positions = Vec::new();
    let mut out_normals = Vec::new();
    let mut out_uvs = Vec::new();
    let mut triangles = Vec::new();
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        line_number += 1;
        let start = offset;
        offset += line.len();
        let content = line.split('#').next().unwrap_or("");
        let mut tokens = tokens_with_offsets(content, start);
        let Some((keyword, _)) = tokens.next() else {
            continue;
        };
        let err =
            |span: (usize, usize), msg: String| SceneError::at(path, text, span.0..span.1, msg);
        let mut numbers = |n: usize, what: &str| -> Result<Vec<f64>, SceneError> {
            let mut out = Vec::with_capacity(n);
            for _ in 0..n {
                let Some((tok, span)) = tokens.next() else {
                    return Err(err(
                        (start, start + content.trim_end().len()),
                        format!("expected {n} numbers for {what}"),
                    ));
                };
                match tok.parse::<f64>() {
                    Ok(v) if v.is_finite() => out.push(v),
                    _ => {
                        return Err(err(
                            span,
                            format!("expected a finite number, found `{tok}`"),
                        ))
                    }
                }
            }
            Ok(out)
        };
        match keyword {
            "v" => {
                let v = numbers(3, "a vertex position")?;
                positions.push(Vec3::new(v[0], v[1], v[2]));
            }
            "vn" => {
                let v = numbers(3, "a vertex normal")?;
                normals.push(Vec3::new(v[0], v[1], v[2]));
            }
            "vt" => {
                let v = numbers(2, "a texture coordinate")?;
                uvs.push([v[0], v[1]]);
            }
            "usemtl" => {
                let name = tokens.next().map(|(t, _)| t.to_string());
                current_material = match material_names.iter().position(|m| *m == name) {
                    Some(i) => i,
                    None => {
                        material_names.push(name);
                        material_names.len() - 1
                    }
                };
            }
            "mtllib" => material_libraries.extend(tokens.by_ref().map(|(t, _)| t.to_string())),
            "f" => {
                let mut corners = Vec::new();
                for (tok, span) in tokens.by_ref() {
                    let mut parts = tok.split('/');
                    let resolve = |s: Option<&str>,
                                   count: usize,
                                   what: &str|
                     -> Result<u32, SceneError> {
                        match s {
                            None | Some("") => Ok(u32::MAX),
                            Some(s) => {
                                let i: i64 = s.parse().map_err(|_| {
                                    err(span, format!("expected a {what} index, found `{s}`"))
                                })?;
                                let resolved = if i < 0 { count as i64 + i } else { i - 1 };
                                if i == 0 || resolved < 0 || resolved >= count as i64 {
                                    return Err(err(span, format!("{what} index {i} is out of range: there are {count} so far")));
                                }
                                Ok(resolved as u32)
                            }
                        }
                    };
                    let p = resolve(parts.next(), positions.len(), "vertex")?;
                    if p == u32::MAX {
                        return Err(err(span, "a face corner needs a vertex index".into()));
                    }
                    let t = resolve(parts.next(), uvs.len(), "texture coordinate")?;
                    let n = resolve(parts.next(), normals.len(), "normal")?;
                    let key = (p, t, n);
                    let index = *vertex_of.entry(key).or_insert_with(|| {
                        out_positions.push(positions[p as usize]);
                        out_normals.push(if n == u32::MAX {
                            Vec3::ZERO
                        } else {
                            normals[n as usize]
                        });
                        out_uvs.push(if t == u32::MAX {
                            [0.0, 0.0]
                        } else {
                            uvs[t as usize]
                        });
                        (out_positions.len() - 1) as u32
                    });
                    corners.push(index);
                }
                if corners.len() < 3 {
                    return Err(err(
                        (start, start + content.trim_end().len()),
                        format!("a face needs at least 3 corners, found {}", corners.len()),
                    ));
                }
                for i in 1..corners.len() - 1 {
                    triangles.push([corners[0], corners[i], corners[i + 1]]);
                    triangle_material.push(current_material);
                }
            }
            "g" | "o" | "s" => {}
            other => {
                if !skipped.iter().any(|(k, _)| k == other) {
                    skipped.push((other.to_string(), line_number));
                }
            }
        }
    }
    // Shading normals only when every vertex has one.
    if normals.is_empty() || out_normals.iter().any(|n| n.length_squared() == 0.0) {
        out_normals.clear();
    }
    if uvs.is_empty() {
        out_uvs.clear();
    }
    let build = |tris: Vec<[u32; 3]>| {
        let (positions, normals, uvs) =
            (out_positions.clone(), out_normals.clone(), out_uvs.clone());
        if keep_indices {
            TriangleMesh::new_keeping_indices(positions, tris, normals, uvs)
        } else {
            TriangleMesh::new(positions, tris, normals, uvs)
        }
        .map_err(|e| SceneError::file(path, e.to_string()))
    };
    // A group's mesh takes only the vertices its triangles use: all of them, in each of a
    // few thousand `usemtl` groups of a 100 KB file, came to gigabytes.
    let compact = |tris: Vec<[u32; 3]>| {
        let mut index_of: HashMap<u32, u32> = HashMap::new();
        let mut used = Vec::new();
        let tris: Vec<[u32; 3]> = tris
            .iter()
            .map(|t| {
                t.map(|v| {
                    *index_of.entry(v).or_insert_with(|| {
                        used.push(v as usize);
                        used.len() as u32 - 1
                    })
                })
            })
            .collect();
        // Normals and uvs may have been dropped (empty) for the whole model.
        fn pick<T: Copy>(all: &[T], used: &[usize]) -> Vec<T> {
            match all.is_empty() {
                true => Vec::new(),
                false => used.iter().map(|&v| all[v]).collect(),
            }
        }
        let (positions, normals, uvs) = (
            pick(&out_positions, &used),
            pick(&out_normals, &used),
            pick(&out_uvs, &used),
        );
        if keep_indices {
            TriangleMesh::new_keeping_indices(positions, tris, normals, uvs)
        } else {
            TriangleMesh::new(positions, tris, normals, uvs)
        }
        .map_err(|e| SceneError::file(path, e.to_string()))
    };
    let groups = if by_material {
        let mut groups = Vec::new();
        for (m, name) in material_names.iter().enumerate() {
            let tris: Vec<[u32; 3]> = triangles
                .iter()
                .zip(&triangle_material)
                .filter(|(_, &tm)| tm == m)
                .map(|(t, _)| *t)
                .collect();
            if !tris.is_empty() {
                groups.push((name.clone(), compact(tris)?));
            }
        }
        if groups.is_empty() {
            groups.push((None, build(triangles)?));
        }
        groups
    } else {
        vec![(None, build(triangles)?)]
    };
    let warnings = skipped
        .into_iter()
        .map(|(k, line)| {
            format!(
                "warning: {}:{line}: `{k}` statements are not supported and are skipped",
                path.display()
            )
        })
        .collect();
    Ok(ObjModel {
        groups,
        material_libraries,
        warnings,
    })
}

/// Whitespace-separated tokens with their byte spans in the whole text.
fn tokens_with_offsets(line: &str, base: usize) -> impl Iterator<Item = (&str, (usize, usize))> {
    let mut rest = line;
    let mut pos = base;
    std::iter::from_fn(move || {
        let trimmed = rest.trim_start();
        pos += rest.len() - trimmed.len();
        if trimmed.is_empty() {
            return None;
        }
        let end = trimmed.find(char::is_whitespace).unwrap_or(trimmed.len());
        let tok = &trimmed[..end];
        let span = (pos, pos + end);
        pos += end;
        rest = &trimmed[end..];
        Some((tok, span))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_with_negative_indices_and_normals() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf -4//1 -3//1 -2//1 -1//1\n";
        let mesh = parse_obj(Path::new("q.obj"), text).unwrap();
        assert_eq!(mesh.triangle_count(), 2);
    }

    #[test]
    fn unsupported_statements_warn_once_each() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\ncurv 0 1 1 2\ncurv 0 1 1 2\nl 1 2\nf 1 2 3\n";
        let model = parse_obj_model(Path::new("w.obj"), text, false).unwrap();
        assert_eq!(model.warnings.len(), 2, "{:?}", model.warnings);
        assert!(model.warnings[0].contains("w.obj:4: `curv`"));
    }

    #[test]
    fn errors_are_located() {
        let e = parse_obj(Path::new("bad.obj"), "v 0 0 0\nv 1 nan 0\n").unwrap_err();
        assert_eq!((e.line, e.column), (2, 5));
        let e =
            parse_obj(Path::new("bad.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n").unwrap_err();
        assert_eq!((e.line, e.column), (4, 7));
        assert!(e.message.contains("out of range"), "{}", e.message);
    }

    #[test]
    fn each_material_group_holds_only_its_own_vertices() {
        // 2000 one-triangle groups with normals over 6000 corners: each group's mesh kept
        // the normals of all 6000 (290 MB).
        let mut text: String = (0..6000).map(|i| format!("v {i} 0 {}\n", i % 7)).collect();
        text += "vn 0 0 1\n";
        for g in 0..2000 {
            let v = g * 3 + 1;
            text += &format!("usemtl m{g}\nf {v}//1 {}//1 {}//1\n", v + 1, v + 2);
        }
        let model = parse_obj_model(Path::new("g.obj"), &text, true).unwrap();
        assert_eq!(model.groups.len(), 2000);
        let bytes: usize = model.groups.iter().map(|(_, m)| m.memory_bytes()).sum();
        assert!(bytes < 16 << 20, "{bytes} bytes");
    }
}
