//! Fresnel reflectance of unpolarised light, the mean of the s- and p-polarised
//! reflectances (Hecht, *Optics*, §4.6; pbrt-v4 §9.3): at a dielectric interface with a
//! real relative index, and at a conductor with a complex one, η + ik, per spectral lane.

use plenum_spectrum::{SampledSpectrum, N_SAMPLES};

/// Reflectance at a dielectric interface for incidence cos θi = `cos_i` on the outside
/// (cos_i > 0) or the inside (cos_i < 0, where the interface is seen with 1/η). `eta` is
/// the relative index, inside over outside. 1 under total internal reflection.
pub fn fr_dielectric(cos_i: f64, eta: f64) -> f64 {
    let mut cos_i = cos_i.clamp(-1.0, 1.0);
    let mut eta = eta;
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    let sin2_i = 1.0 - cos_i * cos_i;
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r_parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular)
}

/// A complex number, just the arithmetic the conductor's Fresnel equations need.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Complex {
    re: f64,
    im: f64,
}

impl Complex {
    fn new(re: f64, im: f64) -> Complex {
        Complex { re, im }
    }

    fn real(re: f64) -> Complex {
        Complex { re, im: 0.0 }
    }

    fn add(self, o: Complex) -> Complex {
        Complex::new(self.re + o.re, self.im + o.im)
    }

    fn sub(self, o: Complex) -> Complex {
        Complex::new(self.re - o.re, self.im - o.im)
    }

    fn mul(self, o: Complex) -> Complex {
        Complex::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }

    fn div(self, o: Complex) -> Complex {
        let scale = 1.0 / (o.re * o.re + o.im * o.im);
        Complex::new(
            (self.re * o.re + self.im * o.im) * scale,
            (self.im * o.re - self.re * o.im) * scale,
        )
    }

    /// |z|².
    fn norm(self) -> f64 {
        self.re * self.re + self.im * self.im
    }

    /// The principal square root, written to avoid cancellation: with r = |z|, the root
    /// has real part √((r + |re|)/2) and imaginary part im/(2·that), swapped for re < 0.
    fn sqrt(self) -> Complex {
        let r = self.norm().sqrt();
        if r == 0.0 {
            return Complex::real(0.0);
        }
        let t = (0.5 * (r + self.re.abs())).sqrt();
        if self.re >= 0.0 {
            Complex::new(t, 0.5 * self.im / t)
        } else {
            Complex::new(0.5 * self.im.abs() / t, t.copysign(self.im))
        }
    }
}

/// Reflectance of one lane at a conductor of complex relative index η + ik.
fn fr_complex_lane(cos_i: f64, eta: f64, k: f64) -> f64 {
    // An index of exactly 0 is no material: the unused fourth lane in RGB mode. It
    // reflects nothing (the formula would divide 0 by 0).
    if eta == 0.0 && k == 0.0 {
        return 0.0;
    }
    let cos_i = cos_i.clamp(0.0, 1.0);
    let eta = Complex::new(eta, k);
    let sin2_i = Complex::real(1.0 - cos_i * cos_i);
    let sin2_t = sin2_i.div(eta.mul(eta));
    let cos_t = Complex::real(1.0).sub(sin2_t).sqrt();
    let ci = Complex::real(cos_i);
    let r_parallel = eta.mul(ci).sub(cos_t).div(eta.mul(ci).add(cos_t));
    let r_perpendicular = ci.sub(eta.mul(cos_t)).div(ci.add(eta.mul(cos_t)));
    0.5 * (r_parallel.norm() + r_perpendicular.norm())
}

/// Reflectance at a conductor of complex index η + ik (relative to the outside), per lane,
/// for light arriving at cos θi = `cos_i` ≥ 0.
pub fn fr_complex(cos_i: f64, eta: SampledSpectrum, k: SampledSpectrum) -> SampledSpectrum {
    let mut r = SampledSpectrum::ZERO;
    for i in 0..N_SAMPLES {
        r[i] = fr_complex_lane(cos_i, eta[i], k[i]);
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    /// In RGB mode a conductor's fourth lane has η = k = 0: finite, and nothing reflected.
    #[test]
    fn the_unused_rgb_lane_stays_finite() {
        let eta = SampledSpectrum([0.16, 0.14, 0.13, 0.0]);
        let k = SampledSpectrum([3.9, 3.0, 2.4, 0.0]);
        let r = fr_complex(0.7, eta, k);
        assert!(r.is_finite(), "{r:?}");
        assert_eq!(r[3], 0.0);
    }

    #[test]
    fn dielectric_at_80_degrees() {
        // η = 1.5 at 80°: the closed form gives 0.387704354691473; to 1e-12.
        let f = fr_dielectric(80f64.to_radians().cos(), 1.5);
        assert!((f - 0.387704354691473).abs() < 1e-12, "{f}");
    }

    #[test]
    fn dielectric_normal_incidence_and_inside() {
        // ((η−1)/(η+1))² from either side, to 1e-15; from inside beyond the critical
        // angle, 1 exactly.
        let normal = (0.5f64 / 2.5).powi(2);
        assert!((fr_dielectric(1.0, 1.5) - normal).abs() < 1e-15);
        assert!((fr_dielectric(-1.0, 1.5) - normal).abs() < 1e-15);
        assert_eq!(fr_dielectric(-(50f64.to_radians().cos()), 1.5), 1.0);
        // Seen from inside, the interface with η is the interface with 1/η from outside.
        for deg in [0.0, 20.0, 40.0] {
            let c = f64::to_radians(deg).cos();
            assert!((fr_dielectric(-c, 1.5) - fr_dielectric(c, 1.0 / 1.5)).abs() < 1e-15);
        }
    }

    #[test]
    fn conductor_at_normal_incidence() {
        // ((n−1)² + k²)/((n+1)² + k²), to 1e-14.
        for (n, k) in [(2.0, 4.0), (0.2, 3.0), (1.5, 0.0), (0.05, 10.0)] {
            let f = fr_complex(1.0, SampledSpectrum::splat(n), SampledSpectrum::splat(k));
            let expected = ((n - 1.0) * (n - 1.0) + k * k) / ((n + 1.0) * (n + 1.0) + k * k);
            assert!((f[0] - expected).abs() < 1e-14, "({n}, {k}): {}", f[0]);
        }
    }

    #[test]
    fn conductor_with_no_absorption_is_a_dielectric() {
        // k = 0 gives the dielectric formula, to 1e-13, and 1 at grazing incidence.
        for deg in [0.0, 30.0, 60.0, 85.0] {
            let c = f64::to_radians(deg).cos();
            let f = fr_complex(c, SampledSpectrum::splat(1.5), SampledSpectrum::ZERO);
            assert!((f[0] - fr_dielectric(c, 1.5)).abs() < 1e-13, "{deg}°");
        }
        let f = fr_complex(
            0.0,
            SampledSpectrum::splat(2.0),
            SampledSpectrum::splat(4.0),
        );
        assert!((f[0] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn complex_sqrt_squares_back() {
        for (re, im) in [
            (3.0, 4.0),
            (-3.0, 4.0),
            (-3.0, -4.0),
            (1e-9, -2.0),
            (-5.0, 0.0),
        ] {
            let z = Complex::new(re, im);
            let s = z.sqrt();
            let back = s.mul(s);
            assert!(s.re >= 0.0);
            assert!(
                (back.re - re).abs() < 1e-12 && (back.im - im).abs() < 1e-12,
                "{z:?}"
            );
        }
    }
}
