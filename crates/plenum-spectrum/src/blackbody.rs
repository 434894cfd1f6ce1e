//! Blackbody emission: Planck's law, and the blackbody spectrum normalised to 1 at its peak
//! (Wien's displacement law), as pbrt-v4's `BlackbodySpectrum`.

/// Speed of light in vacuum, m/s (exact, SI).
pub const SPEED_OF_LIGHT: f64 = 299_792_458.0;
/// Planck constant, J·s (exact, SI 2019).
pub const PLANCK: f64 = 6.626_070_15e-34;
/// Boltzmann constant, J/K (exact, SI 2019).
pub const BOLTZMANN: f64 = 1.380_649e-23;
/// Wien's displacement constant b, m·K (CODATA 2018): λ_max = b / T.
pub const WIEN: f64 = 2.897_771_955e-3;

/// Spectral radiance of a blackbody, B(λ, T) = 2hc² / (λ⁵ (e^{hc/(λ k T)} − 1)), in
/// W·m⁻³·sr⁻¹ (per metre of wavelength), for `lambda_nm` in nm and `kelvin` in K; 0 for
/// T ≤ 0 or λ ≤ 0.
pub fn planck(lambda_nm: f64, kelvin: f64) -> f64 {
    if kelvin <= 0.0 || lambda_nm <= 0.0 {
        return 0.0;
    }
    let l = lambda_nm * 1e-9;
    let c = SPEED_OF_LIGHT;
    2.0 * PLANCK * c * c / (l.powi(5) * ((PLANCK * c / (l * BOLTZMANN * kelvin)).exp_m1()))
}

/// The wavelength of a blackbody's peak radiance, nm (Wien's law).
pub fn wien_peak_nm(kelvin: f64) -> f64 {
    WIEN / kelvin * 1e9
}

/// B(λ, T) / B(λ_max, T): dimensionless, 1 at the peak (pbrt-v4's `BlackbodySpectrum`).
pub fn normalized_blackbody(lambda_nm: f64, kelvin: f64) -> f64 {
    if kelvin <= 0.0 {
        return 0.0;
    }
    planck(lambda_nm, kelvin) / planck(wien_peak_nm(kelvin), kelvin)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planck_at_483nm_6000k() {
        let b = planck(483.0, 6000.0);
        assert!((b / 3.1849e13 - 1.0).abs() < 1e-3, "{b:e}");
    }

    #[test]
    fn normalized_peaks_at_one() {
        for t in [1000.0, 2856.0, 6500.0, 12000.0] {
            let p = wien_peak_nm(t);
            assert!((normalized_blackbody(p, t) - 1.0).abs() < 1e-12);
            assert!(normalized_blackbody(p * 1.01, t) < 1.0);
            assert!(normalized_blackbody(p * 0.99, t) < 1.0);
        }
        assert_eq!(planck(500.0, 0.0), 0.0);
    }
}
