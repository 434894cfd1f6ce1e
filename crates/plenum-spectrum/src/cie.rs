//! The CIE 1931 2° standard colorimetric observer: colour-matching functions x̄, ȳ, z̄ at 1 nm
//! from 360 to 830 nm (CIE 015:2018), linearly interpolated between samples.

pub use crate::data::cie::{CIE_X, CIE_Y, CIE_Z};

/// First wavelength of the tables, nm.
pub const CIE_LAMBDA_MIN: f64 = 360.0;
/// Last wavelength of the tables, nm.
pub const CIE_LAMBDA_MAX: f64 = 830.0;
/// Samples in each table (1 nm apart).
pub const CIE_SAMPLES: usize = 471;

/// ∫ ȳ(λ) dλ in nm, the sum of the 1 nm samples (pbrt-v4's `CIE_Y_integral`). Dividing an
/// integral against the matching functions by it gives the luminance Y of an equal-energy
/// spectrum of value 1 as 1.
pub const CIE_Y_INTEGRAL: f64 = 106.856895;

/// Where `lambda` (nm) falls between table samples: the lower index and the fraction to the
/// next; `None` outside [360, 830] nm.
#[inline]
pub(crate) fn table_position(lambda: f64) -> Option<(usize, f64)> {
    if !(CIE_LAMBDA_MIN..=CIE_LAMBDA_MAX).contains(&lambda) {
        return None;
    }
    let x = lambda - CIE_LAMBDA_MIN;
    let i = (x as usize).min(CIE_SAMPLES - 2);
    Some((i, x - i as f64))
}

/// The colour-matching functions [x̄, ȳ, z̄] at `lambda` in nm (dimensionless), linearly
/// interpolated, 0 outside [360, 830] nm.
#[inline]
pub fn cie_xyz(lambda: f64) -> [f64; 3] {
    match table_position(lambda) {
        None => [0.0; 3],
        Some((i, t)) => {
            let lerp = |tab: &[f64; CIE_SAMPLES]| tab[i] + t * (tab[i + 1] - tab[i]);
            [lerp(&CIE_X), lerp(&CIE_Y), lerp(&CIE_Z)]
        }
    }
}

/// ȳ(λ) alone, `lambda` in nm (the luminous efficiency curve), 0 outside the table.
pub fn cie_y(lambda: f64) -> f64 {
    cie_xyz(lambda)[1]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn y_samples_sum_to_the_integral() {
        let sum: f64 = CIE_Y.iter().sum();
        assert!(
            (sum - CIE_Y_INTEGRAL).abs() / CIE_Y_INTEGRAL < 1e-5,
            "{sum}"
        );
    }

    #[test]
    fn interpolates_and_is_zero_outside() {
        assert_eq!(cie_xyz(359.9), [0.0; 3]);
        assert_eq!(cie_xyz(830.1), [0.0; 3]);
        assert_eq!(cie_xyz(555.0)[1], CIE_Y[195]);
        let mid = cie_xyz(555.5)[1];
        assert!((mid - 0.5 * (CIE_Y[195] + CIE_Y[196])).abs() < 1e-12);
        assert_eq!(cie_xyz(830.0)[0], CIE_X[470]);
    }
}
