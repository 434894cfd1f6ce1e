//! PLY meshes (Turk's Stanford Triangle Format), ASCII and binary in either byte order: vertex
//! `x y z`, optional `nx ny nz` and `u v` (or `s t`, `texture_u texture_v`), and faces as a
//! `vertex_indices` (or `vertex_index`) list, fanned into triangles. Other elements and
//! properties are read past. The header and ASCII bodies give errors at line:column; a binary
//! body, which has no lines, at the element and record.

use crate::diagnostics::SceneError;
use crate::limits::check_count;
use plenum_core::geometry::TriangleMesh;
use plenum_core::math::Vec3;
use std::ops::Range;
use std::path::Path;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

#[derive(Clone, Debug)]
struct Property {
    name: String,
    /// `Some(count type)` for a list property.
    list: Option<Scalar>,
    value: Scalar,
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: u64,
    properties: Vec<Property>,
    /// Its `element` line in the header, for errors about the element as a whole.
    line: Range<usize>,
}

#[derive(Clone, Copy, PartialEq)]
enum Format {
    Ascii,
    Little,
    Big,
}

/// Reads a PLY file into a triangle mesh.
pub fn load_ply(path: &Path) -> Result<TriangleMesh, SceneError> {
    load_ply_with(path, false)
}

/// [`load_ply`], the mesh keeping its vertex indices if `keep_indices`, for data given per
/// vertex elsewhere (see `TriangleMesh::new_keeping_indices`).
pub(crate) fn load_ply_with(path: &Path, keep_indices: bool) -> Result<TriangleMesh, SceneError> {
    let bytes = std::fs::read(path)
        .map_err(|e| SceneError::file(path, format!("cannot read the mesh file: {e}")))?;
    parse_ply_with(path, &bytes, keep_indices)
}

/// Parses PLY bytes; errors are located in `path`.
#[cfg(test)]
pub fn parse_ply(path: &Path, bytes: &[u8]) -> Result<TriangleMesh, SceneError> {
    parse_ply_with(path, bytes, false)
}

pub(crate) fn parse_ply_with(
    path: &Path,
    bytes: &[u8],
    keep_indices: bool,
) -> Result<TriangleMesh, SceneError> {
    let ply = read(path, bytes)?;
    if keep_indices {
        TriangleMesh::new_keeping_indices(ply.positions, ply.triangles, ply.normals, ply.uvs)
    } else {
        TriangleMesh::new(ply.positions, ply.triangles, ply.normals, ply.uvs)
    }
    .map_err(|e| SceneError::file(path, e.to_string()))
}

/// A PLY mesh as pbrt-v4 reads it: without uvs in the file, each triangle has pbrt's corner
/// (u, v) (0, 0), (1, 0), (1, 1), and each quad (a bilinear patch in pbrt-v4) the patch's
/// (0, 0), (1, 0), (1, 1), (0, 1) at its four corners, which its two triangles share.
pub(crate) fn parse_ply_pbrt(
    path: &Path,
    bytes: &[u8],
    triangle_uvs: [[f64; 2]; 3],
) -> Result<TriangleMesh, SceneError> {
    let ply = read(path, bytes)?;
    let mesh = if !ply.uvs.is_empty() || !ply.halves.iter().any(|&h| h != Half::Whole) {
        TriangleMesh::new(ply.positions, ply.triangles, ply.normals, ply.uvs)
            .map(|m| m.with_corner_uvs(triangle_uvs))
    } else {
        // Quads' corners have (u, v) of their own: every triangle gets corners of its own.
        let corners: Vec<u32> = ply.triangles.iter().flatten().copied().collect();
        let positions = corners.iter().map(|&i| ply.positions[i as usize]).collect();
        let normals = match ply.normals.is_empty() {
            true => Vec::new(),
            false => corners.iter().map(|&i| ply.normals[i as usize]).collect(),
        };
        let uvs = ply
            .halves
            .iter()
            .flat_map(|h| match h {
                Half::Whole => triangle_uvs,
                Half::First => [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]],
                Half::Second => [[0.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
            })
            .collect();
        let triangles = (0..ply.triangles.len() as u32)
            .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
            .collect();
        TriangleMesh::new(positions, triangles, normals, uvs)
    };
    mesh.map_err(|e| SceneError::file(path, e.to_string()))
}

/// Which part of its face a triangle is.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Half {
    /// A triangle of the file, or a piece of a polygon of five or more corners.
    Whole,
    /// A quad's (f0, f1, f2) and (f0, f2, f3).
    First,
    Second,
}

/// What a PLY file holds: vertices, faces fanned into triangles.
struct Ply {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<[f64; 2]>,
    triangles: Vec<[u32; 3]>,
    halves: Vec<Half>,
}

fn read(path: &Path, bytes: &[u8]) -> Result<Ply, SceneError> {
    let end = find(bytes, b"end_header")
        .ok_or_else(|| SceneError::file(path, "not a PLY file: no `end_header` line"))?;
    let body_start = bytes[end..]
        .iter()
        .position(|&b| b == b'\n')
        .map_or(bytes.len(), |i| end + i + 1);
    let header = String::from_utf8_lossy(&bytes[..body_start]).into_owned();
    let at = |span: Range<usize>, msg: String| SceneError::at(path, &header, span, msg);
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut offset = 0;
    for (n, line) in header.split_inclusive('\n').enumerate() {
        let start = offset;
        offset += line.len();
        let words: Vec<(&str, Range<usize>)> = words(line, start);
        let Some((keyword, kspan)) = words.first().cloned() else {
            continue;
        };
        let word = |i: usize, what: &str| {
            words.get(i).cloned().ok_or_else(|| {
                at(
                    start..start + line.trim_end().len(),
                    format!("expected {what}"),
                )
            })
        };
        match keyword {
            "ply" if n == 0 => {}
            _ if n == 0 => {
                return Err(at(
                    kspan,
                    "not a PLY file: expected `ply` on the first line".into(),
                ))
            }
            "format" => {
                let (f, span) = word(1, "ascii, binary_little_endian or binary_big_endian")?;
                format = Some(match f {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::Little,
                    "binary_big_endian" => Format::Big,
                    _ => return Err(at(span, format!("unknown PLY format `{f}`"))),
                });
            }
            "comment" | "obj_info" | "end_header" => {}
            "element" => {
                let (name, _) = word(1, "an element name")?;
                let (count, span) = word(2, "an element count")?;
                let count = count
                    .parse()
                    .map_err(|_| at(span, format!("expected an element count, found `{count}`")))?;
                elements.push(Element {
                    name: name.into(),
                    count,
                    properties: Vec::new(),
                    line: start..start + line.trim_end().len(),
                });
            }
            "property" => {
                let element = elements
                    .last_mut()
                    .ok_or_else(|| at(kspan.clone(), "a property before any element".into()))?;
                let (t, span) = word(1, "a property type")?;
                let scalar = |(t, span): (&str, Range<usize>)| {
                    Scalar::parse(t).ok_or_else(|| at(span, format!("unknown property type `{t}`")))
                };
                let property = if t == "list" {
                    let count = scalar(word(2, "the list's count type")?)?;
                    let value = scalar(word(3, "the list's value type")?)?;
                    Property {
                        name: word(4, "a property name")?.0.into(),
                        list: Some(count),
                        value,
                    }
                } else {
                    let value = scalar((t, span))?;
                    Property {
                        name: word(2, "a property name")?.0.into(),
                        list: None,
                        value,
                    }
                };
                element.properties.push(property);
            }
            other => return Err(at(kspan, format!("unknown header line `{other}`"))),
        }
    }
    let format =
        format.ok_or_else(|| SceneError::file(path, "the PLY header has no `format` line"))?;
    let body = &bytes[body_start..];
    let mut reader: Box<dyn Values + '_> = match format {
        Format::Ascii => Box::new(Ascii::new(path, body, header.matches('\n').count())),
        _ => Box::new(Binary {
            path,
            data: body,
            offset: body_start,
            pos: 0,
            big: format == Format::Big,
        }),
    };
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let mut triangles = Vec::new();
    let mut halves = Vec::new();
    let mut vertices_seen = None;
    for element in &elements {
        let find = |names: &[&str]| {
            element
                .properties
                .iter()
                .position(|p| names.contains(&p.name.as_str()))
        };
        let (x, y, z) = (find(&["x"]), find(&["y"]), find(&["z"]));
        let (nx, ny, nz) = (find(&["nx"]), find(&["ny"]), find(&["nz"]));
        let (u, v) = (
            find(&["u", "s", "texture_u"]),
            find(&["v", "t", "texture_v"]),
        );
        let indices = find(&["vertex_indices", "vertex_index"]);
        let whole = |message: &str| at(element.line.clone(), message.to_string());
        // Before looping over its records: an element's count must fit in what is left of
        // the file, or a short file could ask for unbounded time.
        let record_bytes: usize = element
            .properties
            .iter()
            .map(|p| reader.least_bytes(p.list.unwrap_or(p.value)))
            .sum();
        if record_bytes == 0 {
            // No properties: its records take no bytes and hold nothing.
            match element.name.as_str() {
                "vertex" if element.count > 0 => {
                    return Err(whole("the vertex element lacks x, y or z"))
                }
                "face" if element.count > 0 => {
                    return Err(whole("the face element has no vertex_indices list"))
                }
                _ => continue,
            }
        }
        check_count(
            element.count,
            record_bytes as u64,
            reader.remaining(),
            &format!("`{}` records", element.name),
        )
        .map_err(|e| whole(&e))?;
        let mut record = vec![0.0; element.properties.len()];
        let mut list: Vec<f64> = Vec::new();
        for r in 0..element.count as usize {
            reader.start_record(&element.name, r)?;
            let mut face = None;
            for (i, p) in element.properties.iter().enumerate() {
                match p.list {
                    None => record[i] = reader.value(p.value)?,
                    Some(count_type) => {
                        let n = reader.value(count_type)?;
                        if !(0.0..=1e6).contains(&n) || n.fract() != 0.0 {
                            return Err(reader.error(format!("a list of {n} items")));
                        }
                        let least = reader.least_bytes(p.value) as u64;
                        check_count(n as u64, least, reader.remaining(), "list items")
                            .map_err(|e| reader.error(e))?;
                        list.clear();
                        for _ in 0..n as usize {
                            list.push(reader.value(p.value)?);
                        }
                        if Some(i) == indices {
                            face = Some(list.clone());
                        }
                    }
                }
            }
            if element.name == "vertex" {
                let (Some(x), Some(y), Some(z)) = (x, y, z) else {
                    return Err(whole("the vertex element lacks x, y or z"));
                };
                let p = Vec3::new(record[x], record[y], record[z]);
                if !p.is_finite() {
                    return Err(reader.error(format!("vertex {r} is not a finite point")));
                }
                positions.push(p);
                if let (Some(a), Some(b), Some(c)) = (nx, ny, nz) {
                    normals.push(Vec3::new(record[a], record[b], record[c]));
                }
                if let (Some(a), Some(b)) = (u, v) {
                    uvs.push([record[a], record[b]]);
                }
            } else if element.name == "face" {
                let face =
                    face.ok_or_else(|| whole("the face element has no vertex_indices list"))?;
                if face.len() < 3 {
                    return Err(reader.error(format!(
                        "face {r} has {} vertices; at least 3 are needed",
                        face.len()
                    )));
                }
                let count = vertices_seen.unwrap_or(positions.len());
                if let Some(&bad) = face.iter().find(|&&i| i < 0.0 || i as usize >= count) {
                    return Err(reader.error(format!(
                        "face {r} refers to vertex {bad}, but there are {count} vertices"
                    )));
                }
                for k in 1..face.len() - 1 {
                    triangles.push([face[0] as u32, face[k] as u32, face[k + 1] as u32]);
                    halves.push(match (face.len(), k) {
                        (4, 1) => Half::First,
                        (4, _) => Half::Second,
                        _ => Half::Whole,
                    });
                }
            }
        }
        if element.name == "vertex" {
            vertices_seen = Some(positions.len());
        }
    }
    if normals.len() != positions.len() {
        normals.clear();
    }
    if uvs.len() != positions.len() {
        uvs.clear();
    }
    Ok(Ply {
        positions,
        normals,
        uvs,
        triangles,
        halves,
    })
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

fn words(line: &str, base: usize) -> Vec<(&str, Range<usize>)> {
    let mut out = Vec::new();
    let mut pos = 0;
    for w in line.split_whitespace() {
        let i = line[pos..].find(w).map_or(pos, |i| pos + i);
        out.push((w, base + i..base + i + w.len()));
        pos = i + w.len();
    }
    out
}

/// Values of a PLY body, in order.
trait Values {
    fn start_record(&mut self, element: &str, index: usize) -> Result<(), SceneError>;
    fn value(&mut self, t: Scalar) -> Result<f64, SceneError>;
    /// The fewest bytes a value of type `t` takes.
    fn least_bytes(&self, t: Scalar) -> usize;
    /// Bytes not read yet.
    fn remaining(&self) -> usize;
    /// An error at the current place.
    fn error(&self, message: String) -> SceneError;
}

struct Ascii<'a> {
    path: &'a Path,
    text: String,
    /// Line number of the body's first line in the whole file, less one.
    line_base: usize,
    pos: usize,
    last: Range<usize>,
}

impl<'a> Ascii<'a> {
    fn new(path: &'a Path, body: &[u8], line_base: usize) -> Self {
        Ascii {
            path,
            text: String::from_utf8_lossy(body).into_owned(),
            line_base,
            pos: 0,
            last: 0..0,
        }
    }
}

impl Values for Ascii<'_> {
    fn start_record(&mut self, _: &str, _: usize) -> Result<(), SceneError> {
        Ok(())
    }

    fn least_bytes(&self, _: Scalar) -> usize {
        // A digit; the separator after it may be missing at the end of the file.
        1
    }

    fn remaining(&self) -> usize {
        self.text.len() - self.pos
    }

    fn value(&mut self, _: Scalar) -> Result<f64, SceneError> {
        let rest = &self.text[self.pos..];
        let skip = rest.len() - rest.trim_start().len();
        let start = self.pos + skip;
        let len = self.text[start..]
            .find(char::is_whitespace)
            .unwrap_or(self.text.len() - start);
        self.pos = start + len;
        self.last = start..start + len;
        if len == 0 {
            return Err(self.error("expected a number, found the end of the file".into()));
        }
        let token = &self.text[start..start + len];
        token
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| self.error(format!("expected a finite number, found `{token}`")))
    }

    fn error(&self, message: String) -> SceneError {
        let mut e = SceneError::at(self.path, &self.text, self.last.clone(), message);
        e.line += self.line_base;
        e
    }
}

struct Binary<'a> {
    path: &'a Path,
    data: &'a [u8],
    /// Where `data` starts in the file, for errors by byte offset.
    offset: usize,
    pos: usize,
    big: bool,
}

impl Values for Binary<'_> {
    fn start_record(&mut self, element: &str, index: usize) -> Result<(), SceneError> {
        if self.pos >= self.data.len() {
            return Err(self.error(format!(
                "the file ends before {element} {index}: it is truncated"
            )));
        }
        Ok(())
    }

    fn least_bytes(&self, t: Scalar) -> usize {
        t.size()
    }

    fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    fn value(&mut self, t: Scalar) -> Result<f64, SceneError> {
        let n = t.size();
        let Some(b) = self.data.get(self.pos..self.pos + n) else {
            return Err(self.error("the file ends inside a record: it is truncated".into()));
        };
        self.pos += n;
        let mut a = [0u8; 8];
        a[..n].copy_from_slice(b);
        if self.big {
            a[..n].reverse();
        }
        Ok(match t {
            Scalar::I8 => a[0] as i8 as f64,
            Scalar::U8 => a[0] as f64,
            Scalar::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(a),
        })
    }

    fn error(&self, message: String) -> SceneError {
        SceneError::file(
            self.path,
            format!("at byte {}: {message}", self.offset + self.pos),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = "ply\nformat ascii 1.0\ncomment a quad\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

    #[test]
    fn ascii_and_binary_quads() {
        let text = format!("{HEADER}0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
        assert_eq!(
            parse_ply(Path::new("q.ply"), text.as_bytes())
                .unwrap()
                .triangle_count(),
            2
        );
        for big in [false, true] {
            let format = if big {
                "binary_big_endian"
            } else {
                "binary_little_endian"
            };
            let mut bytes = HEADER.replace("ascii", format).into_bytes();
            for p in [
                [0f32, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ] {
                for c in p {
                    bytes.extend(if big {
                        c.to_be_bytes()
                    } else {
                        c.to_le_bytes()
                    });
                }
            }
            bytes.push(4);
            for i in [0i32, 1, 2, 3] {
                bytes.extend(if big {
                    i.to_be_bytes()
                } else {
                    i.to_le_bytes()
                });
            }
            let mesh = parse_ply(Path::new("q.ply"), &bytes).unwrap();
            assert_eq!(mesh.triangle_count(), 2);
            // The mesh numbers its vertices in its own order.
            for (x, y) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                assert!(mesh.indexed().0.contains(&Vec3::new(x, y, 0.0)));
            }
            let cut = &bytes[..bytes.len() - 3];
            assert!(parse_ply(Path::new("q.ply"), cut)
                .unwrap_err()
                .message
                .contains("truncated"));
        }
    }

    #[test]
    fn errors_are_located() {
        let text = format!("{HEADER}0 0 0\n1 nan 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
        let e = parse_ply(Path::new("q.ply"), text.as_bytes()).unwrap_err();
        assert_eq!((e.line, e.column), (12, 3));
        let text = format!("{HEADER}0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 9\n");
        let e = parse_ply(Path::new("q.ply"), text.as_bytes()).unwrap_err();
        assert_eq!(e.line, 15);
        assert!(e.message.contains("refers to vertex 9"));
        let e = parse_ply(
            Path::new("q.ply"),
            HEADER
                .replace("property float y", "property flot y")
                .as_bytes(),
        )
        .unwrap_err();
        assert_eq!((e.line, e.column), (6, 10));
        let e = parse_ply(
            Path::new("q.ply"),
            format!("{HEADER}0 0 0\n1 0 0\n").as_bytes(),
        )
        .unwrap_err();
        assert!(e.message.contains("end of the file"));
    }

    #[test]
    fn counts_the_file_cannot_hold_are_refused_at_once() {
        // An element of no properties and a count of 2^64 − 1 spun forever; so did one whose
        // records a short body could never hold. Each is an error at its header line.
        let junk = "ply\nformat ascii 1.0\nelement junk 18446744073709551615\nend_header\n";
        assert!(parse_ply(Path::new("j.ply"), junk.as_bytes()).is_err());
        let empty_face = "ply\nformat ascii 1.0\nelement face 18446744073709551615\nend_header\n";
        let e = parse_ply(Path::new("f.ply"), empty_face.as_bytes()).unwrap_err();
        assert_eq!(e.line, 3);
        assert!(e.message.contains("no vertex_indices"), "{}", e.message);
        for format in ["ascii", "binary_little_endian"] {
            let text = format!(
                "ply\nformat {format} 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n"
            );
            let e = parse_ply(Path::new("v.ply"), text.as_bytes()).unwrap_err();
            assert_eq!((e.line, e.column), (3, 1), "{format}");
            assert!(e.message.contains("asks for 4000000000"), "{}", e.message);
        }
        // A list longer than the rest of the file.
        let text = HEADER
            .replace("uchar int", "int int")
            .replace("ascii", "binary_little_endian");
        let mut bytes = text.clone().into_bytes();
        bytes.extend([0u8; 48]);
        bytes.extend(900_000i32.to_le_bytes());
        let e = parse_ply(Path::new("l.ply"), &bytes).unwrap_err();
        assert!(e.message.contains("list items"), "{}", e.message);
        assert!(
            e.message.contains(&format!("at byte {}", text.len() + 52)),
            "{}",
            e.message
        );
    }
}
