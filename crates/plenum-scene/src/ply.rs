//! PLY meshes, ASCII and binary (Turk's Stanford Triangle Format), read with `ply-rs-bw`:
//! vertex `x y z`, optional `nx ny nz` and `u v` (or `s t`, `texture_u texture_v`), and
//! faces as `vertex_indices` (or `vertex_index`) lists, fanned into triangles.

use crate::diagnostics::SceneError;
use plenum_core::geometry::TriangleMesh;
use plenum_core::math::Vec3;
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};
use std::path::Path;

fn scalar(e: &DefaultElement, names: &[&str]) -> Option<f64> {
    names.iter().find_map(|n| match e.get(*n)? {
        Property::Float(v) => Some(*v as f64),
        Property::Double(v) => Some(*v),
        Property::Char(v) => Some(*v as f64),
        Property::UChar(v) => Some(*v as f64),
        Property::Short(v) => Some(*v as f64),
        Property::UShort(v) => Some(*v as f64),
        Property::Int(v) => Some(*v as f64),
        Property::UInt(v) => Some(*v as f64),
        _ => None,
    })
}

fn indices(e: &DefaultElement) -> Option<Vec<i64>> {
    ["vertex_indices", "vertex_index"]
        .iter()
        .find_map(|n| match e.get(*n)? {
            Property::ListChar(v) => Some(v.iter().map(|&i| i as i64).collect()),
            Property::ListUChar(v) => Some(v.iter().map(|&i| i as i64).collect()),
            Property::ListShort(v) => Some(v.iter().map(|&i| i as i64).collect()),
            Property::ListUShort(v) => Some(v.iter().map(|&i| i as i64).collect()),
            Property::ListInt(v) => Some(v.iter().map(|&i| i as i64).collect()),
            Property::ListUInt(v) => Some(v.iter().map(|&i| i as i64).collect()),
            _ => None,
        })
}

/// Reads a PLY file into a triangle mesh.
pub fn load_ply(path: &Path) -> Result<TriangleMesh, SceneError> {
    let fail = |msg: String| SceneError::file(path, msg);
    let file =
        std::fs::File::open(path).map_err(|e| fail(format!("cannot read the mesh file: {e}")))?;
    let mut reader = std::io::BufReader::new(file);
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut reader)
        .map_err(|e| fail(format!("not a valid PLY file: {e}")))?;
    let vertices = ply
        .payload
        .get("vertex")
        .ok_or_else(|| fail("the file has no `vertex` element".into()))?;
    let faces = ply
        .payload
        .get("face")
        .ok_or_else(|| fail("the file has no `face` element".into()))?;
    let mut positions = Vec::with_capacity(vertices.len());
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    for (i, v) in vertices.iter().enumerate() {
        let p = match (scalar(v, &["x"]), scalar(v, &["y"]), scalar(v, &["z"])) {
            (Some(x), Some(y), Some(z)) => Vec3::new(x, y, z),
            _ => return Err(fail(format!("vertex {i} lacks x, y or z"))),
        };
        positions.push(p);
        if let (Some(x), Some(y), Some(z)) =
            (scalar(v, &["nx"]), scalar(v, &["ny"]), scalar(v, &["nz"]))
        {
            normals.push(Vec3::new(x, y, z));
        }
        if let (Some(u), Some(w)) = (
            scalar(v, &["u", "s", "texture_u"]),
            scalar(v, &["v", "t", "texture_v"]),
        ) {
            uvs.push([u, w]);
        }
    }
    let mut triangles = Vec::with_capacity(faces.len());
    for (f, face) in faces.iter().enumerate() {
        let idx =
            indices(face).ok_or_else(|| fail(format!("face {f} has no vertex_indices list")))?;
        if idx.len() < 3 {
            return Err(fail(format!(
                "face {f} has {} vertices; at least 3 are needed",
                idx.len()
            )));
        }
        if let Some(&bad) = idx
            .iter()
            .find(|&&i| i < 0 || i as usize >= positions.len())
        {
            return Err(fail(format!(
                "face {f} refers to vertex {bad}, but there are {} vertices",
                positions.len()
            )));
        }
        for k in 1..idx.len() - 1 {
            triangles.push([idx[0] as u32, idx[k] as u32, idx[k + 1] as u32]);
        }
    }
    if normals.len() != positions.len() {
        normals.clear();
    }
    if uvs.len() != positions.len() {
        uvs.clear();
    }
    TriangleMesh::new(positions, triangles, normals, uvs).map_err(|e| fail(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_quad_and_errors() {
        let dir = std::env::temp_dir().join(format!("plenum-ply-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let good = dir.join("quad.ply");
        std::fs::write(&good, "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n").unwrap();
        assert_eq!(load_ply(&good).unwrap().triangle_count(), 2);
        let bad = dir.join("bad.ply");
        std::fs::write(&bad, "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n3 0 1 2\n").unwrap();
        assert!(load_ply(&bad)
            .unwrap_err()
            .message
            .contains("refers to vertex 1"));
        let truncated = dir.join("cut.ply");
        std::fs::write(
            &truncated,
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n",
        )
        .unwrap();
        assert!(load_ply(&truncated).is_err());
        std::fs::remove_dir_all(&dir).ok();
    }
}
