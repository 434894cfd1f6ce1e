//! Material parameters that may vary over a surface and with wavelength.
//!
//! A [`SpectralTexture`] is a spectrum the same everywhere (RGB uplifted once, a named
//! measured spectrum, a blackbody, a piecewise-linear list) or an RGB texture uplifted at each
//! lookup (Jakob and Hanika 2019, through the shared coefficient table). Which of pbrt-v4's
//! three kinds of uplift applies is the parameter's [`SpectrumKind`]: reflectances are
//! bounded by 1, indices of refraction are not, emitters are illuminants.

use crate::color::Color;
use crate::texture::{Texture, TextureCoords};
use plenum_spectrum::uplift::d65_normalized;
use plenum_spectrum::{
    RgbSigmoid, RgbToSpectrumTable, SampledSpectrum, SampledWavelengths, Spectrum,
};
use std::sync::OnceLock;

/// How an RGB value becomes a spectrum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpectrumKind {
    /// Reflectance or transmittance: clamped to [0, 1].
    Albedo,
    /// Any non-negative value (η, k).
    Unbounded,
    /// Emitted radiance: times the colour space's illuminant (D65 for sRGB).
    Illuminant,
}

/// The spectrum of an RGB value of that kind, fitted exactly (a few dozen microseconds; the
/// shared table serves textures, looked up per hit).
pub fn uplift(c: Color, kind: SpectrumKind) -> Spectrum {
    let rgb = [c.r.max(0.0), c.g.max(0.0), c.b.max(0.0)];
    let m = rgb[0].max(rgb[1]).max(rgb[2]);
    match kind {
        SpectrumKind::Albedo => {
            let rgb = rgb.map(|v| v.min(1.0));
            Spectrum::RgbAlbedo {
                rgb,
                sigmoid: RgbSigmoid::fit(rgb),
            }
        }
        SpectrumKind::Unbounded | SpectrumKind::Illuminant => {
            let (scale, sigmoid) = if m > 0.0 {
                (2.0 * m, RgbSigmoid::fit(rgb.map(|v| v / (2.0 * m))))
            } else {
                (0.0, RgbSigmoid::constant(0.0))
            };
            if kind == SpectrumKind::Unbounded {
                Spectrum::RgbUnbounded {
                    rgb,
                    scale,
                    sigmoid,
                }
            } else {
                Spectrum::RgbIlluminant {
                    rgb,
                    scale,
                    sigmoid,
                }
            }
        }
    }
}

/// A spectrum with its RGB projection kept for RGB mode. One given as RGB is uplifted only
/// when a spectral render first asks for it, so RGB renders never build the uplift table.
#[derive(Clone, Debug)]
pub struct SpectrumValue {
    spectrum: OnceLock<Spectrum>,
    rgb: [f64; 3],
    kind: SpectrumKind,
}

impl SpectrumValue {
    pub fn new(spectrum: Spectrum, kind: SpectrumKind) -> SpectrumValue {
        let rgb = match kind {
            SpectrumKind::Illuminant => spectrum.to_rgb_illuminant(),
            _ => spectrum.to_rgb_reflectance(),
        };
        SpectrumValue {
            spectrum: OnceLock::from(spectrum),
            rgb,
            kind,
        }
    }

    pub fn from_rgb(c: Color, kind: SpectrumKind) -> SpectrumValue {
        SpectrumValue {
            spectrum: OnceLock::new(),
            rgb: [c.r, c.g, c.b],
            kind,
        }
    }

    #[inline]
    pub fn sample(&self, wl: &SampledWavelengths) -> SampledSpectrum {
        if wl.is_rgb() {
            let [r, g, b] = self.rgb;
            SampledSpectrum([r, g, b, 0.0])
        } else {
            self.spectrum().sample(wl)
        }
    }

    pub fn rgb(&self) -> Color {
        Color::new(self.rgb[0], self.rgb[1], self.rgb[2])
    }

    pub fn spectrum(&self) -> &Spectrum {
        self.spectrum.get_or_init(|| {
            let [r, g, b] = self.rgb;
            uplift(Color::new(r, g, b), self.kind)
        })
    }
}

#[derive(Clone, Debug)]
pub enum SpectralTexture {
    Constant(SpectrumValue),
    /// An RGB texture, uplifted per lookup.
    Rgb {
        texture: Texture,
        kind: SpectrumKind,
    },
}

impl SpectralTexture {
    /// An RGB texture; a constant one is uplifted once, here.
    pub fn from_texture(texture: Texture, kind: SpectrumKind) -> SpectralTexture {
        match texture {
            Texture::Constant(c) => SpectralTexture::Constant(SpectrumValue::from_rgb(c, kind)),
            texture => SpectralTexture::Rgb { texture, kind },
        }
    }

    pub fn constant(c: Color, kind: SpectrumKind) -> SpectralTexture {
        SpectralTexture::Constant(SpectrumValue::from_rgb(c, kind))
    }

    #[inline]
    pub fn evaluate(&self, at: &TextureCoords, wl: &SampledWavelengths) -> SampledSpectrum {
        match self {
            SpectralTexture::Constant(v) => v.sample(wl),
            SpectralTexture::Rgb { texture, kind } => {
                let mut c = texture.evaluate(at);
                if *kind == SpectrumKind::Albedo {
                    c = Color::new(
                        c.r.clamp(0.0, 1.0),
                        c.g.clamp(0.0, 1.0),
                        c.b.clamp(0.0, 1.0),
                    );
                }
                if wl.is_rgb() {
                    SampledSpectrum([c.r, c.g, c.b, 0.0])
                } else {
                    uplift_at(c, *kind, wl)
                }
            }
        }
    }

    /// The RGB value the parameter shows in Whitted's model (a texture's at this point).
    pub fn rgb(&self, at: &TextureCoords) -> Color {
        match self {
            SpectralTexture::Constant(v) => v.rgb(),
            SpectralTexture::Rgb { texture, .. } => texture.evaluate(at),
        }
    }

    pub fn needs_uv(&self) -> bool {
        match self {
            SpectralTexture::Constant(_) => false,
            SpectralTexture::Rgb { texture, .. } => texture.needs_uv(),
        }
    }

    /// The same value at every wavelength, so that a dielectric of this η does not disperse.
    pub fn is_constant(&self) -> bool {
        match self {
            SpectralTexture::Constant(v) => v.spectrum().is_constant(),
            SpectralTexture::Rgb { .. } => false,
        }
    }
}

/// An RGB value's spectrum at the sample's wavelengths, through the shared table (pbrt-v4's
/// three kinds: the unbounded ones scaled by twice their largest component, illuminants
/// times D65 of unit luminance).
pub(crate) fn uplift_at(c: Color, kind: SpectrumKind, wl: &SampledWavelengths) -> SampledSpectrum {
    let rgb = [c.r.max(0.0), c.g.max(0.0), c.b.max(0.0)];
    let table = RgbToSpectrumTable::srgb();
    let (scale, sigmoid) = match kind {
        SpectrumKind::Albedo => (1.0, table.lookup(rgb)),
        SpectrumKind::Unbounded | SpectrumKind::Illuminant => match scaled_sigmoid(rgb) {
            Some(fit) => fit,
            None => return SampledSpectrum::ZERO,
        },
    };
    let mut s = SampledSpectrum::ZERO;
    for (i, &l) in wl.lambda().iter().enumerate() {
        s[i] = scale * sigmoid.eval(l);
        if kind == SpectrumKind::Illuminant {
            s[i] *= d65_normalized(l);
        }
    }
    s
}

/// A non-negative RGB value of no bound as pbrt-v4 uplifts it: a scale, twice its largest
/// channel, and the sigmoid of the reflectance it scales (an illuminant's spectrum is their
/// product times D65 of unit luminance); `None` for black.
pub(crate) fn scaled_sigmoid(rgb: [f64; 3]) -> Option<(f64, RgbSigmoid)> {
    let m = rgb[0].max(rgb[1]).max(rgb[2]);
    if m == 0.0 {
        return None;
    }
    let scale = 2.0 * m;
    Some((
        scale,
        RgbToSpectrumTable::srgb().lookup(rgb.map(|v| v / scale)),
    ))
}

/// Emitted radiance given as linear RGB, at the sample's wavelengths.
pub fn uplift_illuminant(c: Color, wl: &SampledWavelengths) -> SampledSpectrum {
    uplift_at(c, SpectrumKind::Illuminant, wl)
}

/// Radiance given as linear RGB (a Phong k_e, an environment map's), at the sample's
/// wavelengths: the three channels themselves in RGB mode, else an illuminant spectrum.
#[inline]
pub fn rgb_radiance(c: Color, wl: &SampledWavelengths) -> SampledSpectrum {
    if wl.is_rgb() {
        SampledSpectrum([c.r, c.g, c.b, 0.0])
    } else {
        uplift_illuminant(c, wl)
    }
}

/// `s` times `k`, as a spectrum of the same kind.
pub fn scaled(s: &Spectrum, k: f64) -> Spectrum {
    if k == 1.0 {
        return s.clone();
    }
    match s {
        Spectrum::Constant(c) => Spectrum::Constant(c * k),
        Spectrum::Blackbody { kelvin, scale } => Spectrum::blackbody(*kelvin, scale * k),
        Spectrum::RgbIlluminant { rgb, .. } => Spectrum::rgb_illuminant(rgb.map(|v| v * k)),
        Spectrum::RgbAlbedo { rgb, .. } | Spectrum::RgbUnbounded { rgb, .. } => {
            Spectrum::rgb_unbounded(rgb.map(|v| v * k))
        }
        Spectrum::PiecewiseLinear(p) => {
            let pairs: Vec<(f64, f64)> = p
                .wavelengths()
                .iter()
                .zip(p.values())
                .map(|(&l, &v)| (l, v * k))
                .collect();
            let made = if p.is_illuminant() {
                Spectrum::piecewise_illuminant(&pairs)
            } else {
                Spectrum::piecewise(&pairs)
            };
            made.unwrap_or_else(|_| s.clone())
        }
        // Dispersion formulas are indices, never scaled.
        other => other.clone(),
    }
}

/// The RGB value an uplifted spectrum came from, if it is one.
pub fn source_rgb(s: &Spectrum) -> Option<[f64; 3]> {
    match s {
        Spectrum::RgbAlbedo { rgb, .. }
        | Spectrum::RgbUnbounded { rgb, .. }
        | Spectrum::RgbIlluminant { rgb, .. } => Some(*rgb),
        _ => None,
    }
}

/// A scalar parameter: a constant or a texture's mean channel.
#[derive(Clone, Debug)]
pub enum FloatTexture {
    Constant(f64),
    Texture(Texture),
}

impl FloatTexture {
    #[inline]
    pub fn evaluate(&self, at: &TextureCoords) -> f64 {
        match self {
            FloatTexture::Constant(v) => *v,
            FloatTexture::Texture(t) => {
                let c = t.evaluate(at);
                (c.r + c.g + c.b) / 3.0
            }
        }
    }

    pub fn needs_uv(&self) -> bool {
        match self {
            FloatTexture::Constant(_) => false,
            FloatTexture::Texture(t) => t.needs_uv(),
        }
    }
}
