//! Input spectra: what scene descriptions give for reflectances, emission and refractive
//! indices, evaluated at a sample's wavelengths (spectral mode) or projected to linear sRGB
//! (RGB mode). The variants follow pbrt-v4's spectrum classes (constant, piecewise linear,
//! blackbody, the three RGB kinds of Jakob and Hanika's uplift), plus dispersion formulas
//! (Sellmeier, Cauchy, Ciddor 1996 for air) for refractive indices.

use std::sync::{Arc, OnceLock};

use crate::blackbody::normalized_blackbody;
use crate::cie::{cie_xyz, CIE_LAMBDA_MAX, CIE_LAMBDA_MIN, CIE_SAMPLES, CIE_Y_INTEGRAL};
use crate::color::xyz_to_linear_srgb;
use crate::sampled::{SampledSpectrum, SampledWavelengths, N_SAMPLES};
use crate::uplift::{d65_normalized, RgbSigmoid, RgbToSpectrumTable};

/// Linear sRGB of `f` as a reflectance under D65: ∫ f D65 x̄ȳz̄ dλ / ∫ D65 ȳ dλ at 1 nm over
/// 360–830 nm, then [`crate::color::XYZ_TO_SRGB`]. A constant 1 gives (1, 1, 1) (to 1e-3,
/// the sRGB matrix's rounding of the white point).
pub fn reflectance_to_rgb(f: impl Fn(f64) -> f64) -> [f64; 3] {
    let mut xyz = [0.0; 3];
    let mut norm = 0.0;
    for i in 0..CIE_SAMPLES {
        let l = CIE_LAMBDA_MIN + i as f64;
        let d = d65_normalized(l);
        let cmf = cie_xyz(l);
        let v = f(l) * d;
        norm += d * cmf[1];
        for c in 0..3 {
            xyz[c] += v * cmf[c];
        }
    }
    xyz_to_linear_srgb(xyz.map(|v| v / norm))
}

/// Linear sRGB of `f` as emitted radiance: ∫ f x̄ȳz̄ dλ / [`CIE_Y_INTEGRAL`] at 1 nm over
/// 360–830 nm, then [`crate::color::XYZ_TO_SRGB`]: the expectation of
/// [`SampledSpectrum::to_linear_srgb`] for that radiance, so an [`Spectrum::RgbIlluminant`]
/// of (r, g, b) gives back (r, g, b).
pub fn illuminant_to_rgb(f: impl Fn(f64) -> f64) -> [f64; 3] {
    let mut xyz = [0.0; 3];
    for i in 0..CIE_SAMPLES {
        let l = CIE_LAMBDA_MIN + i as f64;
        let v = f(l);
        let cmf = cie_xyz(l);
        for c in 0..3 {
            xyz[c] += v * cmf[c];
        }
    }
    xyz_to_linear_srgb(xyz.map(|v| v / CIE_Y_INTEGRAL))
}

/// A piecewise-linear spectrum: values at increasing wavelengths (nm), linearly interpolated
/// and 0 outside the first and last wavelength (as pbrt-v4's `PiecewiseLinearSpectrum`).
#[derive(Debug)]
pub struct PiecewiseLinear {
    lambda: Vec<f64>,
    value: Vec<f64>,
    illuminant: bool,
    rgb: OnceLock<[f64; 3]>,
}

impl PiecewiseLinear {
    /// The value at `lambda` nm.
    pub fn eval(&self, lambda: f64) -> f64 {
        let (l, v) = (&self.lambda, &self.value);
        if lambda < l[0] || lambda > l[l.len() - 1] {
            return 0.0;
        }
        if l.len() == 1 {
            return v[0];
        }
        let i = l.partition_point(|&x| x <= lambda).clamp(1, l.len() - 1) - 1;
        let t = (lambda - l[i]) / (l[i + 1] - l[i]);
        v[i] + t * (v[i + 1] - v[i])
    }

    /// The wavelengths, nm.
    pub fn wavelengths(&self) -> &[f64] {
        &self.lambda
    }

    /// The values at [`Self::wavelengths`].
    pub fn values(&self) -> &[f64] {
        &self.value
    }

    /// Whether this is an emission spectrum (projected to RGB as an illuminant).
    pub fn is_illuminant(&self) -> bool {
        self.illuminant
    }
}

/// A spectral quantity given by a scene: reflectance, emitted radiance or refractive index,
/// as a function of wavelength in nm. Clones are cheap (tables are shared behind an `Arc`).
#[derive(Clone, Debug)]
pub enum Spectrum {
    /// The same value at every wavelength.
    Constant(f64),
    /// Tabulated values, linearly interpolated, 0 outside the table's range.
    PiecewiseLinear(Arc<PiecewiseLinear>),
    /// `scale` × the blackbody spectrum at `kelvin` K normalised to 1 at its peak (pbrt-v4's
    /// `BlackbodySpectrum`); an emission spectrum.
    Blackbody {
        /// Temperature, K.
        kelvin: f64,
        /// Value at the peak wavelength.
        scale: f64,
    },
    /// A reflectance in [0, 1] from linear-sRGB `rgb` (clamped to [0, 1]): the sigmoid.
    RgbAlbedo {
        /// The linear-sRGB reflectance given, in [0, 1].
        rgb: [f64; 3],
        /// Its uplifted spectrum.
        sigmoid: RgbSigmoid,
    },
    /// An unbounded positive quantity from `rgb`: `scale` · sigmoid(λ) with scale = 2 · max
    /// component and the sigmoid fitted to rgb / scale (pbrt-v4's `RGBUnboundedSpectrum`).
    RgbUnbounded {
        /// The linear-sRGB value given, ≥ 0.
        rgb: [f64; 3],
        /// 2 × the largest component.
        scale: f64,
        /// The sigmoid of rgb / scale.
        sigmoid: RgbSigmoid,
    },
    /// Emission from `rgb`: the unbounded form times D65 of unit luminance
    /// ([`d65_normalized`]), so seen directly it converts back to `rgb` (pbrt-v4's
    /// `RGBIlluminantSpectrum`).
    RgbIlluminant {
        /// The linear-sRGB radiance given, ≥ 0.
        rgb: [f64; 3],
        /// 2 × the largest component.
        scale: f64,
        /// The sigmoid of rgb / scale.
        sigmoid: RgbSigmoid,
    },
    /// Sellmeier's dispersion formula n(λ) = √(1 + Σ Bᵢ λ² / (λ² − Cᵢ)), λ in µm, C in µm².
    Sellmeier {
        /// Oscillator strengths Bᵢ, dimensionless.
        b: [f64; 3],
        /// Resonance wavelengths squared Cᵢ, µm².
        c: [f64; 3],
    },
    /// The four-term Sellmeier formula (Daimon and Masumura's form for water), λ in µm.
    Sellmeier4 {
        /// Oscillator strengths Bᵢ, dimensionless.
        b: [f64; 4],
        /// Resonance wavelengths squared Cᵢ, µm².
        c: [f64; 4],
    },
    /// Cauchy's formula n(λ) = a + b / λ², λ in µm, b in µm².
    Cauchy {
        /// The index at infinite wavelength.
        a: f64,
        /// The dispersion coefficient, µm².
        b: f64,
    },
    /// The refractive index of standard dry air (15 °C, 101 325 Pa, 450 ppm CO₂) after
    /// Ciddor 1996, "Refractive index of air: new equations for the visible and near
    /// infrared", Appl. Opt. 35, 1566: n − 1 = 0.05792105 / (238.0185 − σ²) +
    /// 0.00167917 / (57.362 − σ²), σ = 1/λ in µm⁻¹ (valid 230–1690 nm).
    CiddorAir,
}

impl Spectrum {
    /// A piecewise-linear reflectance-like spectrum from (wavelength nm, value) pairs, the
    /// wavelengths strictly increasing; 0 outside the first and last wavelength. Errors on an
    /// empty list, non-finite numbers or wavelengths not strictly increasing.
    pub fn piecewise(pairs: &[(f64, f64)]) -> Result<Spectrum, String> {
        Self::piecewise_kind(pairs, false)
    }

    /// As [`Self::piecewise`], for an emission spectrum (RGB mode projects it as an
    /// illuminant).
    pub fn piecewise_illuminant(pairs: &[(f64, f64)]) -> Result<Spectrum, String> {
        Self::piecewise_kind(pairs, true)
    }

    fn piecewise_kind(pairs: &[(f64, f64)], illuminant: bool) -> Result<Spectrum, String> {
        if pairs.is_empty() {
            return Err("piecewise-linear spectrum: no (wavelength, value) pairs".into());
        }
        for (i, &(l, v)) in pairs.iter().enumerate() {
            if !l.is_finite() || !v.is_finite() {
                return Err(format!(
                    "piecewise-linear spectrum: pair {i} ({l}, {v}) is not finite"
                ));
            }
            if i > 0 && l <= pairs[i - 1].0 {
                return Err(format!(
                    "piecewise-linear spectrum: wavelengths not increasing at pair {i} ({} then {l})",
                    pairs[i - 1].0
                ));
            }
        }
        Ok(Spectrum::PiecewiseLinear(Arc::new(PiecewiseLinear {
            lambda: pairs.iter().map(|p| p.0).collect(),
            value: pairs.iter().map(|p| p.1).collect(),
            illuminant,
            rgb: OnceLock::new(),
        })))
    }

    /// `scale` × the peak-normalised blackbody at `kelvin` K.
    pub fn blackbody(kelvin: f64, scale: f64) -> Spectrum {
        Spectrum::Blackbody { kelvin, scale }
    }

    /// A reflectance from linear sRGB (clamped to [0, 1]), by the shared sRGB table.
    pub fn rgb_albedo(rgb: [f64; 3]) -> Spectrum {
        let rgb = rgb.map(|v| v.clamp(0.0, 1.0));
        Spectrum::RgbAlbedo {
            rgb,
            sigmoid: RgbToSpectrumTable::srgb().lookup(rgb),
        }
    }

    /// An unbounded spectrum from linear sRGB (negative components clamped to 0).
    pub fn rgb_unbounded(rgb: [f64; 3]) -> Spectrum {
        let rgb = rgb.map(|v| v.max(0.0));
        let (scale, sigmoid) = unbounded_fit(rgb);
        Spectrum::RgbUnbounded {
            rgb,
            scale,
            sigmoid,
        }
    }

    /// An emission spectrum from linear sRGB radiance (negative components clamped to 0).
    pub fn rgb_illuminant(rgb: [f64; 3]) -> Spectrum {
        let rgb = rgb.map(|v| v.max(0.0));
        let (scale, sigmoid) = unbounded_fit(rgb);
        Spectrum::RgbIlluminant {
            rgb,
            scale,
            sigmoid,
        }
    }

    /// The value at `lambda_nm` (units of the quantity: reflectance, radiance relative to the
    /// scene's scale, or refractive index).
    pub fn eval(&self, lambda_nm: f64) -> f64 {
        match self {
            Spectrum::Constant(c) => *c,
            Spectrum::PiecewiseLinear(p) => p.eval(lambda_nm),
            Spectrum::Blackbody { kelvin, scale } => {
                scale * normalized_blackbody(lambda_nm, *kelvin)
            }
            Spectrum::RgbAlbedo { sigmoid, .. } => sigmoid.eval(lambda_nm),
            Spectrum::RgbUnbounded { scale, sigmoid, .. } => scale * sigmoid.eval(lambda_nm),
            Spectrum::RgbIlluminant { scale, sigmoid, .. } => {
                scale * sigmoid.eval(lambda_nm) * d65_normalized(lambda_nm)
            }
            Spectrum::Sellmeier { b, c } => sellmeier(b, c, lambda_nm),
            Spectrum::Sellmeier4 { b, c } => sellmeier(b, c, lambda_nm),
            Spectrum::Cauchy { a, b } => {
                let l = lambda_nm * 1e-3;
                a + b / (l * l)
            }
            Spectrum::CiddorAir => {
                let s2 = (1e3 / lambda_nm).powi(2);
                1.0 + 0.05792105 / (238.0185 - s2) + 0.00167917 / (57.362 - s2)
            }
        }
    }

    /// Whether this is an emission spectrum (blackbody, RGB illuminant, or a piecewise
    /// spectrum made as one): RGB mode projects those with [`Self::to_rgb_illuminant`].
    pub fn is_illuminant(&self) -> bool {
        match self {
            Spectrum::Blackbody { .. } | Spectrum::RgbIlluminant { .. } => true,
            Spectrum::PiecewiseLinear(p) => p.illuminant,
            _ => false,
        }
    }

    /// Whether this is a refractive-index formula, which RGB mode evaluates at the lanes'
    /// representative wavelength (589.3 nm) rather than projecting.
    pub fn is_dispersion_formula(&self) -> bool {
        matches!(
            self,
            Spectrum::Sellmeier { .. }
                | Spectrum::Sellmeier4 { .. }
                | Spectrum::Cauchy { .. }
                | Spectrum::CiddorAir
        )
    }

    /// The values at the sample's wavelengths. Spectral mode: [`Self::eval`] at each.
    /// RGB mode, lanes R, G, B, 0: a constant its value; RGB variants exactly their rgb;
    /// dispersion formulas their value at the lanes' wavelength (589.3 nm); other spectra
    /// their linear-sRGB projection, as a reflectance ([`Self::to_rgb_reflectance`]) or, for
    /// emission spectra, as an illuminant ([`Self::to_rgb_illuminant`]). Tabulated spectra
    /// cache the projection; a blackbody computes it per call, so convert it once with
    /// [`Self::to_rgb_mode`] when rendering in RGB.
    pub fn sample(&self, wl: &SampledWavelengths) -> SampledSpectrum {
        if !wl.is_rgb() {
            // The kinds every scene has, matched once for all lanes.
            let l = wl.lambda();
            return SampledSpectrum(match self {
                Spectrum::Constant(c) => [*c; N_SAMPLES],
                Spectrum::RgbAlbedo { sigmoid, .. } => sigmoid.eval_lanes(l),
                Spectrum::RgbUnbounded { scale, sigmoid, .. } => {
                    sigmoid.eval_lanes(l).map(|s| scale * s)
                }
                Spectrum::RgbIlluminant { scale, sigmoid, .. } => {
                    let s = sigmoid.eval_lanes(l);
                    std::array::from_fn(|i| scale * s[i] * d65_normalized(l[i]))
                }
                _ => l.map(|x| self.eval(x)),
            });
        }
        let rgb = match self {
            Spectrum::Constant(c) => [*c; 3],
            Spectrum::RgbAlbedo { rgb, .. }
            | Spectrum::RgbUnbounded { rgb, .. }
            | Spectrum::RgbIlluminant { rgb, .. } => *rgb,
            s if s.is_dispersion_formula() => [0, 1, 2].map(|i| s.eval(wl.lambda()[i])),
            Spectrum::PiecewiseLinear(p) => *p.rgb.get_or_init(|| self.projected_rgb()),
            _ => self.projected_rgb(),
        };
        SampledSpectrum([rgb[0], rgb[1], rgb[2], 0.0])
    }

    fn projected_rgb(&self) -> [f64; 3] {
        if self.is_illuminant() {
            self.to_rgb_illuminant()
        } else {
            self.to_rgb_reflectance()
        }
    }

    /// Linear sRGB of this spectrum as a reflectance (or other unbounded factor) under D65,
    /// normalised so that a constant 1 gives (1, 1, 1); RGB albedo and unbounded variants
    /// give their rgb exactly.
    pub fn to_rgb_reflectance(&self) -> [f64; 3] {
        match self {
            Spectrum::Constant(c) => [*c; 3],
            Spectrum::RgbAlbedo { rgb, .. } | Spectrum::RgbUnbounded { rgb, .. } => *rgb,
            _ => reflectance_to_rgb(|l| self.eval(l)),
        }
    }

    /// Linear sRGB of this spectrum as emitted radiance: ∫ s x̄ȳz̄ / [`CIE_Y_INTEGRAL`], the
    /// normalisation under which an RGB illuminant of (r, g, b) gives (r, g, b) back (and
    /// the named `stdillum-D65`, of unit luminance, gives (1, 1, 1)).
    pub fn to_rgb_illuminant(&self) -> [f64; 3] {
        match self {
            Spectrum::RgbIlluminant { rgb, .. } => *rgb,
            _ => illuminant_to_rgb(|l| self.eval(l)),
        }
    }

    /// The spectrum RGB rendering should use: tabulated and blackbody spectra replaced by
    /// an RGB variant of their projection (so [`Self::sample`] in RGB mode is a copy), the
    /// others unchanged.
    pub fn to_rgb_mode(&self) -> Spectrum {
        match self {
            Spectrum::PiecewiseLinear(_) | Spectrum::Blackbody { .. } => {
                if self.is_illuminant() {
                    Spectrum::rgb_illuminant(self.to_rgb_illuminant())
                } else {
                    Spectrum::rgb_unbounded(self.to_rgb_reflectance())
                }
            }
            _ => self.clone(),
        }
    }

    /// Whether the spectrum has the same value at every wavelength of the sampled range
    /// 360–830 nm (constants, grey RGB reflectances, a flat table covering the range).
    pub fn is_constant(&self) -> bool {
        match self {
            Spectrum::Constant(_) => true,
            Spectrum::RgbAlbedo { sigmoid, .. } | Spectrum::RgbUnbounded { sigmoid, .. } => {
                sigmoid.c0 == 0.0 && sigmoid.c1 == 0.0
            }
            Spectrum::PiecewiseLinear(p) => {
                p.lambda[0] <= CIE_LAMBDA_MIN
                    && p.lambda[p.lambda.len() - 1] >= CIE_LAMBDA_MAX
                    && p.value.iter().all(|&v| v == p.value[0])
            }
            Spectrum::Sellmeier { b, .. } => b.iter().all(|&v| v == 0.0),
            Spectrum::Sellmeier4 { b, .. } => b.iter().all(|&v| v == 0.0),
            Spectrum::Cauchy { b, .. } => *b == 0.0,
            Spectrum::Blackbody { scale, .. } => *scale == 0.0,
            Spectrum::RgbIlluminant { scale, .. } => *scale == 0.0,
            Spectrum::CiddorAir => false,
        }
    }

    /// An upper bound of the value: exact for constants, tables and RGB albedos; for the
    /// others the maximum over 360–830 nm (blackbody: its scale, the peak; RGB illuminants:
    /// scale × the sigmoid's maximum × D65's maximum).
    pub fn max_value(&self) -> f64 {
        match self {
            Spectrum::Constant(c) => *c,
            Spectrum::PiecewiseLinear(p) => {
                p.value.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            }
            Spectrum::Blackbody { scale, .. } => *scale,
            Spectrum::RgbAlbedo { sigmoid, .. } => sigmoid.max_value(),
            Spectrum::RgbUnbounded { scale, sigmoid, .. } => scale * sigmoid.max_value(),
            Spectrum::RgbIlluminant { scale, sigmoid, .. } => {
                let d65_max = (0..CIE_SAMPLES)
                    .map(|i| d65_normalized(CIE_LAMBDA_MIN + i as f64))
                    .fold(0.0, f64::max);
                scale * sigmoid.max_value() * d65_max
            }
            _ => (0..CIE_SAMPLES)
                .map(|i| self.eval(CIE_LAMBDA_MIN + i as f64))
                .fold(f64::NEG_INFINITY, f64::max),
        }
    }
}

/// n(λ) = √(1 + Σ Bᵢ λ² / (λ² − Cᵢ)), λ given in nm and used in µm.
fn sellmeier(b: &[f64], c: &[f64], lambda_nm: f64) -> f64 {
    let l2 = (lambda_nm * 1e-3).powi(2);
    let n2 = 1.0 + b.iter().zip(c).map(|(b, c)| b * l2 / (l2 - c)).sum::<f64>();
    n2.max(0.0).sqrt()
}

/// pbrt-v4's unbounded parametrisation: scale = 2 · max component, sigmoid for rgb / scale.
fn unbounded_fit(rgb: [f64; 3]) -> (f64, RgbSigmoid) {
    let m = rgb[0].max(rgb[1]).max(rgb[2]);
    let scale = 2.0 * m;
    if scale > 0.0 {
        (
            scale,
            RgbToSpectrumTable::srgb().lookup(rgb.map(|v| v / scale)),
        )
    } else {
        (0.0, RgbSigmoid::constant(0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close3(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() <= tol * b[i].abs().max(1.0))
    }

    #[test]
    fn piecewise_parses_and_rejects() {
        let s = Spectrum::piecewise(&[(400.0, 1.0), (500.0, 3.0)]).unwrap();
        assert_eq!(s.eval(450.0), 2.0);
        assert_eq!(s.eval(399.0), 0.0);
        assert_eq!(s.eval(501.0), 0.0);
        assert_eq!(s.eval(500.0), 3.0);
        assert_eq!(s.max_value(), 3.0);
        assert!(Spectrum::piecewise(&[]).is_err());
        assert!(Spectrum::piecewise(&[(500.0, 1.0), (400.0, 1.0)]).is_err());
        assert!(Spectrum::piecewise(&[(400.0, 1.0), (400.0, 2.0)]).is_err());
        assert!(Spectrum::piecewise(&[(400.0, f64::NAN)]).is_err());
        assert!(Spectrum::piecewise(&[(f64::INFINITY, 1.0)]).is_err());
    }

    #[test]
    fn constant_one_projects_to_white() {
        let one = Spectrum::piecewise(&[(300.0, 1.0), (900.0, 1.0)]).unwrap();
        assert!(one.is_constant());
        assert!(
            close3(one.to_rgb_reflectance(), [1.0; 3], 1e-3),
            "{:?}",
            one.to_rgb_reflectance()
        );
        assert_eq!(
            Spectrum::Constant(0.5).sample(&SampledWavelengths::rgb()).0,
            [0.5, 0.5, 0.5, 0.0]
        );
    }

    #[test]
    fn d65_illuminant_white_is_srgb_white() {
        let d65 = Spectrum::rgb_illuminant([1.0; 3]);
        // Spectral: the integral the film estimates.
        let rgb = emitted_rgb(&d65);
        assert!(close3(rgb, [1.0; 3], 0.01), "{rgb:?}");
        // And by Monte Carlo through to_linear_srgb, many stratified samples.
        let n = 2000;
        let mut acc = [0.0; 3];
        for k in 0..n {
            let wl = SampledWavelengths::sample_visible((k as f64 + 0.5) / n as f64);
            let c = d65.sample(&wl).to_linear_srgb(&wl);
            for i in 0..3 {
                acc[i] += c[i] / n as f64;
            }
        }
        assert!(close3(acc, [1.0; 3], 0.01), "{acc:?}");
    }

    fn emitted_rgb(s: &Spectrum) -> [f64; 3] {
        illuminant_to_rgb(|l| s.eval(l))
    }

    #[test]
    fn illuminant_round_trips() {
        for rgb in [
            [17.0, 12.0, 4.0],
            [1.0, 0.0, 0.0],
            [0.2, 0.5, 0.9],
            [3.0, 3.0, 3.0],
            [0.05, 0.3, 0.01],
        ] {
            let s = Spectrum::rgb_illuminant(rgb);
            let back = emitted_rgb(&s);
            let m = rgb.iter().copied().fold(0.0, f64::max);
            for i in 0..3 {
                assert!((back[i] - rgb[i]).abs() < 0.01 * m, "{rgb:?} → {back:?}");
            }
            assert_eq!(s.to_rgb_illuminant(), rgb);
        }
    }

    #[test]
    fn unbounded_round_trips() {
        for rgb in [[2.0, 0.5, 0.1], [0.3, 0.3, 0.31], [5.0, 0.0, 2.0]] {
            let s = Spectrum::rgb_unbounded(rgb);
            let back = reflectance_to_rgb(|l| s.eval(l));
            for i in 0..3 {
                assert!(
                    (back[i] - rgb[i]).abs() < 0.01 * rgb[0].max(rgb[1]).max(rgb[2]),
                    "{rgb:?} → {back:?}"
                );
            }
        }
    }

    #[test]
    fn rgb_mode_sampling() {
        let wl = SampledWavelengths::rgb();
        let a = Spectrum::rgb_albedo([0.2, 0.4, 0.6]);
        assert_eq!(a.sample(&wl).0, [0.2, 0.4, 0.6, 0.0]);
        let glass = Spectrum::Sellmeier {
            b: [1.0, 0.0, 0.0],
            c: [0.01, 0.0, 0.0],
        };
        let s = glass.sample(&wl);
        assert_eq!(s[0], glass.eval(589.3));
        assert_eq!(s[3], 0.0);
        let bb = Spectrum::blackbody(6500.0, 1.0);
        let p = bb.sample(&wl);
        let q = bb.to_rgb_mode().sample(&wl);
        for i in 0..3 {
            assert!((p[i] - q[i]).abs() < 1e-12);
        }
        // A 6500 K blackbody is nearly white; blue and red within 15 % of green.
        assert!(
            (p[0] / p[1] - 1.0).abs() < 0.15 && (p[2] / p[1] - 1.0).abs() < 0.15,
            "{p:?}"
        );
    }

    #[test]
    fn spectral_sampling_evaluates_each_lane() {
        let wl = SampledWavelengths::sample_visible(0.37);
        let s = Spectrum::blackbody(3000.0, 2.0);
        let v = s.sample(&wl);
        for i in 0..N_SAMPLES {
            assert_eq!(v[i], s.eval(wl.lambda()[i]));
        }
        assert!(s.max_value() >= v.max_value());
    }

    #[test]
    fn clones_share_tables() {
        let s = Spectrum::piecewise(&[(400.0, 1.0), (500.0, 3.0)]).unwrap();
        let t = s.clone();
        match (&s, &t) {
            (Spectrum::PiecewiseLinear(a), Spectrum::PiecewiseLinear(b)) => {
                assert!(Arc::ptr_eq(a, b))
            }
            _ => unreachable!(),
        }
    }
}
