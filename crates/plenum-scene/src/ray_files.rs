//! The ray and hit files of ../shared/bench (PLRAYS1, PLHITS1): the same rays traced by
//! Plenum and by another intersector, and their closest hits, compared ray by ray.

use std::io::{BufWriter, Write};
use std::path::Path;

const RAYS_MAGIC: &[u8; 8] = b"PLRAYS1\0";
const HITS_MAGIC: &[u8; 8] = b"PLHITS1\0";

/// One ray of a rays file: a hit counts if its distance t satisfies t_min ≤ t ≤ t_max.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FileRay {
    pub origin: [f32; 3],
    pub t_min: f32,
    pub direction: [f32; 3],
    pub t_max: f32,
}

/// The closest hit of one ray: `t = ∞` and `prim = u32::MAX` for a miss.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FileHit {
    pub t: f32,
    pub prim: u32,
}

impl FileHit {
    pub const MISS: FileHit = FileHit {
        t: f32::INFINITY,
        prim: u32::MAX,
    };
}

/// Reads a PLRAYS1 file; the message says what is wrong with a malformed one.
pub fn read_rays(path: &Path) -> Result<Vec<FileRay>, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    parse_rays(&bytes).map_err(|e| format!("{}: {e}", path.display()))
}

pub fn parse_rays(bytes: &[u8]) -> Result<Vec<FileRay>, String> {
    if bytes.len() < 16 || &bytes[..8] != RAYS_MAGIC {
        return Err("not a rays file: expected the magic bytes PLRAYS1".into());
    }
    let count = u64::from_le_bytes(bytes[8..16].try_into().expect("8 bytes"));
    let expected = count
        .checked_mul(32)
        .and_then(|n| n.checked_add(16))
        .ok_or("the ray count is too large")?;
    if bytes.len() as u64 != expected {
        return Err(format!(
            "{count} rays need {expected} bytes, but the file has {}",
            bytes.len()
        ));
    }
    Ok(bytes[16..]
        .chunks_exact(32)
        .map(|r| {
            let f = |i: usize| f32::from_le_bytes(r[4 * i..4 * i + 4].try_into().expect("4 bytes"));
            FileRay {
                origin: [f(0), f(1), f(2)],
                t_min: f(3),
                direction: [f(4), f(5), f(6)],
                t_max: f(7),
            }
        })
        .collect())
}

/// Writes a PLHITS1 file.
pub fn write_hits(path: &Path, hits: &[FileHit]) -> std::io::Result<()> {
    let mut out = BufWriter::new(std::fs::File::create(path)?);
    out.write_all(HITS_MAGIC)?;
    out.write_all(&(hits.len() as u64).to_le_bytes())?;
    for h in hits {
        out.write_all(&h.t.to_le_bytes())?;
        out.write_all(&h.prim.to_le_bytes())?;
    }
    out.flush()
}

/// Writes a PLRAYS1 file (for tests and tools).
pub fn write_rays(path: &Path, rays: &[FileRay]) -> std::io::Result<()> {
    let mut out = BufWriter::new(std::fs::File::create(path)?);
    out.write_all(RAYS_MAGIC)?;
    out.write_all(&(rays.len() as u64).to_le_bytes())?;
    for r in rays {
        for v in r
            .origin
            .iter()
            .chain([&r.t_min])
            .chain(&r.direction)
            .chain([&r.t_max])
        {
            out.write_all(&v.to_le_bytes())?;
        }
    }
    out.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rays_round_trip_and_bad_files() {
        let rays = vec![FileRay {
            origin: [1.0, 2.0, 3.0],
            t_min: 0.0,
            direction: [0.0, 0.0, 1.0],
            t_max: f32::INFINITY,
        }];
        let path = std::env::temp_dir().join(format!("plenum-rays-{}.bin", std::process::id()));
        write_rays(&path, &rays).unwrap();
        assert_eq!(read_rays(&path).unwrap(), rays);
        let mut bytes = std::fs::read(&path).unwrap();
        bytes.pop();
        assert!(parse_rays(&bytes).unwrap_err().contains("need 48 bytes"));
        assert!(parse_rays(b"PLHITS1\0\0\0\0\0\0\0\0\0")
            .unwrap_err()
            .contains("magic"));
        std::fs::remove_file(path).ok();
    }
}
