//! Environment maps: the radiance an infinite light sends from every direction, stored as an
//! image of linear RGB, looked up with bilinear filtering and importance-sampled in
//! proportion to its luminance.
//!
//! Sampling follows pbrt-v4 §12.5.2 (image infinite lights): a [`PiecewiseConstant2D`]
//! over the image's parameter square picks a point, which the layout's map turns into a
//! direction, and the density per unit area of the square becomes one per steradian by the
//! map's Jacobian. Two layouts:
//!
//! - [`EnvironmentLayout::LatLong`], the equirectangular map. In the map's own frame (z up),
//!   texel column i covers φ ∈ [2πi/W, 2π(i+1)/W], φ measured from +x towards +y, and row j
//!   (from the top) covers θ ∈ [πj/H, π(j+1)/H], θ measured from +z: the top row circles
//!   +z, the bottom row −z. Image coordinates (s, t) = (φ/2π, θ/π); dω = 2π² sin θ ds dt.
//! - [`EnvironmentLayout::LatLongPoles`], the same map as Mitsuba 3's `envmap` reads it:
//!   columns as above, but the rows' centres run from the pole to the pole, row 0 at θ = 0
//!   and row H − 1 at θ = π (row j at θ = πj/(H − 1)). The two layouts differ by up to half a
//!   texel in θ; a scene made for Mitsuba renders as Mitsuba renders it only in this one.
//! - [`EnvironmentLayout::EqualArea`], the octahedral equal-area square of Clarberg 2008
//!   ("Fast Equal-Area Mapping of the (Hemi)Sphere using SIMD"), pbrt-v4's own layout for
//!   image infinite lights: (s, t) along the width and down the height go through
//!   [`equal_area_square_to_sphere`], and dω = 4π ds dt. The image must be square.
//!
//! The map's frame is given by the caller: `frame.to_world` carries a direction of the map's
//! frame into the world, so the map's +z (the lat-long map's top row, the equal-area
//! square's centre) lies along `frame.z` in the world.
//!
//! **Filtering and sampling.** Radiance is interpolated bilinearly between texel centres,
//! so it is not constant over a texel, and a density built from the texels alone would be
//! zero where the filter spreads a bright texel into a black neighbour, which biases the
//! estimate. The density's cell for each texel is instead the exact average of the filtered
//! luminance over that texel (weights 1/8, 3/4, 1/8 of the neighbours along each axis, the
//! integral of the tent filter over the cell), times the texel's solid angle for the
//! lat-long layout. That average is positive wherever the filtered radiance is, so every
//! direction that carries radiance can be sampled; the density is close to, not exactly,
//! proportional to the radiance, and it is exact as a density: [`EnvironmentMap::pdf`] is
//! the density [`EnvironmentMap::sample`] draws from.

use std::f64::consts::{FRAC_1_PI, PI, TAU};

use crate::math::Vec3;
use crate::sampling::{
    equal_area_sphere_to_square, equal_area_square_to_sphere, wrap_equal_area_texel, Frame,
    PiecewiseConstant2D,
};

/// How an environment image's pixels map to directions; see the module docs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvironmentLayout {
    /// Equirectangular: (s, t) = (φ/2π, θ/π), θ from the map's +z.
    LatLong,
    /// Equirectangular with the first and last rows' centres on the poles (Mitsuba 3).
    LatLongPoles,
    /// Clarberg's octahedral equal-area square; width and height must be equal.
    EqualArea,
}

/// An infinite light's radiance as an image in linear RGB, with a sampling distribution.
#[derive(Clone, Debug)]
pub struct EnvironmentMap {
    width: usize,
    height: usize,
    /// Row-major from the top-left; negative values stored as 0, `scale` not applied.
    texels: Vec<[f32; 3]>,
    layout: EnvironmentLayout,
    frame: Frame,
    scale: f64,
    distribution: PiecewiseConstant2D,
    /// The texel sum weighted by solid angle over 4π, scaled: the mean radiance.
    average: [f64; 3],
}

/// Rec. 709 luminance of a linear RGB triple.
fn luminance(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// The integral of the bilinear (tent) filter of texels i − 1, i, i + 1 over texel i's cell,
/// per unit cell: the average a texel's cell sees of each neighbour along one axis.
const CELL_AVERAGE_WEIGHTS: [f64; 3] = [0.125, 0.75, 0.125];

impl EnvironmentMap {
    /// A map of `width` × `height` texels (row-major from the top-left) of linear RGB
    /// radiance times `scale`, in `layout`, whose own frame `frame` carries into the world.
    ///
    /// Errors: an empty image, a texel count other than width × height, a non-square
    /// equal-area image, a texel or scale that is not finite, a negative scale, or a frame
    /// that is not orthonormal. Negative texel components are taken as 0.
    pub fn new(
        width: usize,
        height: usize,
        texels: Vec<[f32; 3]>,
        layout: EnvironmentLayout,
        frame: Frame,
        scale: f64,
    ) -> Result<EnvironmentMap, String> {
        if width == 0 || height == 0 {
            return Err(format!(
                "an environment map of {width} × {height} texels is empty"
            ));
        }
        if texels.len() != width * height {
            return Err(format!(
                "an environment map of {width} × {height} texels needs {} of them, got {}",
                width * height,
                texels.len()
            ));
        }
        if layout == EnvironmentLayout::EqualArea && width != height {
            return Err(format!(
                "an equal-area environment map must be square, got {width} × {height}"
            ));
        }
        if !(scale.is_finite() && scale >= 0.0) {
            return Err(format!(
                "the environment map's scale {scale} is not a finite, non-negative number"
            ));
        }
        if let Some(i) = texels.iter().position(|t| t.iter().any(|c| !c.is_finite())) {
            return Err(format!(
                "texel ({}, {}) of the environment map is not finite: {:?}",
                i % width,
                i / width,
                texels[i]
            ));
        }
        let unit = |v: Vec3| (v.length() - 1.0).abs() < 1e-6;
        let orthogonal = frame.x.dot(frame.y).abs() < 1e-6
            && frame.x.dot(frame.z).abs() < 1e-6
            && frame.y.dot(frame.z).abs() < 1e-6;
        if !(unit(frame.x) && unit(frame.y) && unit(frame.z) && orthogonal) {
            return Err(format!(
                "the environment map's frame is not orthonormal: {frame:?}"
            ));
        }
        let texels: Vec<[f32; 3]> = texels.iter().map(|t| t.map(|c| c.max(0.0))).collect();
        let mut map = EnvironmentMap {
            width,
            height,
            texels,
            layout,
            frame,
            scale,
            distribution: PiecewiseConstant2D::new(&[], 1, 1),
            average: [0.0; 3],
        };
        let mut weights = Vec::with_capacity(width * height);
        let mut integral = [0.0; 3];
        for j in 0..height {
            let solid_angle = map.texel_solid_angle(j);
            for i in 0..width {
                let mut cell_average = 0.0;
                for (b, wb) in CELL_AVERAGE_WEIGHTS.iter().enumerate() {
                    for (a, wa) in CELL_AVERAGE_WEIGHTS.iter().enumerate() {
                        let t = map.texel(i as i64 + a as i64 - 1, j as i64 + b as i64 - 1);
                        cell_average += wa * wb * luminance(t);
                    }
                }
                weights.push(cell_average * solid_angle);
                let t = map.texel(i as i64, j as i64);
                for c in 0..3 {
                    integral[c] += t[c] * solid_angle;
                }
            }
        }
        map.distribution = PiecewiseConstant2D::new(&weights, width, height);
        map.average = integral.map(|v| v * scale / (4.0 * PI));
        Ok(map)
    }

    /// The layout the map was built with.
    pub fn layout(&self) -> EnvironmentLayout {
        self.layout
    }

    /// The image's size in texels, [width, height].
    pub fn resolution(&self) -> [usize; 2] {
        [self.width, self.height]
    }

    /// The frame whose `to_world` carries the map's directions into the world.
    pub fn frame(&self) -> Frame {
        self.frame
    }

    /// The solid angle of a texel in row `j`, in steradians.
    fn texel_solid_angle(&self, j: usize) -> f64 {
        match self.layout {
            EnvironmentLayout::LatLong | EnvironmentLayout::LatLongPoles => {
                let theta = |row: usize| PI * row as f64 / self.height as f64;
                TAU / self.width as f64 * (theta(j).cos() - theta(j + 1).cos())
            }
            EnvironmentLayout::EqualArea => 4.0 * PI / (self.width * self.height) as f64,
        }
    }

    /// Texel (x, y), unscaled, for x and y at most one image outside it: the lat-long map
    /// wraps around in φ and clamps at the poles; the equal-area square folds over its edges.
    fn texel(&self, x: i64, y: i64) -> [f64; 3] {
        let (i, j) = match self.layout {
            EnvironmentLayout::LatLong | EnvironmentLayout::LatLongPoles => (
                x.rem_euclid(self.width as i64) as usize,
                y.clamp(0, self.height as i64 - 1) as usize,
            ),
            EnvironmentLayout::EqualArea => wrap_equal_area_texel(x, y, self.width),
        };
        self.texels[j * self.width + i].map(f64::from)
    }

    /// The bilinearly filtered, scaled radiance at image coordinates (s, t) ∈ [0, 1]².
    fn lookup(&self, p: [f64; 2]) -> [f64; 3] {
        let x = p[0] * self.width as f64 - 0.5;
        let y = match self.layout {
            EnvironmentLayout::LatLongPoles => p[1] * (self.height as f64 - 1.0),
            _ => p[1] * self.height as f64 - 0.5,
        };
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let mut sum = [0.0; 3];
        for (dy, wy) in [(0, 1.0 - fy), (1, fy)] {
            for (dx, wx) in [(0, 1.0 - fx), (1, fx)] {
                let t = self.texel(x0 + dx, y0 + dy);
                for c in 0..3 {
                    sum[c] += wx * wy * t[c];
                }
            }
        }
        sum.map(|v| v * self.scale)
    }

    /// Image coordinates of a direction of the map's own frame (unit length).
    fn to_square(&self, local: Vec3) -> [f64; 2] {
        match self.layout {
            EnvironmentLayout::LatLong | EnvironmentLayout::LatLongPoles => {
                let theta = local.z.clamp(-1.0, 1.0).acos();
                let phi = local.y.atan2(local.x).rem_euclid(TAU);
                [(phi / TAU).min(1.0), theta * FRAC_1_PI]
            }
            EnvironmentLayout::EqualArea => equal_area_sphere_to_square(local),
        }
    }

    /// The radiance arriving from world direction `wi` (pointing away from the receiver,
    /// towards the environment), linear RGB, scaled.
    pub fn radiance(&self, wi: Vec3) -> [f64; 3] {
        let local = self.frame.to_local(wi).normalized();
        self.lookup(self.to_square(local))
    }

    /// A world direction towards the environment for u in [0, 1)², its density per
    /// steradian, and the radiance from it; None where the density vanishes (a map that is
    /// black everywhere is sampled uniformly, so only at the lat-long map's poles).
    pub fn sample(&self, u: [f64; 2]) -> Option<(Vec3, f64, [f64; 3])> {
        let (p, pdf_square) = self.distribution.sample(u);
        if pdf_square <= 0.0 {
            return None;
        }
        let (local, pdf) = match self.layout {
            EnvironmentLayout::LatLong | EnvironmentLayout::LatLongPoles => {
                let (sin_theta, cos_theta) = (PI * p[1]).sin_cos();
                if sin_theta <= 0.0 {
                    return None;
                }
                let (sin_phi, cos_phi) = (TAU * p[0]).sin_cos();
                let local = Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta);
                (local, pdf_square / (2.0 * PI * PI * sin_theta))
            }
            EnvironmentLayout::EqualArea => {
                (equal_area_square_to_sphere(p), pdf_square / (4.0 * PI))
            }
        };
        Some((self.frame.to_world(local), pdf, self.lookup(p)))
    }

    /// The density per steradian with which [`sample`](Self::sample) returns world
    /// direction `wi`.
    pub fn pdf(&self, wi: Vec3) -> f64 {
        let local = self.frame.to_local(wi).normalized();
        let p = self.to_square(local);
        let pdf_square = self.distribution.pdf(p);
        match self.layout {
            EnvironmentLayout::LatLong | EnvironmentLayout::LatLongPoles => {
                let sin_theta = (1.0 - local.z * local.z).max(0.0).sqrt();
                if sin_theta <= 0.0 {
                    return 0.0;
                }
                pdf_square / (2.0 * PI * PI * sin_theta)
            }
            EnvironmentLayout::EqualArea => pdf_square / (4.0 * PI),
        }
    }

    /// The mean radiance over the sphere, (1/4π) ∫ L dω, linear RGB: the texels' sum
    /// weighted by their solid angles, which the filtered radiance matches to second order
    /// in the texel size.
    pub fn average(&self) -> [f64; 3] {
        self.average
    }

    /// The luminance of the power the map would deliver through a scene bounded by a sphere
    /// of radius `scene_radius`: π r² ∫ L dω, the weight a light sampler gives the map.
    pub fn power_estimate(&self, scene_radius: f64) -> f64 {
        PI * scene_radius * scene_radius * 4.0 * PI * luminance(self.average)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::chi_square::SphericalBins;
    use crate::sampling::{uniform_sphere, Rng};

    const SEED: u64 = 0x5EED00E0;
    const SAMPLES: usize = 1_000_000;

    fn tilted_frame() -> Frame {
        Frame::from_z(Vec3::new(0.3, -0.5, 0.8).normalized())
    }

    /// A lat-long image of 32 × 16 texels: black polar caps (two rows each), a black block,
    /// a smooth coloured background and one bright texel.
    fn lat_long_texels() -> Vec<[f32; 3]> {
        let (w, h) = (32, 16);
        let mut texels = Vec::with_capacity(w * h);
        for j in 0..h {
            for i in 0..w {
                let value =
                    if !(2..14).contains(&j) || ((20..24).contains(&i) && (5..9).contains(&j)) {
                        [0.0; 3]
                    } else if (i, j) == (9, 6) {
                        [60.0, 40.0, 20.0]
                    } else {
                        let g = 0.2 + 0.1 * ((i as f32) * 0.4).sin().abs();
                        [g, 0.5 * g, 0.3 + 0.01 * j as f32]
                    };
                texels.push(value);
            }
        }
        texels
    }

    /// An equal-area image of 16 × 16 texels: a black block, one bright texel on the edge
    /// (so its filtered light folds over into the mirrored texels), a smooth background.
    fn equal_area_texels() -> Vec<[f32; 3]> {
        let n = 16;
        let mut texels = Vec::with_capacity(n * n);
        for j in 0..n {
            for i in 0..n {
                let value = if (3..7).contains(&i) && (9..13).contains(&j) {
                    [0.0; 3]
                } else if (i, j) == (15, 4) {
                    [30.0, 50.0, 10.0]
                } else {
                    let g = 0.1 + 0.05 * (i + 2 * j) as f32 / 16.0;
                    [g, g, 2.0 * g]
                };
                texels.push(value);
            }
        }
        texels
    }

    fn maps() -> [EnvironmentMap; 2] {
        [
            EnvironmentMap::new(
                32,
                16,
                lat_long_texels(),
                EnvironmentLayout::LatLong,
                tilted_frame(),
                1.5,
            )
            .unwrap(),
            EnvironmentMap::new(
                16,
                16,
                equal_area_texels(),
                EnvironmentLayout::EqualArea,
                tilted_frame(),
                1.5,
            )
            .unwrap(),
        ]
    }

    fn chi_square(map: &EnvironmentMap, what: &str) {
        SphericalBins::about_z(-1.0, [20, 40])
            .test(
                SAMPLES,
                SEED,
                // A failed sample counts outside the bins, where the pdf has no mass.
                |u| map.sample(u).map_or(Vec3::splat(f64::NAN), |(wi, _, _)| wi),
                |w| map.pdf(w),
            )
            .assert_accepted(what);
    }

    #[test]
    fn chi_square_lat_long_environment() {
        chi_square(&maps()[0], "lat-long environment map");
    }

    #[test]
    fn chi_square_lat_long_poles_environment() {
        let map = EnvironmentMap::new(
            32,
            16,
            lat_long_texels(),
            EnvironmentLayout::LatLongPoles,
            tilted_frame(),
            1.5,
        )
        .unwrap();
        chi_square(&map, "lat-long environment map, rows on the poles");
    }

    /// Row j's value is found at θ = π(j + ½)/H in the lat-long layout and at θ = πj/(H − 1)
    /// in Mitsuba's: the first and last rows on the poles.
    #[test]
    fn lat_long_rows_sit_where_each_layout_puts_them() {
        let (w, h) = (8, 5);
        let texels: Vec<[f32; 3]> = (0..w * h).map(|i| [(i / w) as f32; 3]).collect();
        let frame = Frame::from_z(Vec3::Z);
        let at = |layout, theta: f64| {
            let map = EnvironmentMap::new(w, h, texels.clone(), layout, frame, 1.0).unwrap();
            map.radiance(Vec3::new(theta.sin(), 0.0, theta.cos()))[0]
        };
        for j in 0..h {
            let centre = PI * (j as f64 + 0.5) / h as f64;
            assert!((at(EnvironmentLayout::LatLong, centre) - j as f64).abs() < 1e-9);
            let pole_aligned = PI * j as f64 / (h - 1) as f64;
            assert!((at(EnvironmentLayout::LatLongPoles, pole_aligned) - j as f64).abs() < 1e-9);
        }
        // Between rows: linear in θ.
        let mid = PI * 1.5 / (h - 1) as f64;
        assert!((at(EnvironmentLayout::LatLongPoles, mid) - 1.5).abs() < 1e-9);
    }

    #[test]
    fn chi_square_equal_area_environment() {
        chi_square(&maps()[1], "equal-area environment map");
    }

    #[test]
    fn chi_square_rejects_a_shifted_bright_texel() {
        // Samples of the lat-long map against the pdf of the same map with its bright texel
        // one column over: the test must be able to fail.
        let mut shifted = lat_long_texels();
        shifted.swap(6 * 32 + 9, 6 * 32 + 10);
        let wrong = EnvironmentMap::new(
            32,
            16,
            shifted,
            EnvironmentLayout::LatLong,
            tilted_frame(),
            1.5,
        )
        .unwrap();
        let map = &maps()[0];
        let outcome = SphericalBins::about_z(-1.0, [20, 40]).test(
            SAMPLES,
            SEED,
            |u| map.sample(u).map_or(Vec3::splat(f64::NAN), |(wi, _, _)| wi),
            |w| wrong.pdf(w),
        );
        assert!(!outcome.accepted(), "{outcome:?}");
    }

    #[test]
    fn samples_agree_with_pdf_and_radiance() {
        for map in maps() {
            let mut rng = Rng::new(SEED, 1);
            for _ in 0..100_000 {
                let u = [rng.uniform(), rng.uniform()];
                let Some((wi, pdf, radiance)) = map.sample(u) else {
                    panic!("{:?}: no sample for {u:?}", map.layout());
                };
                assert!((wi.length() - 1.0).abs() < 1e-12);
                assert!(pdf > 0.0 && (map.pdf(wi) / pdf - 1.0).abs() < 1e-9, "{u:?}");
                let looked_up = map.radiance(wi);
                for c in 0..3 {
                    assert!((looked_up[c] - radiance[c]).abs() < 1e-7 * (1.0 + radiance[c]));
                }
            }
        }
    }

    #[test]
    fn every_direction_with_radiance_can_be_sampled() {
        // pdf > 0 wherever L > 0, over 200 000 random directions, including the zero block's
        // border, where only the filter's tail carries light; and the black caps of the
        // lat-long map (which hold no light) are never sampled.
        for map in maps() {
            let mut rng = Rng::new(SEED, 2);
            let mut dark = 0;
            for _ in 0..200_000 {
                let w = uniform_sphere([rng.uniform(), rng.uniform()]);
                let lit = map.radiance(w).iter().any(|&c| c > 0.0);
                if lit {
                    assert!(
                        map.pdf(w) > 0.0,
                        "{:?}: {w:?} is lit but has pdf 0",
                        map.layout()
                    );
                } else {
                    dark += 1;
                }
            }
            assert!(dark > 1_000, "the test image has black regions: {dark}");
        }
        let lat_long = &maps()[0];
        let frame = tilted_frame();
        let mut rng = Rng::new(SEED, 3);
        for _ in 0..100_000 {
            let (wi, _, _) = lat_long.sample([rng.uniform(), rng.uniform()]).unwrap();
            let theta = frame.to_local(wi).z.clamp(-1.0, 1.0).acos();
            assert!((PI / 16.0..=PI * 15.0 / 16.0).contains(&theta), "{theta}");
        }
    }

    #[test]
    fn monte_carlo_integral_matches_the_texel_sum() {
        // ∫ L dω ≈ mean of L/pdf over 200 000 samples, against the texels weighted by their
        // solid angles (4π × average), to 1 %.
        for map in maps() {
            let mut rng = Rng::new(SEED, 4);
            let n = 200_000;
            let mut sum = [0.0; 3];
            for _ in 0..n {
                if let Some((_, pdf, radiance)) = map.sample([rng.uniform(), rng.uniform()]) {
                    for c in 0..3 {
                        sum[c] += radiance[c] / pdf;
                    }
                }
            }
            let expected = map.average().map(|a| 4.0 * PI * a);
            for c in 0..3 {
                let estimate = sum[c] / n as f64;
                eprintln!(
                    "{:?} channel {c}: {estimate} vs {}",
                    map.layout(),
                    expected[c]
                );
                assert!(
                    (estimate / expected[c] - 1.0).abs() < 0.01,
                    "{:?} channel {c}: {estimate} vs {}",
                    map.layout(),
                    expected[c]
                );
            }
            let power = map.power_estimate(2.0);
            assert!((power - 4.0 * PI * 4.0 * PI * luminance(map.average())).abs() < 1e-9 * power);
        }
    }

    #[test]
    fn texel_centres_and_seams() {
        let frame = tilted_frame();
        let maps = maps();
        let [lat_long, equal_area] = [&maps[0], &maps[1]];
        let texels = lat_long_texels();
        for j in 2..14 {
            for i in 0..32 {
                let theta = PI * (j as f64 + 0.5) / 16.0;
                let phi = TAU * (i as f64 + 0.5) / 32.0;
                let local = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                );
                let l = lat_long.radiance(frame.to_world(local));
                for c in 0..3 {
                    let expected = 1.5 * texels[j * 32 + i][c] as f64;
                    assert!(
                        (l[c] - expected).abs() < 1e-9 * (1.0 + expected),
                        "({i}, {j})"
                    );
                }
            }
        }
        let texels = equal_area_texels();
        for j in 0..16 {
            for i in 0..16 {
                let p = [(i as f64 + 0.5) / 16.0, (j as f64 + 0.5) / 16.0];
                let l = equal_area.radiance(frame.to_world(equal_area_square_to_sphere(p)));
                for c in 0..3 {
                    let expected = 1.5 * texels[j * 16 + i][c] as f64;
                    assert!(
                        (l[c] - expected).abs() < 1e-6 * (1.0 + expected),
                        "({i}, {j})"
                    );
                }
            }
        }
        // Radiance is continuous across the seams: φ = 0 for the lat-long map; for the
        // equal-area square its four edges, the half-circles y = 0 and x = 0 below z = 0.
        let mut rng = Rng::new(SEED, 5);
        let e = 1e-9;
        for _ in 0..10_000 {
            let z = -rng.uniform();
            let s = (1.0 - z * z).sqrt();
            let pairs = [
                (lat_long, Vec3::new(s, e, z), Vec3::new(s, -e, z)),
                (equal_area, Vec3::new(s, e, z), Vec3::new(s, -e, z)),
                (equal_area, Vec3::new(-s, e, z), Vec3::new(-s, -e, z)),
                (equal_area, Vec3::new(e, s, z), Vec3::new(-e, s, z)),
                (equal_area, Vec3::new(e, -s, z), Vec3::new(-e, -s, z)),
            ];
            for (map, a, b) in pairs {
                let (la, lb) = (
                    map.radiance(frame.to_world(a)),
                    map.radiance(frame.to_world(b)),
                );
                for c in 0..3 {
                    assert!(
                        (la[c] - lb[c]).abs() < 1e-5,
                        "{:?} {a:?}: {la:?} vs {lb:?}",
                        map.layout()
                    );
                }
            }
        }
    }

    #[test]
    fn bad_maps_are_refused() {
        let frame = Frame::from_z(Vec3::Z);
        let layout = EnvironmentLayout::LatLong;
        assert!(EnvironmentMap::new(0, 4, vec![], layout, frame, 1.0).is_err());
        assert!(EnvironmentMap::new(2, 2, vec![[1.0; 3]; 3], layout, frame, 1.0).is_err());
        assert!(EnvironmentMap::new(
            2,
            1,
            vec![[1.0; 3]; 2],
            EnvironmentLayout::EqualArea,
            frame,
            1.0
        )
        .is_err());
        assert!(EnvironmentMap::new(1, 1, vec![[f32::NAN, 0.0, 0.0]], layout, frame, 1.0).is_err());
        assert!(EnvironmentMap::new(1, 1, vec![[1.0; 3]], layout, frame, -1.0).is_err());
        let skewed = Frame {
            x: Vec3::X,
            y: Vec3::X,
            z: Vec3::Z,
        };
        assert!(EnvironmentMap::new(1, 1, vec![[1.0; 3]], layout, skewed, 1.0).is_err());
        // A black map still samples (uniformly) and reports no light.
        let black = EnvironmentMap::new(
            4,
            4,
            vec![[0.0; 3]; 16],
            EnvironmentLayout::EqualArea,
            frame,
            1.0,
        )
        .unwrap();
        let (_, pdf, radiance) = black.sample([0.3, 0.6]).unwrap();
        assert!((pdf - 0.25 * FRAC_1_PI).abs() < 1e-12 && radiance == [0.0; 3]);
        assert_eq!(black.power_estimate(10.0), 0.0);
        // A constant map: average equals the constant, for both layouts.
        for (w, h, layout) in [
            (8, 4, EnvironmentLayout::LatLong),
            (4, 4, EnvironmentLayout::EqualArea),
        ] {
            let map = EnvironmentMap::new(w, h, vec![[2.0, 1.0, 0.5]; w * h], layout, frame, 2.0)
                .unwrap();
            let a = map.average();
            assert!(
                (a[0] - 4.0).abs() < 1e-12
                    && (a[1] - 2.0).abs() < 1e-12
                    && (a[2] - 1.0).abs() < 1e-12
            );
        }
    }
}
