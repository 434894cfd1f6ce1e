//! Image files for Plenum. Renders leave as PNG (8-bit sRGB after exposure and clamping),
//! OpenEXR (linear 32-bit float RGB), PFM (linear float, the Portable Float Map) or Radiance
//! HDR; textures arrive from PNG or JPEG, decoded from sRGB to linear.
//!
//! Pixels are linear RGB triples, row-major from the top-left, in the layout of
//! `plenum_core::film::Film::pixels`; this crate does not depend on the renderer.

use image::{ImageFormat, Rgb32FImage, RgbImage};
use std::io::Write;
use std::path::Path;

#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    #[error("unsupported image extension `{0}`: use .png, .exr, .pfm or .hdr")]
    UnsupportedExtension(String),
    #[error("cannot write {path}: {source}")]
    Write {
        path: String,
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    #[error("cannot read image {path}: {source}")]
    Read {
        path: String,
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}

/// The output formats, chosen by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputFormat {
    Png,
    Exr,
    Pfm,
    Hdr,
}

impl OutputFormat {
    pub fn from_path(path: &Path) -> Result<OutputFormat, ImageError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        match ext.as_str() {
            "png" => Ok(OutputFormat::Png),
            "exr" => Ok(OutputFormat::Exr),
            "pfm" => Ok(OutputFormat::Pfm),
            "hdr" => Ok(OutputFormat::Hdr),
            _ => Err(ImageError::UnsupportedExtension(ext)),
        }
    }
}

/// The sRGB transfer function (IEC 61966-2-1), linear to encoded, for values in [0, 1].
pub fn srgb_encode(linear: f32) -> f32 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// The inverse of [`srgb_encode`].
pub fn srgb_decode(encoded: f32) -> f32 {
    if encoded <= 0.040_45 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

/// 8-bit sRGB bytes of a linear image: scaled by 2^exposure, clamped to [0, 1], encoded.
pub fn to_srgb8(pixels: &[[f32; 3]], exposure: f32) -> Vec<u8> {
    let scale = exposure.exp2();
    pixels
        .iter()
        .flat_map(|p| p.map(|c| (srgb_encode((c * scale).clamp(0.0, 1.0)) * 255.0).round() as u8))
        .collect()
}

/// Writes a linear RGB image in the format the path's extension names. `exposure` (in stops)
/// applies to PNG only; the float formats keep the linear values.
pub fn write_image(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[[f32; 3]],
    exposure: f32,
) -> Result<(), ImageError> {
    let wrap = |e: Box<dyn std::error::Error + Send + Sync>| ImageError::Write {
        path: path.display().to_string(),
        source: e,
    };
    match OutputFormat::from_path(path)? {
        OutputFormat::Png => {
            let img = RgbImage::from_raw(width, height, to_srgb8(pixels, exposure))
                .ok_or_else(|| wrap("pixel count does not match the size".into()))?;
            img.save_with_format(path, ImageFormat::Png)
                .map_err(|e| wrap(e.into()))
        }
        OutputFormat::Exr | OutputFormat::Hdr => {
            let floats: Vec<f32> = pixels.iter().flatten().copied().collect();
            let img = Rgb32FImage::from_raw(width, height, floats)
                .ok_or_else(|| wrap("pixel count does not match the size".into()))?;
            let format = if OutputFormat::from_path(path)? == OutputFormat::Exr {
                ImageFormat::OpenExr
            } else {
                ImageFormat::Hdr
            };
            img.save_with_format(path, format)
                .map_err(|e| wrap(e.into()))
        }
        OutputFormat::Pfm => write_pfm(path, width, height, pixels).map_err(|e| wrap(e.into())),
    }
}

/// PFM: a text header "PF\nW H\n-1.0\n" (negative scale: little-endian), then float RGB rows
/// from the bottom of the image up.
fn write_pfm(path: &Path, width: u32, height: u32, pixels: &[[f32; 3]]) -> std::io::Result<()> {
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    write!(out, "PF\n{width} {height}\n-1.0\n")?;
    for row in pixels.chunks(width as usize).rev() {
        for p in row {
            for c in p {
                out.write_all(&c.to_le_bytes())?;
            }
        }
    }
    out.flush()
}

/// A decoded texture: linear RGB, row-major from the top.
pub struct Texels {
    pub width: usize,
    pub height: usize,
    pub rgb: Vec<[f32; 3]>,
}

/// Reads a texture: PNG or JPEG, whose 8- or 16-bit values are sRGB-encoded and decoded to
/// linear here; EXR and HDR, whose float values are linear already.
pub fn read_texture(path: &Path) -> Result<Texels, ImageError> {
    let img = image::open(path).map_err(|e| ImageError::Read {
        path: path.display().to_string(),
        source: e.into(),
    })?;
    let (w, h) = (img.width() as usize, img.height() as usize);
    let rgb = match img {
        image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_) => {
            img.to_rgb32f().pixels().map(|p| p.0).collect()
        }
        _ => img
            .to_rgb32f()
            .pixels()
            .map(|p| p.0.map(srgb_decode))
            .collect(),
    };
    Ok(Texels {
        width: w,
        height: h,
        rgb,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trip_and_known_values() {
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
        // Linear 0.214 is about mid-grey 0.5 encoded.
        assert!((srgb_encode(0.214_041_14) - 0.5).abs() < 1e-4);
        for v in [0.001f32, 0.02, 0.3, 0.9] {
            assert!((srgb_decode(srgb_encode(v)) - v).abs() < 1e-5);
        }
    }

    #[test]
    fn every_format_writes_and_png_reads_back() {
        let dir = std::env::temp_dir().join(format!("plenum-image-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let pixels = vec![[0.0, 0.5, 1.0], [2.0, 0.25, 0.0]];
        for ext in ["png", "exr", "pfm", "hdr"] {
            let path = dir.join(format!("t.{ext}"));
            write_image(&path, 2, 1, &pixels, 0.0).unwrap();
            assert!(std::fs::metadata(&path).unwrap().len() > 0);
        }
        let back = read_texture(&dir.join("t.png")).unwrap();
        assert_eq!((back.width, back.height), (2, 1));
        // Clamped to 1 in the PNG.
        assert!((back.rgb[1][0] - 1.0).abs() < 1e-6);
        assert!((back.rgb[0][1] - 0.5).abs() < 0.01);
        let exr = image::open(dir.join("t.exr")).unwrap().to_rgb32f();
        assert_eq!(exr.get_pixel(1, 0).0, [2.0, 0.25, 0.0]);
        let pfm = std::fs::read(dir.join("t.pfm")).unwrap();
        assert!(pfm.starts_with(b"PF\n2 1\n-1.0\n"));
        assert!(matches!(
            write_image(&dir.join("t.bmp"), 2, 1, &pixels, 0.0),
            Err(ImageError::UnsupportedExtension(_))
        ));
        std::fs::remove_dir_all(&dir).ok();
    }
}
