//! Film files (`.plf`): a render's raw film, exactly, with what it was rendered from. They
//! are the checkpoints that `--resume` continues and the parts that `plenum merge` sums.
//!
//! Layout, little-endian: the magic line `PLENUM-FILM 2\n`; the header's length (u64) and
//! the header, JSON (the scene file, a hash of the scene, the settings, the command line, the
//! film's size and sample range); the film, each list after its length as u64 (per pixel
//! Σw·L, Σw and ΣL as i128, Σ(w·L)² as f64, the sample count as u32, and Σ Y and Σ Y² as f64; a byte per
//! pixel of passes done; the open flags of sampling by variance; the splat sums as i64;
//! SPPM's statistics, after its iterations done (u32) and photons per iteration (u64): per
//! pixel r, N, τ and L_d as f64); and last an FNV-1a hash of all that precedes it, so that a
//! file cut short or damaged is refused, not read.
//!
//! A checkpoint is written to `NAME.tmp`, synced, and renamed over `NAME`: a crash at any
//! moment leaves either the previous checkpoint or the new one, whole.

use plenum_core::raw_film::{PhotonStatistics, PixelSums, Progressive, RawFilm};
use serde_json::{json, Value};
use std::io::Write;
use std::path::{Path, PathBuf};

const MAGIC: &[u8] = b"PLENUM-FILM 2\n";

/// What a film was rendered from: the same scene and settings must go on with it.
#[derive(Clone, Debug, PartialEq)]
pub struct Provenance {
    /// The scene file as given (None: the built-in scene).
    pub scene: Option<PathBuf>,
    /// FNV-1a of the scene as read (its native text, all meshes included) and its file.
    pub scene_hash: u64,
    /// The render settings, in full.
    pub settings: String,
    /// The arguments after `render` that started it, to resume it with, and the folder
    /// it was started in, which their relative paths are relative to.
    pub args: Vec<String>,
    pub cwd: PathBuf,
}

/// FNV-1a, 64 bits: a checksum and a fingerprint, not a defence against tampering.
#[derive(Clone, Copy)]
pub struct Fnv(u64);

impl Fnv {
    pub fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }

    pub fn update(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    pub fn value(self) -> u64 {
        self.0
    }
}

pub fn encode(film: &RawFilm, p: &Provenance) -> Vec<u8> {
    let header = json!({
        "scene": p.scene.as_ref().map(|s| s.to_string_lossy().into_owned()),
        "scene_hash": format!("{:016x}", p.scene_hash),
        "settings": p.settings,
        "spp": film.spp,
        "args": p.args,
        "cwd": p.cwd.to_string_lossy(),
        "width": film.width,
        "height": film.height,
        "corners": film.corners,
        "samples": [film.samples.start, film.samples.end],
    })
    .to_string();
    let n = film.pixels.len();
    let mut out = Vec::with_capacity(64 + header.len() + n * 156 + n * 2 + film.splats.len() * 24);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&(header.len() as u64).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out.extend_from_slice(&(film.pixels.len() as u64).to_le_bytes());
    for px in &film.pixels {
        for v in px.weighted.iter().chain([&px.weight]).chain(&px.plain) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in &px.weighted_squared {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&px.count.to_le_bytes());
        out.extend_from_slice(&px.luminance.to_le_bytes());
        out.extend_from_slice(&px.luminance_squared.to_le_bytes());
    }
    out.extend_from_slice(&(film.stages.len() as u64).to_le_bytes());
    out.extend_from_slice(&film.stages);
    out.extend_from_slice(&(film.open.len() as u64).to_le_bytes());
    out.extend(film.open.iter().map(|&o| o as u8));
    out.extend_from_slice(&(film.splats.len() as u64).to_le_bytes());
    for s in &film.splats {
        for v in s {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    match &film.progressive {
        None => out.extend_from_slice(&0u64.to_le_bytes()),
        Some(p) => {
            out.extend_from_slice(&(p.pixels.len() as u64).to_le_bytes());
            out.extend_from_slice(&p.iterations.to_le_bytes());
            out.extend_from_slice(&p.photons_per_iteration.to_le_bytes());
            for px in &p.pixels {
                let values = [px.radius, px.photons]
                    .into_iter()
                    .chain(px.flux)
                    .chain(px.direct);
                for v in values {
                    out.extend_from_slice(&v.to_le_bytes());
                }
            }
        }
    }
    let mut hash = Fnv::new();
    hash.update(&out);
    out.extend_from_slice(&hash.value().to_le_bytes());
    out
}

/// Reads bytes in order, failing with what was being read.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], String> {
        let end = self
            .at
            .checked_add(n)
            .filter(|&e| e <= self.bytes.len())
            .ok_or_else(|| format!("it ends inside {what}"))?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }

    fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N], String> {
        Ok(self.take(N, what)?.try_into().expect("N bytes"))
    }

    fn u64(&mut self, what: &str) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.array(what)?))
    }

    /// The length of a list of `what`, which must be `n` or, where allowed, 0.
    fn length(&mut self, what: &str, n: usize, may_be_empty: bool) -> Result<usize, String> {
        match self.u64(what)? {
            0 if may_be_empty => Ok(0),
            l if l == n as u64 => Ok(n),
            _ => Err(format!("its {what} do not match its size")),
        }
    }
}

pub fn decode(bytes: &[u8]) -> Result<(RawFilm, Provenance), String> {
    if !bytes.starts_with(MAGIC) {
        if bytes.starts_with(b"PLENUM-FILM ") {
            return Err("it was written by another version of Plenum: render it again".to_string());
        }
        return Err("not a Plenum film file (it does not begin with `PLENUM-FILM 2`)".to_string());
    }
    let body = bytes.len().checked_sub(8).ok_or("it is cut short")?;
    let mut hash = Fnv::new();
    hash.update(&bytes[..body]);
    let stored = u64::from_le_bytes(bytes[body..].try_into().expect("8 bytes"));
    if hash.value() != stored {
        return Err("it is damaged or cut short: its checksum does not match".to_string());
    }
    let mut r = Reader {
        bytes: &bytes[..body],
        at: MAGIC.len(),
    };
    let len = r.u64("the header length")?;
    let header = r.take(
        usize::try_from(len).map_err(|_| "header too long")?,
        "the header",
    )?;
    let h: Value = serde_json::from_slice(header).map_err(|e| format!("its header: {e}"))?;
    let field = |k: &str| h.get(k).ok_or_else(|| format!("its header lacks `{k}`"));
    let number = |k: &str| -> Result<u64, String> {
        field(k)?
            .as_u64()
            .ok_or_else(|| format!("its header's `{k}` is not a count"))
    };
    let (width, height) = (number("width")? as u32, number("height")? as u32);
    let samples = field("samples")?
        .as_array()
        .filter(|a| a.len() == 2)
        .and_then(|a| Some(a[0].as_u64()? as u32..a[1].as_u64()? as u32))
        .ok_or("its header's `samples` is not a range")?;
    let corners = field("corners")?.as_bool().ok_or("bad `corners`")?;
    let provenance = Provenance {
        scene: field("scene")?.as_str().map(PathBuf::from),
        scene_hash: field("scene_hash")?
            .as_str()
            .and_then(|s| u64::from_str_radix(s, 16).ok())
            .ok_or("bad `scene_hash`")?,
        settings: field("settings")?
            .as_str()
            .ok_or("bad `settings`")?
            .to_string(),
        args: field("args")?
            .as_array()
            .and_then(|a| a.iter().map(|v| v.as_str().map(str::to_string)).collect())
            .ok_or("bad `args`")?,
        cwd: PathBuf::from(field("cwd")?.as_str().ok_or("bad `cwd`")?),
    };
    let n = (width as usize)
        .checked_mul(height as usize)
        .filter(|&n| n <= bytes.len())
        .ok_or("its size does not match its length")?;
    let mut film = RawFilm::empty(width, height, corners, samples);
    film.spp = number("spp")? as u32;
    // SPPM's films hold no per-sample sums: its lists are empty.
    let sums = r.length("pixels", n, true)?;
    film.pixels = vec![PixelSums::default(); sums];
    for px in film.pixels.iter_mut() {
        let b = r.take(7 * 16 + 3 * 8 + 4 + 16, "the pixels")?;
        let i128_at =
            |i: usize| i128::from_le_bytes(b[i * 16..i * 16 + 16].try_into().expect("16"));
        let f64_at = |at: usize| f64::from_le_bytes(b[at..at + 8].try_into().expect("8"));
        *px = PixelSums {
            weighted: [i128_at(0), i128_at(1), i128_at(2)],
            weight: i128_at(3),
            plain: [i128_at(4), i128_at(5), i128_at(6)],
            weighted_squared: [f64_at(112), f64_at(120), f64_at(128)],
            count: u32::from_le_bytes(b[136..140].try_into().expect("4")),
            luminance: f64_at(140),
            luminance_squared: f64_at(148),
        };
    }
    let stages = r.length("passes", sums, false)?;
    film.stages = r.take(stages, "the passes")?.to_vec();
    let open = r.length("open flags", n, true)?;
    film.open = r
        .take(open, "the open flags")?
        .iter()
        .map(|&b| b != 0)
        .collect();
    let splats = r.length("splats", n, true)?;
    film.splats = Vec::with_capacity(splats);
    for _ in 0..splats {
        let b = r.take(24, "the splats")?;
        let at = |i: usize| i64::from_le_bytes(b[i * 8..i * 8 + 8].try_into().expect("8"));
        film.splats.push([at(0), at(1), at(2)]);
    }
    let progressive = r.length("SPPM statistics", n, true)?;
    if (progressive == 0) != (sums == n) {
        return Err("it holds neither per-sample sums nor SPPM's statistics in full".to_string());
    }
    if progressive > 0 {
        let iterations = u32::from_le_bytes(r.array("the SPPM iterations")?);
        let photons_per_iteration = r.u64("the SPPM photon count")?;
        let mut pixels = Vec::with_capacity(progressive);
        for _ in 0..progressive {
            let b = r.take(8 * 8, "the SPPM statistics")?;
            let at = |i: usize| f64::from_le_bytes(b[i * 8..i * 8 + 8].try_into().expect("8"));
            pixels.push(PhotonStatistics {
                radius: at(0),
                photons: at(1),
                flux: [at(2), at(3), at(4)],
                direct: [at(5), at(6), at(7)],
            });
        }
        film.progressive = Some(Progressive {
            iterations,
            photons_per_iteration,
            pixels,
        });
    }
    if r.at != body {
        return Err("it has bytes after its film".to_string());
    }
    Ok((film, provenance))
}

/// Reads a film file, saying which one is at fault.
pub fn read(path: &Path) -> Result<(RawFilm, Provenance), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    decode(&bytes).map_err(|e| format!("{} cannot be used: {e}", path.display()))
}

/// Writes a film file atomically: to `NAME.tmp`, synced, then renamed over `NAME` (and the
/// folder synced, so that the rename itself survives a crash).
pub fn write(path: &Path, film: &RawFilm, p: &Provenance) -> std::io::Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(&encode(film, p))?;
        f.sync_all()?;
    }
    std::fs::rename(&tmp, path)?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if let Ok(d) = std::fs::File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use plenum_core::Color;

    fn sample() -> (RawFilm, Provenance) {
        let mut film = RawFilm::new(3, 2, false, 4..12);
        film.spp = 16;
        for (i, px) in film.pixels.iter_mut().enumerate() {
            px.add(Color::new(i as f64, 0.5, -1e-3), 0.75);
            px.add(Color::new(1e6, 2.0, 3.0), -0.1);
        }
        film.stages = vec![1, 1, 0, 1, 0, 0];
        film.open = vec![true, false, true, true, false, false];
        film.splats = (0..6).map(|i| [i, -i, i << 40]).collect();
        let p = Provenance {
            scene: Some(PathBuf::from("scenes/x.toml")),
            scene_hash: 0x0123_4567_89ab_cdef,
            settings: "RenderSettings { width: 3 }".to_string(),
            args: vec![
                "scenes/x.toml".to_string(),
                "--spp".to_string(),
                "16".to_string(),
            ],
            cwd: PathBuf::from("/home/someone"),
        };
        (film, p)
    }

    /// An SPPM film after 3 of 5 iterations.
    fn sppm_sample() -> (RawFilm, Provenance) {
        let mut film = RawFilm::progressive(3, 2, 5, 1234);
        let state = film.progressive.as_mut().unwrap();
        state.iterations = 3;
        for (i, px) in state.pixels.iter_mut().enumerate() {
            let t = i as f64;
            *px = PhotonStatistics {
                radius: 0.1 / (t + 1.0),
                photons: t * 2.0 / 3.0,
                flux: [t, 1e-300, -0.0],
                direct: [f64::MIN_POSITIVE, 3.5, t * t],
            };
        }
        (film, sample().1)
    }

    #[test]
    fn round_trip_is_exact() {
        for (film, p) in [sample(), sppm_sample()] {
            let (back, q) = decode(&encode(&film, &p)).unwrap();
            assert_eq!(back, film);
            assert_eq!(q, p);
        }
        // Bit for bit, -0.0 included.
        let (film, p) = sppm_sample();
        let (back, _) = decode(&encode(&film, &p)).unwrap();
        let bits = |f: &RawFilm| -> Vec<u64> {
            let s = f.progressive.as_ref().unwrap();
            s.pixels
                .iter()
                .flat_map(|p| p.flux.map(f64::to_bits))
                .collect()
        };
        assert_eq!(bits(&back), bits(&film));
    }

    /// Any byte changed or any length cut off is refused, never read as another film.
    #[test]
    fn damage_is_refused() {
        for (film, p) in [sample(), sppm_sample()] {
            let bytes = encode(&film, &p);
            for i in (0..bytes.len()).step_by(7) {
                let mut b = bytes.clone();
                b[i] ^= 0x10;
                assert!(decode(&b).is_err(), "byte {i} changed");
            }
            for len in (0..bytes.len()).step_by(5) {
                assert!(decode(&bytes[..len]).is_err(), "cut at {len}");
            }
        }
    }

    #[test]
    fn films_of_another_version_are_refused_by_name() {
        let (film, p) = sample();
        let mut bytes = encode(&film, &p);
        bytes[12] = b'1';
        let e = decode(&bytes).unwrap_err();
        assert!(e.contains("another version of Plenum"), "{e}");
    }
}
