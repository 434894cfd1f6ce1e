//! Point lights whose intensity varies with direction: a goniometric diagram, as lamp makers
//! measure it, or an image projected as by a slide projector (pbrt-v4's `goniometric` and
//! `projection` lights, §12.2.2–12.2.3). Both look their image up at the nearest texel, as
//! pbrt-v4 does.

use crate::color::Color;
use crate::math::Vec3;
use crate::sampling::{equal_area_sphere_to_square, uniform_sphere, Frame};
use std::f64::consts::PI;

/// How a point light's intensity varies over the directions of its own frame.
#[derive(Clone, Debug)]
pub struct Profile {
    /// The light's frame in the world (orthonormal; for the projection, left-handed).
    frame: Frame,
    kind: ProfileKind,
    /// The factor's mean luminance over the sphere, (1/4π) ∫ Y(f(ω)) dω.
    mean_luminance: f64,
}

#[derive(Clone, Debug)]
enum ProfileKind {
    /// Grey factors over the sphere in Clarberg's equal-area square, `size` texels a side,
    /// row-major from the top-left.
    Goniometric { size: usize, texels: Vec<f64> },
    /// An RGB image on the plane z = 1 of the frame, filling the screen [−w, w] × [−h, h]
    /// (in units of tan(fov/2)): the longer side spans [−aspect, aspect], the shorter [−1, 1].
    Projection {
        width: usize,
        height: usize,
        texels: Vec<Color>,
        screen: [f64; 2],
        tan_half_fov: f64,
    },
}

/// pbrt-v4's near plane for the projection: nothing is sent at angles of 90° or more.
const HITHER: f64 = 1e-3;

impl Profile {
    /// A goniometric diagram: `texels` (grey, row-major from the top-left) of a square image
    /// in the equal-area layout, over the directions of the frame `frame`.
    pub fn goniometric(size: usize, texels: Vec<f64>, frame: Frame) -> Result<Profile, String> {
        if size == 0 || texels.len() != size * size {
            return Err(format!(
                "a goniometric diagram must be a square image, got {} texels for a side of {size}",
                texels.len()
            ));
        }
        if texels.iter().any(|t| !(t.is_finite() && *t >= 0.0)) {
            return Err("a goniometric diagram's values must be finite and ≥ 0".into());
        }
        // Equal-area texels: each covers the same solid angle.
        let mean = texels.iter().sum::<f64>() / texels.len() as f64;
        Ok(Profile {
            frame,
            kind: ProfileKind::Goniometric { size, texels },
            mean_luminance: mean,
        })
    }

    /// An image (`width` × `height` RGB texels, row-major from the top-left) projected along
    /// the frame's +z through a field of view of `fov` degrees across its shorter side, its
    /// top row toward −y.
    pub fn projection(
        width: usize,
        height: usize,
        texels: Vec<Color>,
        fov: f64,
        frame: Frame,
    ) -> Result<Profile, String> {
        if width == 0 || height == 0 || texels.len() != width * height {
            return Err(format!(
                "a projected image of {width} × {height} texels needs that many, got {}",
                texels.len()
            ));
        }
        if !(fov > 0.0 && fov < 180.0) {
            return Err(format!(
                "a projection's fov must be in (0°, 180°), got {fov}"
            ));
        }
        if texels.iter().any(|c| {
            [c.r, c.g, c.b]
                .iter()
                .any(|v| !(v.is_finite() && *v >= 0.0))
        }) {
            return Err("a projected image's values must be finite and ≥ 0".into());
        }
        let aspect = width as f64 / height as f64;
        let screen = if aspect > 1.0 {
            [aspect, 1.0]
        } else {
            [1.0, 1.0 / aspect]
        };
        let tan_half_fov = (fov.to_radians() / 2.0).tan();
        let kind = ProfileKind::Projection {
            width,
            height,
            texels,
            screen,
            tan_half_fov,
        };
        let mut profile = Profile {
            frame,
            kind,
            mean_luminance: 0.0,
        };
        profile.mean_luminance = profile.screen_integral() / (4.0 * PI);
        Ok(profile)
    }

    /// ∫ Y(f(ω)) dω over the projected image, by its texels: each texel centre's luminance
    /// times the solid angle it subtends, cos³θ dA (pbrt-v4's sum for `power`).
    pub fn screen_integral(&self) -> f64 {
        match &self.kind {
            ProfileKind::Goniometric { .. } => 4.0 * PI * self.mean_luminance,
            ProfileKind::Projection {
                width,
                height,
                texels,
                screen,
                tan_half_fov,
            } => {
                let t = *tan_half_fov;
                let texel_area =
                    (2.0 * screen[0] * t / *width as f64) * (2.0 * screen[1] * t / *height as f64);
                let mut sum = 0.0;
                for y in 0..*height {
                    for x in 0..*width {
                        let sx = (-1.0 + 2.0 * (x as f64 + 0.5) / *width as f64) * screen[0];
                        let sy = (-1.0 + 2.0 * (y as f64 + 0.5) / *height as f64) * screen[1];
                        let d = Vec3::new(sx * t, sy * t, 1.0);
                        let cos = 1.0 / d.length();
                        sum += texels[y * width + x].luminance() * cos.powi(3) * texel_area;
                    }
                }
                sum
            }
        }
    }

    /// The factor's mean luminance over the sphere.
    pub fn mean_luminance(&self) -> f64 {
        self.mean_luminance
    }

    /// Whether the factor is grey (a goniometric diagram), so that it scales the light's own
    /// spectrum rather than replacing it by an RGB colour.
    pub fn is_grey(&self) -> bool {
        matches!(self.kind, ProfileKind::Goniometric { .. })
    }

    /// The factor on the light's intensity toward the world direction `w` (unit length).
    pub fn factor(&self, w: Vec3) -> Color {
        let local = self.frame.to_local(w);
        match &self.kind {
            ProfileKind::Goniometric { size, texels } => {
                let [u, v] = equal_area_sphere_to_square(local);
                let texel = |s: f64| ((s * *size as f64) as usize).min(size - 1);
                Color::gray(texels[texel(v) * size + texel(u)])
            }
            ProfileKind::Projection {
                width,
                height,
                texels,
                screen,
                tan_half_fov,
            } => {
                if local.z < HITHER {
                    return Color::BLACK;
                }
                let sx = local.x / (local.z * tan_half_fov);
                let sy = local.y / (local.z * tan_half_fov);
                if sx.abs() > screen[0] || sy.abs() > screen[1] {
                    return Color::BLACK;
                }
                let u = (sx + screen[0]) / (2.0 * screen[0]);
                let v = (sy + screen[1]) / (2.0 * screen[1]);
                let x = ((u * *width as f64) as usize).min(width - 1);
                let y = ((v * *height as f64) as usize).min(height - 1);
                texels[y * width + x]
            }
        }
    }

    /// A direction for light leaving the light, from `u` ∈ [0, 1)², and its density per
    /// steradian: uniform over the sphere for a diagram, uniform over the screen for the
    /// projection (so nothing is sent where it sends nothing).
    pub fn sample(&self, u: [f64; 2]) -> (Vec3, f64) {
        match &self.kind {
            ProfileKind::Goniometric { .. } => (uniform_sphere(u), 1.0 / (4.0 * PI)),
            ProfileKind::Projection {
                screen,
                tan_half_fov,
                ..
            } => {
                let sx = (2.0 * u[0] - 1.0) * screen[0];
                let sy = (2.0 * u[1] - 1.0) * screen[1];
                let local = Vec3::new(sx * tan_half_fov, sy * tan_half_fov, 1.0);
                let d = local.normalized();
                (self.frame.to_world(d), self.pdf_local(d))
            }
        }
    }

    /// The density per steradian with which [`Profile::sample`] picks world direction `w`.
    pub fn pdf(&self, w: Vec3) -> f64 {
        self.pdf_local(self.frame.to_local(w))
    }

    fn pdf_local(&self, local: Vec3) -> f64 {
        match &self.kind {
            ProfileKind::Goniometric { .. } => 1.0 / (4.0 * PI),
            ProfileKind::Projection {
                screen,
                tan_half_fov,
                ..
            } => {
                if local.z < HITHER {
                    return 0.0;
                }
                let t = *tan_half_fov;
                let (sx, sy) = (local.x / (local.z * t), local.y / (local.z * t));
                if sx.abs() > screen[0] || sy.abs() > screen[1] {
                    return 0.0;
                }
                // Uniform over the plane z = 1 (area 4·w·h·tan²), and dω = cos³θ dA there.
                let cos = local.z / local.length();
                1.0 / (4.0 * screen[0] * screen[1] * t * t * cos.powi(3))
            }
        }
    }
}

/// Equal when it is the same profile (as environment maps are compared).
impl PartialEq for Profile {
    fn eq(&self, o: &Self) -> bool {
        std::ptr::eq(self, o)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    fn projector() -> Profile {
        // 4 × 2 texels of distinct colours, 60° across the shorter side, along world −y.
        let texels = (0..8).map(|i| Color::new(i as f64, 1.0, 0.5)).collect();
        let frame = Frame {
            x: Vec3::X,
            y: Vec3::Z,
            z: -Vec3::Y,
        };
        Profile::projection(4, 2, texels, 60.0, frame).unwrap()
    }

    /// Sampled directions have the density `pdf` gives (its integral over the sphere, by
    /// importance sampling, is 1), and the factor's integral matches the texel sum.
    #[test]
    fn projection_samples_match_their_density_and_cover_the_screen() {
        let p = projector();
        let mut rng = Rng::new(7, 1);
        let n = 200_000;
        let (mut ones, mut integral) = (0.0, 0.0);
        for _ in 0..n {
            let (w, pdf) = p.sample([rng.uniform(), rng.uniform()]);
            assert!(
                (pdf - p.pdf(w)).abs() <= 1e-9 * pdf,
                "{pdf} against {}",
                p.pdf(w)
            );
            assert!(p.factor(w).g > 0.0, "a sample off the screen: {w:?}");
            ones += 1.0;
            integral += p.factor(w).luminance() / pdf;
        }
        assert_eq!(ones, n as f64);
        // Uniform sphere directions: the pdf integrates to 1 over the sphere.
        let mut total = 0.0;
        for _ in 0..n {
            let w = uniform_sphere([rng.uniform(), rng.uniform()]);
            total += p.pdf(w) * 4.0 * PI;
        }
        let total = total / n as f64;
        assert!((total - 1.0).abs() < 0.02, "∫ pdf dω = {total}");
        // ∫ Y(f) dω by the midpoint rule on a fine grid of the screen (pbrt-v4's one point
        // per texel, `screen_integral`, is 3 % off at this size).
        let t = (30f64).to_radians().tan();
        let (cells_x, cells_y) = (256, 128);
        let area = (4.0 * t / cells_x as f64) * (2.0 * t / cells_y as f64);
        let mut exact = 0.0;
        for j in 0..cells_y {
            for i in 0..cells_x {
                let x = (-2.0 + 4.0 * (i as f64 + 0.5) / cells_x as f64) * t;
                let y = (-1.0 + 2.0 * (j as f64 + 0.5) / cells_y as f64) * t;
                let d = Vec3::new(x, y, 1.0);
                let cos = 1.0 / d.length();
                let w = p.frame.to_world(d.normalized());
                exact += p.factor(w).luminance() * cos.powi(3) * area;
            }
        }
        let integral = integral / n as f64;
        assert!(
            (integral / exact - 1.0).abs() < 0.01,
            "{integral} against {exact}"
        );
        let sum = p.screen_integral();
        assert!((sum / exact - 1.0).abs() < 0.05, "{sum} against {exact}");
    }

    /// The projection's texels land where pbrt-v4 puts them: the first column at −x, the
    /// top row toward the frame's −y, nothing behind or outside the screen.
    #[test]
    fn projection_texels_lie_where_pbrt_puts_them() {
        let p = projector();
        let t = (30f64).to_radians().tan();
        // The screen is [−2, 2] × [−1, 1] in units of tan 30°: texel (x, y) centres at
        // sx = −1.5 + x, sy = −0.5 + y; frame x = world x, frame y = world z.
        for (x, y) in [(0, 0), (3, 0), (1, 1), (2, 1)] {
            let sx = -1.5 + x as f64;
            let sy = -0.5 + y as f64;
            let w = Vec3::new(sx * t, -1.0, sy * t).normalized();
            assert_eq!(p.factor(w).r, (y * 4 + x) as f64, "texel ({x}, {y})");
        }
        assert!(p.factor(Vec3::Y).is_black());
        assert!(p
            .factor(Vec3::new(3.0 * t, -1.0, 0.0).normalized())
            .is_black());
    }

    /// A goniometric diagram's texel is the one its direction falls in on the equal-area
    /// square; the mean is the texels' mean.
    #[test]
    fn goniometric_texels_by_direction() {
        let texels: Vec<f64> = (0..16).map(|i| i as f64).collect();
        let g = Profile::goniometric(4, texels, Frame::from_z(Vec3::Z)).unwrap();
        assert!((g.mean_luminance() - 7.5).abs() < 1e-12);
        let mut rng = Rng::new(3, 1);
        for _ in 0..1000 {
            let w = uniform_sphere([rng.uniform(), rng.uniform()]);
            let [u, v] = equal_area_sphere_to_square(w);
            let want = ((v * 4.0) as usize).min(3) * 4 + ((u * 4.0) as usize).min(3);
            assert_eq!(g.factor(w).r, want as f64);
        }
        assert!(Profile::goniometric(3, vec![1.0; 8], Frame::from_z(Vec3::Z)).is_err());
    }
}
