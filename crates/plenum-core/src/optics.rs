//! The laws of geometric optics at a smooth interface: reflection, Snell's law and the
//! Fresnel equations for dielectrics (Hecht, Optics, §4.6).
//!
//! Directions here follow the ray: `d` travels toward the surface, `n` is the unit normal on
//! the side the ray comes from (d·n < 0).

use crate::math::Vec3;

/// The law of reflection: the angle of reflection equals the angle of incidence.
pub fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - n * (2.0 * d.dot(n))
}

/// Snell's law η₁ sin θ₁ = η₂ sin θ₂ for a unit direction `d`, with `eta` = η₁/η₂.
/// `None` on total internal reflection.
pub fn refract(d: Vec3, n: Vec3, eta: f64) -> Option<Vec3> {
    let cos_i = -d.dot(n);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t > 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some(d * eta + n * (eta * cos_i - cos_t))
}

/// Reflectance of unpolarised light at a dielectric interface, the average of the s and p
/// Fresnel reflectances; 1 beyond the critical angle. `cos_i` is the cosine of the angle of
/// incidence, the ray going from index `eta_i` into `eta_t`.
pub fn fresnel_dielectric(cos_i: f64, eta_i: f64, eta_t: f64) -> f64 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin_t = eta_i / eta_t * (1.0 - cos_i * cos_i).sqrt();
    if sin_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let r_s = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
    let r_p = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
    0.5 * (r_s * r_s + r_p * r_p)
}

/// The angle of incidence, in radians, beyond which light going from `eta_i` into `eta_t`
/// is totally reflected; `None` when eta_i ≤ eta_t.
pub fn critical_angle(eta_i: f64, eta_t: f64) -> Option<f64> {
    (eta_i > eta_t).then(|| (eta_t / eta_i).asin())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reflection_mirrors_the_angle() {
        let d = Vec3::new(1.0, -1.0, 0.0).normalized();
        let r = reflect(d, Vec3::Y);
        assert!((r - Vec3::new(1.0, 1.0, 0.0).normalized()).length() < 1e-15);
    }

    #[test]
    fn refraction_obeys_snell() {
        let n = Vec3::Y;
        for deg in [0.0, 10.0, 30.0, 60.0, 89.0] {
            let theta_i = f64::to_radians(deg);
            let d = Vec3::new(theta_i.sin(), -theta_i.cos(), 0.0);
            let t = refract(d, n, 1.0 / 1.5).unwrap();
            assert!((t.length() - 1.0).abs() < 1e-12);
            let sin_t = t.x;
            assert!(
                (1.0 * theta_i.sin() - 1.5 * sin_t).abs() < 1e-12,
                "at {deg}°"
            );
            assert!(t.y < 0.0);
        }
    }

    #[test]
    fn critical_angle_of_glass_to_air_is_41_8_degrees() {
        let theta_c = critical_angle(1.5, 1.0).unwrap();
        assert!((theta_c.to_degrees() - 41.81).abs() < 0.01);
        assert!(critical_angle(1.0, 1.5).is_none());
        let n = Vec3::Y;
        let ray_at = |deg: f64| {
            let th = deg.to_radians();
            Vec3::new(th.sin(), -th.cos(), 0.0)
        };
        // Leaving glass just inside and just beyond the critical angle.
        let c = theta_c.to_degrees();
        assert!(refract(ray_at(c - 0.01), n, 1.5).is_some());
        assert!(refract(ray_at(c + 0.01), n, 1.5).is_none());
        assert_eq!(
            fresnel_dielectric((c + 0.01).to_radians().cos(), 1.5, 1.0),
            1.0
        );
    }

    #[test]
    fn fresnel_at_normal_and_grazing_incidence() {
        let eta: f64 = 1.5;
        let normal = ((eta - 1.0) / (eta + 1.0)).powi(2);
        assert!((fresnel_dielectric(1.0, 1.0, eta) - normal).abs() < 1e-15);
        assert!((fresnel_dielectric(1.0, eta, 1.0) - normal).abs() < 1e-15);
        assert!(fresnel_dielectric(1e-6, 1.0, eta) > 0.999);
        // Brewster's angle: p-polarised reflectance vanishes, leaving half of R_s.
        let brewster = eta.atan();
        let cos_t = (1.0 - (brewster.sin() / eta).powi(2)).sqrt();
        let cos_i = brewster.cos();
        let r_s = ((cos_i - eta * cos_t) / (cos_i + eta * cos_t)).powi(2);
        assert!((fresnel_dielectric(cos_i, 1.0, eta) - 0.5 * r_s).abs() < 1e-12);
    }
}
