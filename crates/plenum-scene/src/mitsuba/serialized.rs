//! Mitsuba's `.serialized` meshes, as its documentation of the `serialized` plugin describes
//! the format: little-endian; per mesh a 2-byte identifier 0x041C and a 2-byte version (3 or
//! 4), then a zlib stream of flags, the name (version 4), the vertex and triangle counts,
//! positions, optional normals, texture coordinates and colours (in f32 or f64), and the
//! triangles' indices (u32, or u64 past 2³² vertices); the file ends with each mesh's byte
//! offset (u64 in version 4, u32 in 3) and their count (u32).

use crate::limits::check_count;
use flate2::read::ZlibDecoder;
use plenum_core::math::Vec3;
use std::io::Read;

const IDENTIFIER: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_TEXCOORDS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const FACE_NORMALS: u32 = 0x0010;
const DOUBLE_PRECISION: u32 = 0x2000;

/// One mesh of a file, its (u, v) in Mitsuba's convention (v down the image).
#[derive(Debug, Default)]
pub struct SerializedMesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub uvs: Vec<[f64; 2]>,
    pub triangles: Vec<[u32; 3]>,
    /// The file asks for face normals (its flag 0x0010).
    pub face_normals: bool,
}

/// Mesh `index` of the file's `bytes`; an error says what is wrong and at which byte of the
/// file (or of the mesh's decompressed stream).
pub fn parse(bytes: &[u8], index: u32) -> Result<SerializedMesh, String> {
    let header = |at: usize| -> Result<u16, String> {
        bytes
            .get(at..at + 2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
            .ok_or_else(|| format!("byte {at}: the file ends inside a mesh's header"))
    };
    if header(0)? != IDENTIFIER {
        return Err(format!(
            "byte 0: not a serialized mesh (expected the identifier 0x041C, found {:#06x})",
            header(0)?
        ));
    }
    let version = header(2)?;
    if version != 3 && version != 4 {
        return Err(format!("byte 2: version {version}: expected 3 or 4"));
    }
    let start = if index == 0 {
        0
    } else {
        mesh_offset(bytes, index, version)?
    };
    if header(start)? != IDENTIFIER || header(start + 2)? != version {
        return Err(format!(
            "byte {start}: mesh {index} does not start with the file's header"
        ));
    }
    // The stream cannot be longer than 1032 times the compressed bytes (deflate's most), so
    // counts are checked against that before anything is allocated for them.
    let compressed = &bytes[start + 4..];
    let most = compressed.len().saturating_mul(1032);
    let mut stream = Stream {
        reader: ZlibDecoder::new(compressed),
        at: 0,
        most,
    };
    let flags = stream.u32()?;
    if version == 4 {
        stream.skip_name()?;
    }
    let vertices = stream.u64()?;
    let faces = stream.u64()?;
    let real = if flags & DOUBLE_PRECISION != 0 { 8 } else { 4 };
    let left = stream.most.saturating_sub(stream.at);
    check_count(vertices, 3 * real, left, "vertices").map_err(|e| stream.here(e))?;
    check_count(faces, 12, left, "triangles").map_err(|e| stream.here(e))?;
    let vec3s = |s: &mut Stream<'_>| -> Result<Vec<Vec3>, String> {
        (0..vertices)
            .map(|_| Ok(Vec3::new(s.real(real)?, s.real(real)?, s.real(real)?)))
            .collect()
    };
    let positions = vec3s(&mut stream)?;
    let normals = match flags & HAS_NORMALS {
        0 => Vec::new(),
        _ => vec3s(&mut stream)?,
    };
    let uvs = match flags & HAS_TEXCOORDS {
        0 => Vec::new(),
        _ => (0..vertices)
            .map(|_| Ok([stream.real(real)?, stream.real(real)?]))
            .collect::<Result<_, String>>()?,
    };
    if flags & HAS_COLORS != 0 {
        vec3s(&mut stream)?;
    }
    let wide = vertices > u32::MAX as u64;
    let triangles = (0..faces)
        .map(|_| {
            let mut t = [0u32; 3];
            for i in &mut t {
                let at = stream.at;
                let v = if wide {
                    stream.u64()?
                } else {
                    stream.u32()? as u64
                };
                *i = u32::try_from(v).map_err(|_| {
                    format!("byte {at} of the mesh's stream: index {v} is too large")
                })?;
            }
            Ok(t)
        })
        .collect::<Result<_, String>>()?;
    Ok(SerializedMesh {
        positions,
        normals,
        uvs,
        triangles,
        face_normals: flags & FACE_NORMALS != 0,
    })
}

/// Where mesh `index` starts, from the dictionary at the end of the file.
fn mesh_offset(bytes: &[u8], index: u32, version: u16) -> Result<usize, String> {
    let n = bytes.len();
    let read = |at: usize, width: usize| -> Option<u64> {
        let b = bytes.get(at..at.checked_add(width)?)?;
        Some(b.iter().rev().fold(0u64, |a, &x| (a << 8) | x as u64))
    };
    let count = n
        .checked_sub(4)
        .and_then(|at| read(at, 4))
        .ok_or("the file is too short to end with its dictionary of meshes")?;
    if index as u64 >= count {
        return Err(format!(
            "shape_index {index}: the file holds {count} mesh{}",
            if count == 1 { "" } else { "es" }
        ));
    }
    let width = if version == 4 { 8 } else { 4 };
    let entry = (count - index as u64)
        .checked_mul(width as u64)
        .and_then(|back| (n as u64).checked_sub(4 + back))
        .ok_or("the dictionary of meshes at the end of the file is cut short")?
        as usize;
    let offset = read(entry, width).ok_or("the dictionary of meshes is cut short")?;
    usize::try_from(offset)
        .ok()
        .filter(|&o| o < n)
        .ok_or_else(|| {
            format!("byte {entry}: mesh {index} is said to start past the end of the file")
        })
}

/// The decompressed stream of one mesh, read value by value.
struct Stream<'b> {
    reader: ZlibDecoder<&'b [u8]>,
    /// Bytes read so far.
    at: usize,
    /// The longest the stream can be.
    most: usize,
}

impl Stream<'_> {
    fn here(&self, e: String) -> String {
        format!("byte {} of the mesh's stream: {e}", self.at)
    }

    fn bytes<const N: usize>(&mut self) -> Result<[u8; N], String> {
        let mut b = [0u8; N];
        self.reader.read_exact(&mut b).map_err(|e| {
            self.here(match e.kind() {
                std::io::ErrorKind::UnexpectedEof => "the mesh's data ends early".to_string(),
                _ => format!("the compressed data is damaged ({e})"),
            })
        })?;
        self.at += N;
        Ok(b)
    }

    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.bytes()?))
    }

    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.bytes()?))
    }

    fn real(&mut self, width: u64) -> Result<f64, String> {
        let at = self.at;
        let x = match width {
            8 => f64::from_le_bytes(self.bytes()?),
            _ => f32::from_le_bytes(self.bytes()?) as f64,
        };
        if x.is_finite() {
            Ok(x)
        } else {
            Err(format!(
                "byte {at} of the mesh's stream: a value that is not finite"
            ))
        }
    }

    /// Past the mesh's null-terminated name (at most 64 KiB; Plenum names shapes itself).
    fn skip_name(&mut self) -> Result<(), String> {
        for _ in 0..=1 << 16 {
            if self.bytes::<1>()?[0] == 0 {
                return Ok(());
            }
        }
        Err(self.here("the mesh's name has no end".to_string()))
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use flate2::write::ZlibEncoder;
    use std::io::Write;

    /// A file of `meshes` (positions, triangles, uvs), written as the format says, in f32 or
    /// f64 and version 3 or 4.
    pub(crate) fn write(
        meshes: &[(Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<[f64; 2]>)],
        double: bool,
        version: u16,
    ) -> Vec<u8> {
        let mut out = Vec::new();
        let mut offsets = Vec::new();
        for (i, (positions, triangles, uvs)) in meshes.iter().enumerate() {
            offsets.push(out.len() as u64);
            out.extend(IDENTIFIER.to_le_bytes());
            out.extend(version.to_le_bytes());
            let mut z = ZlibEncoder::new(Vec::new(), flate2::Compression::default());
            let mut flags = if double { DOUBLE_PRECISION } else { 0x1000 };
            if !uvs.is_empty() {
                flags |= HAS_TEXCOORDS;
            }
            z.write_all(&flags.to_le_bytes()).unwrap();
            if version == 4 {
                z.write_all(format!("mesh {i}\0").as_bytes()).unwrap();
            }
            z.write_all(&(positions.len() as u64).to_le_bytes())
                .unwrap();
            z.write_all(&(triangles.len() as u64).to_le_bytes())
                .unwrap();
            let mut real = |x: f64| {
                if double {
                    z.write_all(&x.to_le_bytes()).unwrap()
                } else {
                    z.write_all(&(x as f32).to_le_bytes()).unwrap()
                }
            };
            positions.iter().flatten().for_each(|&x| real(x));
            uvs.iter().flatten().for_each(|&x| real(x));
            for i in triangles.iter().flatten() {
                z.write_all(&i.to_le_bytes()).unwrap();
            }
            out.extend(z.finish().unwrap());
        }
        for o in &offsets {
            if version == 4 {
                out.extend(o.to_le_bytes());
            } else {
                out.extend((*o as u32).to_le_bytes());
            }
        }
        out.extend((meshes.len() as u32).to_le_bytes());
        out
    }

    fn square(z: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<[f64; 2]>) {
        (
            vec![[0.0, 0.0, z], [1.0, 0.0, z], [1.0, 1.0, z], [0.0, 1.0, z]],
            vec![[0, 1, 2], [0, 2, 3]],
            vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
        )
    }

    #[test]
    fn every_mesh_of_a_file_is_read_in_either_precision_and_version() {
        for (double, version) in [(false, 4), (true, 4), (false, 3)] {
            let file = write(&[square(0.0), square(2.5)], double, version);
            for index in [0, 1] {
                let m = parse(&file, index).unwrap();
                assert_eq!(m.positions.len(), 4);
                assert_eq!(m.positions[2], Vec3::new(1.0, 1.0, 2.5 * index as f64));
                assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
                assert_eq!(m.uvs[3], [0.0, 1.0]);
            }
            let e = parse(&file, 2).unwrap_err();
            assert!(e.contains("holds 2 meshes"), "{e}");
        }
    }

    #[test]
    fn damaged_files_are_refused_with_where() {
        let file = write(&[square(0.0)], false, 4);
        assert!(parse(&file[..1], 0).unwrap_err().contains("byte 0"));
        let mut wrong = file.clone();
        wrong[0] = 0;
        assert!(parse(&wrong, 0).unwrap_err().contains("identifier"));
        // Cut inside the compressed stream.
        let e = parse(&file[..file.len() / 2], 0).unwrap_err();
        assert!(e.contains("of the mesh's stream"), "{e}");
        // A count no stream of this size can hold.
        let mut z = ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        z.write_all(&0x1000u32.to_le_bytes()).unwrap();
        z.write_all(b"x\0").unwrap();
        z.write_all(&u64::MAX.to_le_bytes()).unwrap();
        z.write_all(&1u64.to_le_bytes()).unwrap();
        let mut huge = vec![0x1C, 0x04, 4, 0];
        huge.extend(z.finish().unwrap());
        let e = parse(&huge, 0).unwrap_err();
        assert!(e.contains("vertices"), "{e}");
        // Every prefix and a flipped byte anywhere: an error or a mesh, never a panic.
        for cut in 0..file.len() {
            let _ = parse(&file[..cut], 0);
            let mut flipped = file.clone();
            flipped[cut] ^= 0x5A;
            let _ = parse(&flipped, 0);
            let _ = parse(&flipped, 1);
        }
    }
}
