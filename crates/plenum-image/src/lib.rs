//! Image files for Plenum. Renders leave as PNG (8-bit sRGB after exposure and clamping),
//! OpenEXR (linear 32-bit float RGB), PFM (linear float, the Portable Float Map) or Radiance
//! HDR; textures arrive from PNG or JPEG, decoded from sRGB to linear; float images (for
//! environment maps) arrive from EXR, HDR, PFM, PNG or JPEG through [`read_float_image`].
//!
//! PFM has no formal standard; this crate follows the description of its author's HDRShop
//! (Debevec): a header "PF" (RGB) or "Pf" (grey), the width and height, and a scale whose sign
//! gives the byte order (negative: little-endian) and whose magnitude multiplies the values,
//! each followed by one white-space character; then 32-bit floats, rows from the bottom up.
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
    #[error("{path}: byte offset {offset}: {message}")]
    Malformed {
        path: String,
        offset: usize,
        message: String,
    },
    #[error(
        "unsupported image extension `{0}` to read: use .exr, .hdr, .pfm, .png, .jpg or .jpeg"
    )]
    UnsupportedReadExtension(String),
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

/// Views beside an EXR's image, each written as OpenEXR's layers within one part are: its
/// channels named `NAME.CHANNEL` (`rays.Y`, `normal.R`, …), which viewers and compositors
/// (Blender, Nuke, the OpenEXR tools) group under NAME.
pub struct ExrLayer {
    pub name: String,
    /// Each channel's name and values, row-major from the top-left.
    pub channels: Vec<(&'static str, Vec<f32>)>,
}

/// Writes `pixels` (linear RGB) and `layers` to an OpenEXR file at `path`: 32-bit float
/// channels R, G and B and NAME.CHANNEL for each layer's, compressed losslessly.
pub fn write_exr_layers(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[[f32; 3]],
    layers: &[ExrLayer],
) -> Result<(), ImageError> {
    use exr::prelude::*;
    let wrap = |e: Box<dyn std::error::Error + Send + Sync>| ImageError::Write {
        path: path.display().to_string(),
        source: e,
    };
    let size = (width as usize, height as usize);
    let area = size.0 * size.1;
    if pixels.len() != area
        || layers
            .iter()
            .flat_map(|l| &l.channels)
            .any(|c| c.1.len() != area)
    {
        return Err(wrap("pixel count does not match the size".into()));
    }
    let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (k, name) in ["R", "G", "B"].into_iter().enumerate() {
        let values = pixels.iter().map(|p| p[k]).collect();
        channels.push(AnyChannel::new(name, FlatSamples::F32(values)));
    }
    for layer in layers {
        for (channel, values) in &layer.channels {
            let name = format!("{}.{channel}", layer.name);
            channels.push(AnyChannel::new(
                name.as_str(),
                FlatSamples::F32(values.clone()),
            ));
        }
    }
    let layer = Layer::new(
        size,
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels),
    );
    Image::from_layer(layer)
        .write()
        .to_file(path)
        .map_err(|e| wrap(e.into()))
}

/// An image's channels: each one's name and values, row-major from the top-left.
pub type Channels = Vec<(String, Vec<f32>)>;

/// The channels of an OpenEXR file's first part by name, with the image's width and height.
pub fn read_exr_channels(path: &Path) -> Result<(u32, u32, Channels), ImageError> {
    let image =
        exr::prelude::read_first_flat_layer_from_file(path).map_err(|e| ImageError::Read {
            path: path.display().to_string(),
            source: e.into(),
        })?;
    let size = image.layer_data.size;
    let channels = image
        .layer_data
        .channel_data
        .list
        .iter()
        .map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect()))
        .collect();
    Ok((size.0 as u32, size.1 as u32, channels))
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
    /// The alpha channel, where the image has one: linear coverage in [0, 1], never
    /// sRGB-decoded.
    pub alpha: Option<Vec<f32>>,
}

/// Reads a texture: PNG or JPEG, whose 8- or 16-bit values are sRGB-encoded and decoded to
/// linear here; EXR and HDR, whose float values are linear already.
pub fn read_texture(path: &Path) -> Result<Texels, ImageError> {
    let img = image::open(path).map_err(|e| ImageError::Read {
        path: path.display().to_string(),
        source: e.into(),
    })?;
    Ok(texels(img))
}

/// [`read_texture`] of an image that holds data rather than colour (a normal map, pbrt's
/// `"linear"` encoding): 8- and 16-bit values are scaled to [0, 1] as they are.
pub fn read_data_texture(path: &Path) -> Result<Texels, ImageError> {
    let img = image::open(path).map_err(|e| ImageError::Read {
        path: path.display().to_string(),
        source: e.into(),
    })?;
    Ok(texels_as(img, false))
}

/// [`read_texture`] of an image file's bytes already read (an image inside a glTF buffer or
/// data URI); `name` says where they came from in messages.
pub fn decode_texture(bytes: &[u8], name: &str) -> Result<Texels, ImageError> {
    let img = image::load_from_memory(bytes).map_err(|e| ImageError::Read {
        path: name.to_string(),
        source: e.into(),
    })?;
    Ok(texels(img))
}

/// [`decode_texture`] of an image that holds data rather than colour (glTF's metallic and
/// roughness): 8- and 16-bit values are scaled to [0, 1] as they are, not sRGB-decoded.
pub fn decode_data_texture(bytes: &[u8], name: &str) -> Result<Texels, ImageError> {
    let img = image::load_from_memory(bytes).map_err(|e| ImageError::Read {
        path: name.to_string(),
        source: e.into(),
    })?;
    Ok(texels_as(img, false))
}

fn texels(img: image::DynamicImage) -> Texels {
    texels_as(img, true)
}

/// The image's texels, its 8- and 16-bit values sRGB-decoded if `colour`.
fn texels_as(img: image::DynamicImage, colour: bool) -> Texels {
    let (w, h) = (img.width() as usize, img.height() as usize);
    let alpha = img
        .color()
        .has_alpha()
        .then(|| img.to_rgba32f().pixels().map(|p| p.0[3]).collect());
    let rgb = match img {
        image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_) => {
            img.to_rgb32f().pixels().map(|p| p.0).collect()
        }
        _ if !colour => img.to_rgb32f().pixels().map(|p| p.0).collect(),
        _ => img
            .to_rgb32f()
            .pixels()
            .map(|p| p.0.map(srgb_decode))
            .collect(),
    };
    Texels {
        width: w,
        height: h,
        rgb,
        alpha,
    }
}

/// A float image of linear RGB, row-major from the top-left.
#[derive(Clone, Debug, PartialEq)]
pub struct FloatImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
}

/// Reads a linear RGB float image, chosen by extension: `.exr` and `.hdr` (Radiance RGBE)
/// through the `image` crate, `.pfm` by [`parse_pfm`], `.png`, `.jpg` and `.jpeg` as 8- or
/// 16-bit sRGB decoded to linear. Alpha is dropped; grey images become grey RGB.
pub fn read_float_image(path: &Path) -> Result<FloatImage, ImageError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let read_error = |e: Box<dyn std::error::Error + Send + Sync>| ImageError::Read {
        path: path.display().to_string(),
        source: e,
    };
    let (linear, format) = match ext.as_str() {
        "pfm" => {
            let bytes = std::fs::read(path).map_err(|e| read_error(e.into()))?;
            return parse_pfm(&bytes).map_err(|e| ImageError::Malformed {
                path: path.display().to_string(),
                offset: e.offset,
                message: e.message,
            });
        }
        "exr" => (true, ImageFormat::OpenExr),
        "hdr" => (true, ImageFormat::Hdr),
        "png" => (false, ImageFormat::Png),
        "jpg" | "jpeg" => (false, ImageFormat::Jpeg),
        _ => return Err(ImageError::UnsupportedReadExtension(ext)),
    };
    let file = std::fs::File::open(path).map_err(|e| read_error(e.into()))?;
    let img = image::ImageReader::with_format(std::io::BufReader::new(file), format)
        .decode()
        .map_err(|e| read_error(e.into()))?;
    let (width, height) = (img.width(), img.height());
    let pixels = img
        .to_rgb32f()
        .pixels()
        .map(|p| if linear { p.0 } else { p.0.map(srgb_decode) })
        .collect();
    Ok(FloatImage {
        width,
        height,
        pixels,
    })
}

/// What is wrong with a PFM file, and at which byte.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PfmError {
    pub offset: usize,
    pub message: String,
}

/// Decodes a PFM file held in memory (see the crate docs for the format). Never panics, and
/// allocates the pixels only once the file is known to hold them all; bytes after the last
/// row are ignored.
pub fn parse_pfm(bytes: &[u8]) -> Result<FloatImage, PfmError> {
    let fail = |offset: usize, message: String| Err(PfmError { offset, message });
    let channels = match bytes.get(..2) {
        Some(b"PF") => 3,
        Some(b"Pf") => 1,
        _ => return fail(0, "not a PFM file: it must begin with `PF` or `Pf`".into()),
    };
    let mut at = 2;
    // Each header field is preceded by white space and read up to the next white space.
    let mut field = |what: &str| -> Result<(usize, String), PfmError> {
        let start = at;
        while bytes.get(at).is_some_and(u8::is_ascii_whitespace) {
            at += 1;
        }
        if at == start {
            return Err(PfmError {
                offset: at,
                message: format!("expected white space before the {what}"),
            });
        }
        let begin = at;
        while bytes.get(at).is_some_and(|b| !b.is_ascii_whitespace()) && at - begin < 64 {
            at += 1;
        }
        if at == begin {
            return Err(PfmError {
                offset: at,
                message: format!("the header ends before the {what}"),
            });
        }
        Ok((
            begin,
            String::from_utf8_lossy(&bytes[begin..at]).into_owned(),
        ))
    };
    let mut dimension = |what: &str| -> Result<u32, PfmError> {
        let (offset, text) = field(what)?;
        match text.parse::<u32>() {
            Ok(n) if n > 0 => Ok(n),
            _ => Err(PfmError {
                offset,
                message: format!("the {what} `{text}` is not a whole number of at least 1"),
            }),
        }
    };
    let width = dimension("width")?;
    let height = dimension("height")?;
    let (offset, text) = field("scale")?;
    let scale = match text.parse::<f32>() {
        Ok(s) if s.is_finite() && s != 0.0 => s,
        _ => {
            return fail(
                offset,
                format!("the scale `{text}` is not a finite, non-zero number"),
            )
        }
    };
    // Exactly one white-space byte ends the header; the pixels may begin with any byte.
    match bytes.get(at) {
        Some(b) if b.is_ascii_whitespace() => at += 1,
        _ => return fail(at, "expected one white-space byte after the scale".into()),
    }
    let available = bytes.len() - at;
    // At most 2^64 · 12 bytes: u128 cannot overflow.
    let needed = width as u128 * height as u128 * channels as u128 * 4;
    if needed > available as u128 {
        return fail(
            bytes.len(),
            format!(
                "the pixels end early: {width} × {height} × {channels} floats need {needed} \
                 bytes from offset {at}, the file holds {available}"
            ),
        );
    }
    let little_endian = scale < 0.0;
    let magnitude = scale.abs();
    let data = &bytes[at..at + needed as usize];
    let value = |k: usize| {
        let b = [
            data[4 * k],
            data[4 * k + 1],
            data[4 * k + 2],
            data[4 * k + 3],
        ];
        let v = if little_endian {
            f32::from_le_bytes(b)
        } else {
            f32::from_be_bytes(b)
        };
        if magnitude == 1.0 {
            v
        } else {
            v * magnitude
        }
    };
    let (w, h) = (width as usize, height as usize);
    let mut pixels = Vec::with_capacity(w * h);
    for y in 0..h {
        // The file's first row is the image's bottom one.
        let row = h - 1 - y;
        for x in 0..w {
            let k = (row * w + x) * channels;
            pixels.push(if channels == 3 {
                [value(k), value(k + 1), value(k + 2)]
            } else {
                [value(k); 3]
            });
        }
    }
    Ok(FloatImage {
        width,
        height,
        pixels,
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

    fn temp_dir(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("plenum-image-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// A 3 × 2 image with a distinct value in every channel of every pixel.
    fn test_pixels() -> Vec<[f32; 3]> {
        (0..6)
            .map(|i| {
                let i = i as f32;
                [0.1 + 0.1 * i, 0.05 * i, 0.9 - 0.1 * i]
            })
            .collect()
    }

    #[test]
    fn float_formats_round_trip() {
        let dir = temp_dir("round-trip");
        let mut pixels = test_pixels();
        // Values above 1 survive the float formats.
        pixels[4] = [12.5, 0.25, 3.0];
        for (ext, tolerance) in [("exr", 0.0), ("pfm", 0.0), ("hdr", 1.0 / 64.0)] {
            let path = dir.join(format!("t.{ext}"));
            write_image(&path, 3, 2, &pixels, 0.0).unwrap();
            let back = read_float_image(&path).unwrap();
            assert_eq!((back.width, back.height), (3, 2), "{ext}");
            for (a, b) in pixels.iter().zip(&back.pixels) {
                for c in 0..3 {
                    // RGBE shares one exponent per pixel: error relative to the largest channel.
                    let largest = a.iter().fold(0.0f32, |m, &v| m.max(v));
                    assert!(
                        (a[c] - b[c]).abs() <= tolerance * largest,
                        "{ext}: {a:?} vs {b:?}"
                    );
                }
            }
        }
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn eight_bit_formats_decode_to_linear() {
        let dir = temp_dir("srgb");
        let pixels = test_pixels();
        let path = dir.join("t.png");
        write_image(&path, 3, 2, &pixels, 0.0).unwrap();
        let back = read_float_image(&path).unwrap();
        assert_eq!((back.width, back.height), (3, 2));
        for (a, b) in pixels.iter().zip(&back.pixels) {
            for c in 0..3 {
                // One 8-bit step of the encoded value, in linear terms, is below 0.01 here.
                assert!((a[c] - b[c]).abs() < 0.005, "png: {a:?} vs {b:?}");
            }
        }
        // A flat JPEG of encoded grey 128 decodes to linear 0.216.
        let jpeg = dir.join("t.jpg");
        image::RgbImage::from_pixel(8, 8, image::Rgb([128, 128, 128]))
            .save_with_format(&jpeg, ImageFormat::Jpeg)
            .unwrap();
        let back = read_float_image(&jpeg).unwrap();
        assert_eq!((back.width, back.height), (8, 8));
        for p in &back.pixels {
            assert!(
                p.iter()
                    .all(|&v| (v - srgb_decode(128.0 / 255.0)).abs() < 0.01),
                "{p:?}"
            );
        }
        assert!(matches!(
            read_float_image(&dir.join("t.bmp")),
            Err(ImageError::UnsupportedReadExtension(_))
        ));
        assert!(matches!(
            read_float_image(&dir.join("missing.exr")),
            Err(ImageError::Read { .. })
        ));
        std::fs::remove_dir_all(&dir).ok();
    }

    /// A PFM file from its header and float values, in the given byte order.
    fn pfm(header: &str, values: &[f32], little_endian: bool) -> Vec<u8> {
        let mut bytes = header.as_bytes().to_vec();
        for v in values {
            bytes.extend(if little_endian {
                v.to_le_bytes()
            } else {
                v.to_be_bytes()
            });
        }
        bytes
    }

    #[test]
    fn pfm_byte_order_scale_grey_and_row_order() {
        // Big-endian (positive scale), two rows: the file's first row is the bottom one.
        let values = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let image = parse_pfm(&pfm("PF\n1 2\n1.0\n", &values, false)).unwrap();
        assert_eq!(image.pixels, vec![[4.0, 5.0, 6.0], [1.0, 2.0, 3.0]]);
        // Grey, little-endian, scale magnitude 2 multiplies; any white space between fields.
        let image = parse_pfm(&pfm("Pf  2\t1 -2.0 ", &[0.5, 1.5], true)).unwrap();
        assert_eq!((image.width, image.height), (2, 1));
        assert_eq!(image.pixels, vec![[1.0; 3], [3.0; 3]]);
        // Trailing bytes after the last row are ignored.
        let mut bytes = pfm("PF\n1 1\n-1\n", &[7.0, 8.0, 9.0], true);
        bytes.extend(b"junk");
        assert_eq!(parse_pfm(&bytes).unwrap().pixels, vec![[7.0, 8.0, 9.0]]);
    }

    #[test]
    fn pfm_truncated_and_malformed_files_are_errors() {
        let whole = pfm("PF\n2 2\n-1.0\n", &[0.5; 12], true);
        let header_length = "PF\n2 2\n-1.0\n".len();
        for end in 0..whole.len() {
            let error = parse_pfm(&whole[..end]).expect_err("a truncated file is an error");
            if end >= header_length {
                assert_eq!(error.offset, end, "{error:?}");
                assert!(error.message.contains("end early"), "{error:?}");
            }
        }
        let cases: [(&[u8], usize); 12] = [
            (b"P6\n1 1\n255\n", 0),
            (b"", 0),
            (b"PF", 2),
            (b"PF1 1 -1\n", 2),
            (b"PF\nx 1\n-1\n", 3),
            (b"PF\n0 1\n-1\n", 3),
            (b"PF\n1 -1\n-1\n", 5),
            (b"PF\n99999999999 1\n-1\n", 3),
            (b"PF\n1 1\n0\n", 7),
            (b"PF\n1 1\nnan\n", 7),
            (b"PF\n1 1\n-1", 9),
            (b"PF\n4294967295 4294967295\n-1\n", 28),
        ];
        for (bytes, offset) in cases {
            let error = parse_pfm(bytes).expect_err("malformed");
            assert_eq!(
                error.offset,
                offset,
                "{:?}: {error:?}",
                String::from_utf8_lossy(bytes)
            );
        }
        // Through the file reader the offset is part of the message.
        let dir = temp_dir("pfm");
        let path = dir.join("short.pfm");
        std::fs::write(&path, &whole[..20]).unwrap();
        let message = read_float_image(&path).unwrap_err().to_string();
        assert!(message.contains("byte offset 20"), "{message}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn pfm_parser_never_panics_on_corrupted_bytes() {
        // Every single-byte corruption of a small file, to each of a few telling values.
        let whole = pfm("PF\n2 1\n-1.0\n", &[0.25; 6], true);
        for k in 0..whole.len() {
            for replacement in [b' ', b'\n', b'0', b'9', b'-', b'P', b'f', 0, 0xFF] {
                let mut bytes = whole.clone();
                bytes[k] = replacement;
                let _ = parse_pfm(&bytes);
            }
        }
    }

    /// An EXR with layers: the image as R, G, B, which every reader (the `image` crate's
    /// included) takes as the image, and each layer's channels as NAME.CHANNEL, read back
    /// exactly.
    #[test]
    fn an_exr_carries_its_views_as_layers() {
        let path = temp_dir("layers").join("t.exr");
        let pixels = [[1.0, 2.0, 3.0], [0.5, 0.25, 0.125]];
        let layers = [
            ExrLayer {
                name: "rays".into(),
                channels: vec![("Y", vec![7.0, 9.0])],
            },
            ExrLayer {
                name: "normal".into(),
                channels: vec![
                    ("R", vec![0.0, 1.0]),
                    ("G", vec![1.0, 0.0]),
                    ("B", vec![0.0, -1.0]),
                ],
            },
        ];
        write_exr_layers(&path, 2, 1, &pixels, &layers).unwrap();
        let image = read_float_image(&path).unwrap();
        assert_eq!(image.pixels, pixels.to_vec());
        let (w, h, channels) = read_exr_channels(&path).unwrap();
        assert_eq!((w, h), (2, 1));
        let get = |n: &str| channels.iter().find(|c| c.0 == n).map(|c| c.1.clone());
        assert_eq!(get("rays.Y"), Some(vec![7.0, 9.0]));
        assert_eq!(get("normal.B"), Some(vec![0.0, -1.0]));
        assert_eq!(get("G"), Some(vec![2.0, 0.25]));
        assert_eq!(channels.len(), 7);
        assert!(write_exr_layers(&path, 3, 1, &pixels, &layers).is_err());
    }
}
