//! Values at a few wavelengths at once: what a camera sample carries through the scene.
//!
//! In spectral mode a sample carries [`N_SAMPLES`] wavelengths, a hero wavelength and the
//! others equally spaced from it across the visible range (Wilkie et al. 2014, "Hero
//! Wavelength Spectral Sampling"). In RGB mode the same lanes hold red, green and blue (the
//! last lane unused), so integrators and BSDFs are written once for both modes; only the
//! evaluation of input spectra and the film's conversion differ.

use std::ops::{Add, AddAssign, Div, DivAssign, Index, IndexMut, Mul, MulAssign, Neg, Sub};

/// Wavelengths a sample carries.
pub const N_SAMPLES: usize = 4;

/// The shortest wavelength sampled, nm.
pub const LAMBDA_MIN: f64 = 360.0;
/// The longest wavelength sampled, nm.
pub const LAMBDA_MAX: f64 = 830.0;

/// Spectral values (radiance, reflectance, a path's throughput) at the sample's wavelengths,
/// or R, G, B and 0 in RGB mode.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SampledSpectrum(pub [f64; N_SAMPLES]);

impl SampledSpectrum {
    /// 0 in every lane.
    pub const ZERO: SampledSpectrum = SampledSpectrum([0.0; N_SAMPLES]);
    /// 1 in every lane.
    pub const ONE: SampledSpectrum = SampledSpectrum([1.0; N_SAMPLES]);

    /// `v` in every lane.
    #[inline]
    pub const fn splat(v: f64) -> Self {
        SampledSpectrum([v; N_SAMPLES])
    }

    /// `f` applied to each lane.
    #[inline]
    pub fn map(self, f: impl Fn(f64) -> f64) -> Self {
        SampledSpectrum(self.0.map(f))
    }

    /// `f` applied lane by lane to `self` and `o`.
    #[inline]
    pub fn zip(self, o: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        let mut r = self;
        for i in 0..N_SAMPLES {
            r.0[i] = f(self.0[i], o.0[i]);
        }
        r
    }

    /// Every lane is 0.
    #[inline]
    pub fn is_black(&self) -> bool {
        self.0.iter().all(|&v| v == 0.0)
    }

    /// The largest lane.
    #[inline]
    pub fn max_value(&self) -> f64 {
        self.0.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }

    /// The smallest lane.
    #[inline]
    pub fn min_value(&self) -> f64 {
        self.0.iter().copied().fold(f64::INFINITY, f64::min)
    }

    /// The mean of the lanes (in RGB mode the unused lane counts as 0).
    #[inline]
    pub fn average(&self) -> f64 {
        self.0.iter().sum::<f64>() / N_SAMPLES as f64
    }

    /// Every value is finite (no NaN, no infinity).
    #[inline]
    pub fn is_finite(&self) -> bool {
        self.0.iter().all(|v| v.is_finite())
    }

    /// self / o, with 0 wherever o is 0 (pbrt's `SafeDiv`).
    #[inline]
    pub fn safe_div(self, o: Self) -> Self {
        self.zip(o, |a, b| if b != 0.0 { a / b } else { 0.0 })
    }

    /// Square root per lane, negatives taken as 0.
    #[inline]
    pub fn sqrt(self) -> Self {
        self.map(|v| v.max(0.0).sqrt())
    }

    /// e^x per lane (transmittance from optical depth).
    #[inline]
    pub fn exp(self) -> Self {
        self.map(f64::exp)
    }

    /// Negative lanes set to 0.
    #[inline]
    pub fn clamp_zero(self) -> Self {
        self.map(|v| v.max(0.0))
    }
}

macro_rules! elementwise {
    ($trait:ident, $method:ident, $assign:ident, $assign_method:ident, $op:tt) => {
        impl $trait for SampledSpectrum {
            type Output = SampledSpectrum;
            #[inline]
            fn $method(self, o: SampledSpectrum) -> SampledSpectrum {
                self.zip(o, |a, b| a $op b)
            }
        }
        impl $trait<f64> for SampledSpectrum {
            type Output = SampledSpectrum;
            #[inline]
            fn $method(self, s: f64) -> SampledSpectrum {
                self.map(|a| a $op s)
            }
        }
        impl $assign for SampledSpectrum {
            #[inline]
            fn $assign_method(&mut self, o: SampledSpectrum) {
                *self = *self $op o;
            }
        }
        impl $assign<f64> for SampledSpectrum {
            #[inline]
            fn $assign_method(&mut self, s: f64) {
                *self = *self $op s;
            }
        }
    };
}

elementwise!(Add, add, AddAssign, add_assign, +);
elementwise!(Mul, mul, MulAssign, mul_assign, *);
elementwise!(Div, div, DivAssign, div_assign, /);

impl Sub for SampledSpectrum {
    type Output = SampledSpectrum;
    #[inline]
    fn sub(self, o: SampledSpectrum) -> SampledSpectrum {
        self.zip(o, |a, b| a - b)
    }
}

impl Mul<SampledSpectrum> for f64 {
    type Output = SampledSpectrum;
    #[inline]
    fn mul(self, s: SampledSpectrum) -> SampledSpectrum {
        s * self
    }
}

impl Neg for SampledSpectrum {
    type Output = SampledSpectrum;
    fn neg(self) -> SampledSpectrum {
        self.map(|v| -v)
    }
}

impl Index<usize> for SampledSpectrum {
    type Output = f64;
    fn index(&self, i: usize) -> &f64 {
        &self.0[i]
    }
}

impl IndexMut<usize> for SampledSpectrum {
    fn index_mut(&mut self, i: usize) -> &mut f64 {
        &mut self.0[i]
    }
}

/// How light is represented while rendering.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ColorMode {
    /// Wavelengths sampled per camera sample; the film integrates against the CIE observer.
    #[default]
    Spectral,
    /// Three channels, linear sRGB primaries, as RGB renderers work.
    Rgb,
}

/// The wavelengths (nm) a sample carries and their sampling densities (per nm), or the
/// three RGB channels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledWavelengths {
    lambda: [f64; N_SAMPLES],
    pdf: [f64; N_SAMPLES],
    mode: ColorMode,
}

impl SampledWavelengths {
    /// RGB mode: the lanes are channels. `lambda` reports a representative wavelength per
    /// channel for anything that must pick one (all at the sodium D line, 589.3 nm, so a
    /// dispersive medium in RGB mode takes its usual tabulated index).
    #[inline]
    pub fn rgb() -> Self {
        SampledWavelengths {
            lambda: [589.3; N_SAMPLES],
            pdf: [1.0, 1.0, 1.0, 0.0],
            mode: ColorMode::Rgb,
        }
    }

    /// Wavelengths and pdfs as given (tests and tools).
    #[inline]
    pub fn from_parts(lambda: [f64; N_SAMPLES], pdf: [f64; N_SAMPLES]) -> Self {
        SampledWavelengths {
            lambda,
            pdf,
            mode: ColorMode::Spectral,
        }
    }

    /// Uniform over [min, max]: the hero at u, the others equally spaced, wrapping around.
    #[inline]
    pub fn sample_uniform(u: f64, min: f64, max: f64) -> Self {
        let delta = (max - min) / N_SAMPLES as f64;
        let mut lambda = [0.0; N_SAMPLES];
        lambda[0] = min + u * (max - min);
        for i in 1..N_SAMPLES {
            lambda[i] = lambda[i - 1] + delta;
            if lambda[i] > max {
                lambda[i] = min + (lambda[i] - max);
            }
        }
        Self::from_parts(lambda, [1.0 / (max - min); N_SAMPLES])
    }

    /// Spectral mode, the hero wavelength drawn from [`visible_pdf`] by `u` in [0, 1) and the
    /// other [`N_SAMPLES`] − 1 from `u + i/N` wrapped into [0, 1), each mapped the same way, so
    /// the lanes are stratified over the visible density (pbrt-v4's `SampleVisible`).
    /// Every lane's pdf (per nm) is its own [`visible_pdf`].
    #[inline]
    pub fn sample_visible(u: f64) -> Self {
        let mut lambda = [0.0; N_SAMPLES];
        let mut pdf = [0.0; N_SAMPLES];
        for i in 0..N_SAMPLES {
            let mut up = u + i as f64 / N_SAMPLES as f64;
            if up >= 1.0 {
                up -= 1.0;
            }
            let x = VISIBLE_X0 - VISIBLE_DX * up;
            lambda[i] = 538.0 - VISIBLE_WIDTH * atanh(x);
            // The density of λ is du/dλ = (1 − x²) / (width · dx): the cosh² of
            // `visible_pdf` without an exponential (the two agree to 2e-7, pbrt-v4's
            // constants being rounded).
            pdf[i] = (1.0 - x * x) / (VISIBLE_WIDTH * VISIBLE_DX);
        }
        Self::from_parts(lambda, pdf)
    }

    /// Spectral or RGB.
    #[inline]
    pub fn mode(&self) -> ColorMode {
        self.mode
    }

    /// Whether the lanes are RGB channels.
    #[inline]
    pub fn is_rgb(&self) -> bool {
        self.mode == ColorMode::Rgb
    }

    /// The wavelengths, nm (589.3 in every lane in RGB mode).
    #[inline]
    pub fn lambda(&self) -> &[f64; N_SAMPLES] {
        &self.lambda
    }

    /// The sampling densities, per nm (RGB mode: 1, 1, 1, 0).
    #[inline]
    pub fn pdf(&self) -> SampledSpectrum {
        SampledSpectrum(self.pdf)
    }

    /// After a wavelength-dependent event (dispersive refraction) only the hero wavelength
    /// goes on: the others get pdf 0 and the hero's pdf is divided by N, since the path could
    /// have been started by any of the N (pbrt-v4's `TerminateSecondary`). Nothing happens in
    /// RGB mode or when already terminated.
    #[inline]
    pub fn terminate_secondary(&mut self) {
        if self.is_rgb() || self.secondary_terminated() {
            return;
        }
        for i in 1..N_SAMPLES {
            self.pdf[i] = 0.0;
        }
        self.pdf[0] /= N_SAMPLES as f64;
    }

    /// Whether only the hero wavelength still carries the path.
    #[inline]
    pub fn secondary_terminated(&self) -> bool {
        !self.is_rgb() && self.pdf[1..].iter().all(|&p| p == 0.0)
    }
}

/// The density (per nm) of [`sample_visible_wavelength`]: 0.0039398042 / cosh²(0.0072 (λ − 538))
/// on [360, 830] nm, 0 outside. It follows the shape of the CIE ȳ curve with heavier tails,
/// which lowers colour noise against uniform sampling (Radziszewski et al. 2009, as used in
/// pbrt-v4 and Mitsuba 3). `lambda` in nm.
pub fn visible_pdf(lambda: f64) -> f64 {
    if !(LAMBDA_MIN..=LAMBDA_MAX).contains(&lambda) {
        return 0.0;
    }
    // 1 / cosh²x = 4 e^{2x} / (e^{2x} + 1)²: one exponential (it runs four times per
    // camera sample).
    let e = (0.0144 * (lambda - 538.0)).exp();
    0.003_939_804_2 * 4.0 * e / ((e + 1.0) * (e + 1.0))
}

/// Inverts the cumulative distribution of [`visible_pdf`]: u in [0, 1) to a wavelength in nm,
/// λ = 538 − 138.888889 · atanh(0.85691062 − 1.82750197 u).
pub fn sample_visible_wavelength(u: f64) -> f64 {
    538.0 - VISIBLE_WIDTH * atanh(VISIBLE_X0 - VISIBLE_DX * u)
}

/// atanh x = ½ ln((1 + x)/(1 − x)) for the |x| < 0.975 of the visible map: one `ln`, half
/// the cost of the library's `atanh` (a `log1p`), within 4e-15 of it there (tested): 6e-13 nm
/// in λ.
#[inline]
fn atanh(x: f64) -> f64 {
    0.5 * ((1.0 + x) / (1.0 - x)).ln()
}

/// The constants of [`sample_visible_wavelength`] (pbrt-v4's).
const VISIBLE_WIDTH: f64 = 138.888_889;
const VISIBLE_X0: f64 = 0.856_910_62;
const VISIBLE_DX: f64 = 1.827_501_97;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn visible_samples_at_known_points() {
        for (u, l) in [(0.1, 424.343), (0.5, 545.903), (0.8, 635.381)] {
            let v = sample_visible_wavelength(u);
            assert!((v - l).abs() < 1e-3, "u {u}: {v}");
        }
    }

    /// Over the visible map's range of x (0.857 down to −0.971), within 4e-15 absolutely
    /// (measured 3.6e-15).
    #[test]
    fn atanh_by_one_log_matches_the_library() {
        let mut worst = 0.0f64;
        for k in 0..=100_000 {
            let u = k as f64 / 100_000.0;
            let x = VISIBLE_X0 - VISIBLE_DX * u;
            worst = worst.max((atanh(x) - x.atanh()).abs());
        }
        assert!(worst < 4e-15, "{worst:e}");
    }

    #[test]
    fn sampled_visible_wavelengths_carry_their_density() {
        // Each lane's pdf, worked out from the sample, is visible_pdf at its wavelength.
        for k in 0..1000 {
            let wl = SampledWavelengths::sample_visible(k as f64 / 1000.0);
            for i in 0..N_SAMPLES {
                let (l, p) = (wl.lambda()[i], wl.pdf()[i]);
                assert_eq!(
                    l,
                    sample_visible_wavelength((k as f64 / 1000.0 + i as f64 / 4.0) % 1.0)
                );
                assert!(
                    (p / visible_pdf(l) - 1.0).abs() < 1e-6,
                    "λ {l}: {p} vs {}",
                    visible_pdf(l)
                );
            }
        }
    }

    #[test]
    fn visible_pdf_integrates_to_one() {
        let n = 47_000;
        let h = (LAMBDA_MAX - LAMBDA_MIN) / n as f64;
        let sum: f64 = (0..n)
            .map(|i| visible_pdf(LAMBDA_MIN + (i as f64 + 0.5) * h) * h)
            .sum();
        assert!((sum - 1.0).abs() < 1e-4, "{sum}");
        assert_eq!(visible_pdf(359.0), 0.0);
        assert_eq!(visible_pdf(831.0), 0.0);
    }

    #[test]
    fn sample_visible_stratifies_lanes() {
        let wl = SampledWavelengths::sample_visible(0.8);
        let expect = [0.8, 0.05, 0.3, 0.55].map(sample_visible_wavelength);
        for (i, &e) in expect.iter().enumerate() {
            assert!((wl.lambda()[i] - e).abs() < 1e-9);
            assert!((wl.pdf()[i] / visible_pdf(e) - 1.0).abs() < 1e-6);
            assert!((LAMBDA_MIN..=LAMBDA_MAX).contains(&wl.lambda()[i]));
        }
        assert!(!wl.is_rgb());
    }

    #[test]
    fn the_visible_cdf_matches_the_pdf() {
        // d λ / d u = 1 / pdf(λ).
        for u in [0.05, 0.3, 0.6, 0.95] {
            let h = 1e-6;
            let dl =
                (sample_visible_wavelength(u + h) - sample_visible_wavelength(u - h)) / (2.0 * h);
            let p = visible_pdf(sample_visible_wavelength(u));
            assert!((dl * p - 1.0).abs() < 1e-4, "{u}: {}", dl * p);
        }
    }
}
