//! Colour spaces: CIE XYZ and linear sRGB (ITU-R BT.709 primaries, D65 white, IEC 61966-2-1),
//! the conversion of sampled spectra to them (the Monte-Carlo estimate of the CIE integrals,
//! as pbrt-v4's `SampledSpectrum::ToXYZ`), and CIELAB for the RGB uplift's fit.

use crate::cie::{table_position, CIE_X, CIE_Y, CIE_Y_INTEGRAL, CIE_Z};
use crate::sampled::{SampledSpectrum, SampledWavelengths, N_SAMPLES};

/// Linear sRGB to XYZ (Y = 1 for white), from the BT.709 primaries and D65's chromaticity
/// (0.3127, 0.3290); the values of IEC 61966-2-1 to 7 digits (as tabulated by B. Lindbloom).
pub const SRGB_TO_XYZ: [[f64; 3]; 3] = [
    [0.4124564, 0.3575761, 0.1804375],
    [0.2126729, 0.7151522, 0.0721750],
    [0.0193339, 0.1191920, 0.9503041],
];

/// XYZ to linear sRGB, the inverse of [`SRGB_TO_XYZ`].
pub const XYZ_TO_SRGB: [[f64; 3]; 3] = [
    [3.2404542, -1.5371385, -0.4985314],
    [-0.9692660, 1.8760108, 0.0415560],
    [0.0556434, -0.2040259, 1.0572252],
];

/// XYZ of the sRGB white, D65 with Y = 1.
pub const D65_WHITE_XYZ: [f64; 3] = [0.95047, 1.0, 1.08883];

/// `m` · `v`.
#[inline]
pub fn mul3(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

/// CIE XYZ to linear sRGB.
#[inline]
pub fn xyz_to_linear_srgb(xyz: [f64; 3]) -> [f64; 3] {
    mul3(&XYZ_TO_SRGB, xyz)
}

/// Linear sRGB to CIE XYZ.
#[inline]
pub fn linear_srgb_to_xyz(rgb: [f64; 3]) -> [f64; 3] {
    mul3(&SRGB_TO_XYZ, rgb)
}

/// CIE 1976 L*a*b* of an XYZ colour relative to the white `white` (XYZ), defined for any
/// real input (the cube root's linear segment below (6/29)³ extends to negatives).
pub fn xyz_to_lab(xyz: [f64; 3], white: [f64; 3]) -> [f64; 3] {
    let f = |t: f64| {
        const D: f64 = 6.0 / 29.0;
        if t > D * D * D {
            t.cbrt()
        } else {
            t / (3.0 * D * D) + 4.0 / 29.0
        }
    };
    let (fx, fy, fz) = (
        f(xyz[0] / white[0]),
        f(xyz[1] / white[1]),
        f(xyz[2] / white[2]),
    );
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

impl SampledSpectrum {
    /// CIE XYZ of the radiance these samples estimate: the mean over lanes of
    /// x̄ȳz̄(λ_i) · L_i / pdf_i (lanes with pdf 0 give 0), divided by [`CIE_Y_INTEGRAL`], so a
    /// spectrum of constant 1 has Y = 1 in expectation. Spectral mode only; in RGB mode this
    /// converts the lanes' linear sRGB to XYZ.
    pub fn to_xyz(&self, wl: &SampledWavelengths) -> [f64; 3] {
        if wl.is_rgb() {
            return linear_srgb_to_xyz([self.0[0], self.0[1], self.0[2]]);
        }
        let pdf = wl.pdf();
        let mut xyz = [0.0; 3];
        for i in 0..N_SAMPLES {
            if pdf[i] == 0.0 {
                continue;
            }
            if let Some((j, t)) = table_position(wl.lambda()[i]) {
                let w = self.0[i] / pdf[i];
                let lerp = |tab: &[f64]| tab[j] + t * (tab[j + 1] - tab[j]);
                xyz[0] += w * lerp(&CIE_X);
                xyz[1] += w * lerp(&CIE_Y);
                xyz[2] += w * lerp(&CIE_Z);
            }
        }
        let k = 1.0 / (N_SAMPLES as f64 * CIE_Y_INTEGRAL);
        [xyz[0] * k, xyz[1] * k, xyz[2] * k]
    }

    /// Linear sRGB of the radiance these samples estimate ([`Self::to_xyz`] then
    /// [`XYZ_TO_SRGB`]); in RGB mode lanes 0..3 as they are. One table look-up per lane and a
    /// 3×3 product: what the film does once per camera sample.
    #[inline]
    pub fn to_linear_srgb(&self, wl: &SampledWavelengths) -> [f64; 3] {
        if wl.is_rgb() {
            return [self.0[0], self.0[1], self.0[2]];
        }
        xyz_to_linear_srgb(self.to_xyz(wl))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matrices_are_inverse_and_map_white_to_d65() {
        for i in 0..3 {
            let mut e = [0.0; 3];
            e[i] = 1.0;
            let back = xyz_to_linear_srgb(linear_srgb_to_xyz(e));
            for j in 0..3 {
                assert!((back[j] - e[j]).abs() < 1e-6);
            }
        }
        let w = linear_srgb_to_xyz([1.0; 3]);
        for j in 0..3 {
            assert!((w[j] - D65_WHITE_XYZ[j]).abs() < 1e-4, "{w:?}");
        }
    }

    #[test]
    fn rgb_mode_passes_lanes_through() {
        let s = SampledSpectrum([0.25, 0.5, 2.0, 0.0]);
        assert_eq!(
            s.to_linear_srgb(&SampledWavelengths::rgb()),
            [0.25, 0.5, 2.0]
        );
    }

    #[test]
    fn constant_one_has_unit_luminance_in_expectation() {
        // Many stratified visible samples of an equal-energy spectrum: Y → 1.
        let n = 4000;
        let mut y = 0.0;
        for k in 0..n {
            let wl = SampledWavelengths::sample_visible((k as f64 + 0.5) / n as f64);
            y += SampledSpectrum::ONE.to_xyz(&wl)[1];
        }
        assert!((y / n as f64 - 1.0).abs() < 2e-3, "{}", y / n as f64);
    }

    #[test]
    fn zero_pdf_lanes_contribute_nothing() {
        let mut wl = SampledWavelengths::sample_visible(0.3);
        wl.terminate_secondary();
        let a = SampledSpectrum([1.0, 5.0, 7.0, 9.0]).to_xyz(&wl);
        let b = SampledSpectrum([1.0, 0.0, 0.0, 0.0]).to_xyz(&wl);
        assert_eq!(a, b);
    }

    #[test]
    fn lab_of_white_is_100_0_0() {
        let lab = xyz_to_lab(D65_WHITE_XYZ, D65_WHITE_XYZ);
        assert!((lab[0] - 100.0).abs() < 1e-9 && lab[1].abs() < 1e-9 && lab[2].abs() < 1e-9);
    }
}
