//! Warps from the unit square [0, 1)² onto the domains a renderer samples (disk, polygon,
//! triangle, cone, sphere, hemisphere, Phong lobe), each with its density.
//!
//! The maps follow pbrt-v4 §A.5 and Shirley & Chiu 1997, "A low distortion map between disk
//! and square"; the triangle map is Heitz 2019, "A low-distortion map between triangle and
//! square". Every map here is continuous and one-to-one on the pieces it is built from, so
//! well-stratified points in the square stay well stratified on the domain.
//!
//! Densities: planar maps give a pdf per unit area; direction maps give a pdf per unit solid
//! angle (steradian). Directions are unit vectors about +z; [`Frame`] carries them to a
//! world-space normal.

use std::f64::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, TAU};

use crate::math::Vec3;

/// The density of [`concentric_disk`] per unit area of the unit disk: 1/π.
pub const DISK_PDF: f64 = FRAC_1_PI;

/// The density of [`uniform_sphere`] per steradian: 1/(4π).
pub const SPHERE_PDF: f64 = 0.25 * FRAC_1_PI;

/// The density of [`uniform_triangle`] per unit area of (b0, b1) space, whose triangle has
/// area 1/2; on a triangle of area A in the scene, the density is 1/A.
pub const TRIANGLE_BARYCENTRIC_PDF: f64 = 2.0;

/// A uniform point (x, y) on the unit disk, density [`DISK_PDF`] (Shirley & Chiu 1997).
///
/// Concentric squares go to concentric circles, so the map is continuous, keeps the aspect
/// of each cell near 1, and preserves the strata of the square (unlike the polar map).
pub fn concentric_disk(u: [f64; 2]) -> (f64, f64) {
    let a = 2.0 * u[0] - 1.0;
    let b = 2.0 * u[1] - 1.0;
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    // Each of the four triangles between the square's diagonals maps to a quarter disk: the
    // angle is π/4 · t, |t| ≤ 1, from the x axis (or π/2 − π/4 · t, from the y axis,
    // where sine and cosine trade places).
    if a.abs() > b.abs() {
        let (sin, cos) = sin_cos_quarter(FRAC_PI_4 * (b / a));
        (a * cos, a * sin)
    } else {
        let (sin, cos) = sin_cos_quarter(FRAC_PI_4 * (a / b));
        (b * sin, b * cos)
    }
}

/// sin x and cos x for |x| ≤ π/4 by their Taylor polynomials to x¹⁵ and x¹⁶, whose first
/// omitted terms are below 5e-17 there: within an ulp or two of `f64::sin_cos` at an eighth
/// of its cost (the cosine-weighted sample of every diffuse bounce draws one).
#[inline]
fn sin_cos_quarter(x: f64) -> (f64, f64) {
    let x2 = x * x;
    // Horner in x²: 1/(2k+1)! for the sine, 1/(2k)! for the cosine.
    const S: [f64; 8] = [
        1.0,
        -1.0 / 6.0,
        1.0 / 120.0,
        -1.0 / 5040.0,
        1.0 / 362_880.0,
        -1.0 / 39_916_800.0,
        1.0 / 6_227_020_800.0,
        -1.0 / 1_307_674_368_000.0,
    ];
    const C: [f64; 9] = [
        1.0,
        -1.0 / 2.0,
        1.0 / 24.0,
        -1.0 / 720.0,
        1.0 / 40_320.0,
        -1.0 / 3_628_800.0,
        1.0 / 479_001_600.0,
        -1.0 / 87_178_291_200.0,
        1.0 / 20_922_789_888_000.0,
    ];
    let sin = x * S.iter().rev().fold(0.0, |acc, &c| acc * x2 + c);
    let cos = C.iter().rev().fold(0.0, |acc, &c| acc * x2 + c);
    (sin, cos)
}

/// The area of the regular `blades`-gon inscribed in the unit circle: n/2 · sin(2π/n).
pub fn polygon_area(blades: u32) -> f64 {
    let n = blades as f64;
    0.5 * n * (TAU / n).sin()
}

/// A uniform point (x, y) in the regular `blades`-gon (blades ≥ 3) inscribed in the unit
/// circle, with one vertex at angle 0; density 1 / [`polygon_area`] per unit area.
///
/// `u[0]` picks one of the n congruent triangles (centre, vertex k, vertex k + 1) and is
/// rescaled to [0, 1) within it, so the pieces join without gaps and strata carry through.
pub fn regular_polygon(u: [f64; 2], blades: u32) -> (f64, f64) {
    debug_assert!(
        blades >= 3,
        "a polygon has at least three blades, got {blades}"
    );
    let n = blades.max(3);
    let scaled = u[0] * n as f64;
    // Rounding can push u[0]·n up to n when u[0] is just below 1.
    let k = (scaled as u32).min(n - 1);
    let within = (scaled - k as f64).clamp(0.0, 1.0);
    let (b0, b1) = uniform_triangle([within, u[1]]);
    let wedge = TAU / n as f64;
    let (s0, c0) = (k as f64 * wedge).sin_cos();
    let (s1, c1) = ((k + 1) as f64 * wedge).sin_cos();
    // The centre takes the remaining weight 1 − b0 − b1 and sits at the origin.
    (b0 * c0 + b1 * c1, b0 * s0 + b1 * s1)
}

/// Uniform barycentrics (b0, b1) on a triangle; b2 = 1 − b0 − b1. The density is
/// [`TRIANGLE_BARYCENTRIC_PDF`] in (b0, b1), or 1/area on the triangle itself.
///
/// Heitz 2019: the square is split along its diagonal and each half is sheared onto the
/// triangle, which is area-preserving and continuous (unlike the square-root map, it does
/// not crowd points towards one vertex).
pub fn uniform_triangle(u: [f64; 2]) -> (f64, f64) {
    if u[0] < u[1] {
        let b0 = 0.5 * u[0];
        (b0, u[1] - b0)
    } else {
        let b1 = 0.5 * u[1];
        (u[0] - b1, b1)
    }
}

/// A unit direction about +z within the angle acos(`cos_max`), uniform in solid angle;
/// density [`uniform_cone_pdf`]. `cos_max` is in [−1, 1].
///
/// For tiny cones, cos θ near 1 carries few significant bits, so the sine comes from
/// 1 − cos θ = u·(1 − cos_max), computed directly, as sin²θ = (1 − cos θ)(1 + cos θ). The
/// subtraction 1 − cos_max is itself exact whenever cos_max ≥ 1/2 (Sterbenz's lemma).
pub fn uniform_cone(u: [f64; 2], cos_max: f64) -> Vec3 {
    let one_minus_cos = u[0] * (1.0 - cos_max);
    let cos = 1.0 - one_minus_cos;
    let sin = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
    let (sin_phi, cos_phi) = (TAU * u[1]).sin_cos();
    Vec3::new(sin * cos_phi, sin * sin_phi, cos)
}

/// The density of [`uniform_cone`] per steradian: 1 / (2π (1 − cos_max)); infinite for a
/// cone of zero width.
pub fn uniform_cone_pdf(cos_max: f64) -> f64 {
    1.0 / (TAU * (1.0 - cos_max))
}

/// A unit direction uniform on the sphere, density [`SPHERE_PDF`].
pub fn uniform_sphere(u: [f64; 2]) -> Vec3 {
    let z = 1.0 - 2.0 * u[0];
    // 1 − z² = 4u(1 − u), free of the cancellation near the poles.
    let sin = 2.0 * (u[0] * (1.0 - u[0])).max(0.0).sqrt();
    let (sin_phi, cos_phi) = (TAU * u[1]).sin_cos();
    Vec3::new(sin * cos_phi, sin * sin_phi, z)
}

/// A unit direction in the hemisphere about +z with density cos θ / π per steradian
/// (Malley's method: a uniform disk point lifted onto the hemisphere).
pub fn cosine_hemisphere(u: [f64; 2]) -> Vec3 {
    let (x, y) = concentric_disk(u);
    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
    Vec3::new(x, y, z)
}

/// The density of [`cosine_hemisphere`] per steradian for a direction with z = `cos_theta`:
/// cos θ / π, and 0 below the horizon.
pub fn cosine_hemisphere_pdf(cos_theta: f64) -> f64 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// A unit direction about +z with density (n + 1)/(2π) · cosⁿα per steradian, where
/// n = `exponent` ≥ 0 and α is the angle to +z; see [`phong_lobe_pdf`].
///
/// cos α = u^(1/(n+1)) inverts the cumulative distribution cos^(n+1). For sharp lobes cos α
/// is near 1, so 1 − cos α comes from expm1 rather than by subtraction.
pub fn phong_lobe(u: [f64; 2], exponent: f64) -> Vec3 {
    let log_cos = u[0].ln() / (exponent + 1.0);
    let cos = log_cos.exp();
    let one_minus_cos = -log_cos.exp_m1();
    let sin = (one_minus_cos * (1.0 + cos)).max(0.0).sqrt();
    let (sin_phi, cos_phi) = (TAU * u[1]).sin_cos();
    Vec3::new(sin * cos_phi, sin * sin_phi, cos)
}

/// The density of [`phong_lobe`] per steradian at a direction with cos α = `cos_alpha`:
/// (n + 1)/(2π) · cosⁿα, and 0 where cos α ≤ 0.
pub fn phong_lobe_pdf(cos_alpha: f64, exponent: f64) -> f64 {
    if cos_alpha <= 0.0 {
        return 0.0;
    }
    (exponent + 1.0) / TAU * cos_alpha.powf(exponent)
}

/// An orthonormal, right-handed frame whose z axis is a given unit vector: local directions
/// about +z (as every warp here returns) become world directions about that vector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub x: Vec3,
    pub y: Vec3,
    pub z: Vec3,
}

impl Frame {
    /// The frame with z = `n`, which must be unit length; x and y follow Duff et al. 2017,
    /// so they vary continuously with `n` except across z = 0.
    pub fn from_z(n: Vec3) -> Frame {
        let (x, y) = n.orthonormal_basis();
        Frame { x, y, z: n }
    }

    /// A local vector (components along x, y, z) in world space.
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.x * v.x + self.y * v.y + self.z * v.z
    }

    /// A world vector in local components.
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.x), v.dot(self.y), v.dot(self.z))
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::*;
    use crate::sampling::chi_square::{PlanarBins, SphericalBins};
    use crate::sampling::Rng;

    /// Seed for every random test in this module.
    const SEED: u64 = 0x5EED0005;
    /// Samples per chi-square test: about 1.5 s for all of them together at the test profile.
    const SAMPLES: usize = 1_000_000;

    /// Points on a 64 × 64 grid over [0, 1)² that include both edges of the square.
    fn grid() -> impl Iterator<Item = [f64; 2]> {
        let last = 1.0 - f64::EPSILON / 2.0;
        let steps = 64;
        (0..=steps).flat_map(move |i| {
            (0..=steps).map(move |j| {
                let at = |k: u32| (k as f64 / steps as f64).min(last);
                [at(i), at(j)]
            })
        })
    }

    /// The inverse of the concentric map, from Shirley & Chiu's construction: it shows the
    /// map is one-to-one, so cells of the square go to disjoint regions of the disk.
    fn concentric_inverse(x: f64, y: f64) -> [f64; 2] {
        let r = x.hypot(y);
        let (a, b) = if x.abs() >= y.abs() {
            let a = r.copysign(x);
            if a == 0.0 {
                (0.0, 0.0)
            } else {
                (a, a * (y / x).atan() / FRAC_PI_4)
            }
        } else {
            let b = r.copysign(y);
            (b * (x / y).atan() / FRAC_PI_4, b)
        };
        [0.5 * (a + 1.0), 0.5 * (b + 1.0)]
    }

    fn unit(v: Vec3) -> bool {
        (v.length() - 1.0).abs() < 1e-12
    }

    #[test]
    fn the_quarter_turn_sine_and_cosine_match_the_library() {
        for k in -1000..=1000 {
            let x = FRAC_PI_4 * k as f64 / 1000.0;
            let (s, c) = sin_cos_quarter(x);
            let (ws, wc) = x.sin_cos();
            assert!(
                (s - ws).abs() <= 2.5e-16 && (c - wc).abs() <= 2.5e-16,
                "{x}: {s} {c}"
            );
        }
    }

    #[test]
    fn maps_land_in_their_domains() {
        let polygons = [3, 5, 6, 9].map(|blades| (blades, polygon_inside(blades)));
        for u in grid() {
            let (x, y) = concentric_disk(u);
            assert!(x.hypot(y) <= 1.0 + 1e-12, "disk {u:?}");

            let (b0, b1) = uniform_triangle(u);
            assert!(
                b0 >= 0.0 && b1 >= 0.0 && b0 + b1 <= 1.0 + 1e-15,
                "triangle {u:?}"
            );

            for (blades, inside) in &polygons {
                let (x, y) = regular_polygon(u, *blades);
                // A hair of slack for points on an edge.
                assert!(
                    inside(x * (1.0 - 1e-12), y * (1.0 - 1e-12)),
                    "polygon {blades} {u:?}"
                );
            }

            for cos_max in [-0.5, 0.0, 0.5, 0.999, 1.0 - 1e-12] {
                let w = uniform_cone(u, cos_max);
                assert!(
                    unit(w) && w.z >= cos_max && w.z <= 1.0,
                    "cone {cos_max} {u:?}"
                );
            }
            assert!(unit(uniform_sphere(u)), "sphere {u:?}");
            let w = cosine_hemisphere(u);
            assert!(unit(w) && w.z >= 0.0, "hemisphere {u:?}");
            for exponent in [0.0, 1.0, 10.0, 200.0, 1e6] {
                let w = phong_lobe(u, exponent);
                assert!(unit(w) && w.z >= 0.0, "phong {exponent} {u:?}");
            }
        }
    }

    #[test]
    fn concentric_disk_is_one_to_one() {
        let mut rng = Rng::new(SEED, 1);
        for _ in 0..10_000 {
            let u = [rng.uniform(), rng.uniform()];
            let (x, y) = concentric_disk(u);
            let back = concentric_inverse(x, y);
            assert!(
                (back[0] - u[0]).abs() < 1e-12 && (back[1] - u[1]).abs() < 1e-12,
                "{u:?} → ({x}, {y}) → {back:?}"
            );
        }
    }

    #[test]
    fn concentric_disk_preserves_area() {
        // The Jacobian determinant is π everywhere off the diagonals (area π from area 1):
        // central differences, step 1e-6, agree to 1e-5 relative.
        let mut rng = Rng::new(SEED, 2);
        let h = 1e-6;
        for _ in 0..2_000 {
            let u = [0.01 + 0.98 * rng.uniform(), 0.01 + 0.98 * rng.uniform()];
            let (a, b) = (2.0 * u[0] - 1.0, 2.0 * u[1] - 1.0);
            if (a.abs() - b.abs()).abs() < 1e-4 {
                continue;
            }
            let d = |du: [f64; 2]| {
                let (x0, y0) = concentric_disk([u[0] - du[0], u[1] - du[1]]);
                let (x1, y1) = concentric_disk([u[0] + du[0], u[1] + du[1]]);
                ((x1 - x0) / (2.0 * h), (y1 - y0) / (2.0 * h))
            };
            let (xu, yu) = d([h, 0.0]);
            let (xv, yv) = d([0.0, h]);
            let jacobian = xu * yv - xv * yu;
            assert!((jacobian / PI - 1.0).abs() < 1e-5, "{u:?}: {jacobian}");
        }
    }

    #[test]
    fn concentric_disk_keeps_strata() {
        // Each cell of a 4 × 4 grid maps to a region of area π/16: the shoelace area of the
        // image of its boundary, 256 points an edge, agrees to 1e-4 relative. Disjointness
        // follows from concentric_disk_is_one_to_one.
        let cells = 4;
        let per_edge = 256;
        for i in 0..cells {
            for j in 0..cells {
                let corner = [i as f64 / cells as f64, j as f64 / cells as f64];
                let side = 1.0 / cells as f64;
                let mut outline = Vec::new();
                for edge in 0..4 {
                    for k in 0..per_edge {
                        let t = side * k as f64 / per_edge as f64;
                        let u = match edge {
                            0 => [corner[0] + t, corner[1]],
                            1 => [corner[0] + side, corner[1] + t],
                            2 => [corner[0] + side - t, corner[1] + side],
                            _ => [corner[0], corner[1] + side - t],
                        };
                        outline.push(concentric_disk(u));
                    }
                }
                let area: f64 = (0..outline.len())
                    .map(|k| {
                        let (x0, y0) = outline[k];
                        let (x1, y1) = outline[(k + 1) % outline.len()];
                        0.5 * (x0 * y1 - x1 * y0)
                    })
                    .sum();
                let expected = PI / (cells * cells) as f64;
                assert!(
                    (area / expected - 1.0).abs() < 1e-4,
                    "cell ({i}, {j}): {area} vs {expected}"
                );
            }
        }
    }

    #[test]
    fn polygon_area_closed_forms() {
        assert!((polygon_area(3) - 3.0 * 3f64.sqrt() / 4.0).abs() < 1e-14);
        assert!((polygon_area(4) - 2.0).abs() < 1e-14);
        assert!((polygon_area(6) - 3.0 * 3f64.sqrt() / 2.0).abs() < 1e-14);
        assert!((polygon_area(100_000) - PI).abs() < 1e-8);
    }

    #[test]
    fn narrow_cones_stay_accurate() {
        // A cone of half-angle about 1e-6 rad: cos θ is within 1e-12 of 1, so 1 − cos²θ
        // would keep only about four digits of sin²θ. The sine must match
        // √(d (2 − d)), d = u·(1 − cos_max), to 1e-12 relative.
        for cos_max in [1.0 - 2f64.powi(-40), 1.0 - 1e-12, 0.999_999] {
            for u0 in [0.5, 0.25, 0.1, 1.0 - f64::EPSILON] {
                let w = uniform_cone([u0, 0.0], cos_max);
                let d = u0 * (1.0 - cos_max);
                let expected = (d * (2.0 - d)).sqrt();
                assert!(
                    (w.x / expected - 1.0).abs() < 1e-12,
                    "{cos_max} {u0}: {}",
                    w.x
                );
                assert!(w.y.abs() <= 1e-12 * expected && w.z >= cos_max);
            }
            assert!(uniform_cone_pdf(cos_max).is_finite());
        }
        // The same for the Phong lobe: 1 − cos α from expm1, so sin α ≈ √(2 ln(1/u)/(n+1)).
        let exponent = 1e12;
        let w = phong_lobe([0.5, 0.0], exponent);
        let expected = (2.0 * 2f64.ln() / (exponent + 1.0)).sqrt();
        assert!((w.x / expected - 1.0).abs() < 1e-9, "{}", w.x);
    }

    #[test]
    fn phong_pdf_is_normalised() {
        // ∫ pdf dω = 2π ∫₀¹ pdf(c) dc; Simpson's rule with 20 000 intervals, to 1e-6.
        for exponent in [0.0, 1.0, 10.0, 200.0] {
            let intervals = 20_000;
            let h = 1.0 / intervals as f64;
            let total: f64 = (0..=intervals)
                .map(|k| {
                    let weight = match k {
                        0 => 1.0,
                        k if k == intervals => 1.0,
                        k if k % 2 == 1 => 4.0,
                        _ => 2.0,
                    };
                    // At c = 0 take the limit from above, where the lobe for n = 0 is 1/(2π).
                    let c = (k as f64 * h).max(f64::MIN_POSITIVE);
                    weight * phong_lobe_pdf(c, exponent)
                })
                .sum::<f64>()
                * h
                / 3.0
                * TAU;
            assert!((total - 1.0).abs() < 1e-6, "exponent {exponent}: {total}");
        }
        assert_eq!(phong_lobe_pdf(-0.1, 3.0), 0.0);
        assert_eq!(phong_lobe_pdf(0.0, 3.0), 0.0);
    }

    #[test]
    fn frame_is_orthonormal_and_round_trips() {
        let mut rng = Rng::new(SEED, 3);
        for _ in 0..1_000 {
            let n = uniform_sphere([rng.uniform(), rng.uniform()]);
            let f = Frame::from_z(n);
            assert!(unit(f.x) && unit(f.y) && unit(f.z));
            assert!(f.x.dot(f.y).abs() < 1e-12 && f.x.dot(f.z).abs() < 1e-12);
            assert!((f.x.cross(f.y) - f.z).length() < 1e-12, "right-handed");
            assert!((f.to_world(Vec3::Z) - n).length() < 1e-12);
            let v = Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform());
            assert!((f.to_local(f.to_world(v)) - v).length() < 1e-12);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-12);
        }
    }

    // Chi-square goodness-of-fit tests: seed SEED, SAMPLES samples each; a test fails when
    // the p-value falls below the Šidák-corrected level of chi_square::SIGNIFICANCE.

    #[test]
    fn chi_square_concentric_disk() {
        let bins = PlanarBins::square(-1.0, 1.0, 40);
        let inside = |x: f64, y: f64| x * x + y * y <= 1.0;
        bins.test(SAMPLES, SEED, concentric_disk, |x, y| {
            if inside(x, y) {
                DISK_PDF
            } else {
                0.0
            }
        })
        .assert_accepted("concentric disk");
    }

    #[test]
    fn chi_square_rejects_disk_against_wrong_pdf() {
        // A pdf ∝ r (normalised: 3r/(2π)) must be rejected: the test can fail.
        let bins = PlanarBins::square(-1.0, 1.0, 40);
        let outcome = bins.test(SAMPLES, SEED, concentric_disk, |x, y| {
            let r = x.hypot(y);
            if r <= 1.0 {
                1.5 * FRAC_1_PI * r
            } else {
                0.0
            }
        });
        assert!(!outcome.accepted(), "{outcome:?}");
    }

    /// The inside test of the regular polygon: left of every counter-clockwise edge.
    fn polygon_inside(blades: u32) -> impl Fn(f64, f64) -> bool {
        let wedge = TAU / blades as f64;
        let corners: Vec<(f64, f64)> = (0..=blades)
            .map(|k| {
                let (s, c) = (k as f64 * wedge).sin_cos();
                (c, s)
            })
            .collect();
        move |x, y| {
            corners
                .windows(2)
                .all(|e| (e[1].0 - e[0].0) * (y - e[0].1) - (e[1].1 - e[0].1) * (x - e[0].0) >= 0.0)
        }
    }

    #[test]
    fn chi_square_polygon() {
        for blades in [5, 6] {
            let bins = PlanarBins::square(-1.0, 1.0, 40);
            let pdf = 1.0 / polygon_area(blades);
            let inside = polygon_inside(blades);
            bins.test(
                SAMPLES,
                SEED + blades as u64,
                |u| regular_polygon(u, blades),
                |x, y| if inside(x, y) { pdf } else { 0.0 },
            )
            .assert_accepted(&format!("polygon with {blades} blades"));
        }
    }

    #[test]
    fn chi_square_triangle() {
        // Unequal bin counts keep the hypotenuse b0 + b1 = 1 off the quadrature nodes.
        let bins = PlanarBins {
            x: [0.0, 1.0],
            y: [0.0, 1.0],
            bins: [37, 29],
        };
        bins.test(SAMPLES, SEED, uniform_triangle, |b0, b1| {
            if b0 + b1 <= 1.0 {
                TRIANGLE_BARYCENTRIC_PDF
            } else {
                0.0
            }
        })
        .assert_accepted("triangle");
    }

    /// Cone samples binned over [cos_max, 1], so the cone's edge lies on a bin edge.
    fn cone_test(cos_max: f64) {
        let bins = SphericalBins::about_z(cos_max, [20, 40]);
        let pdf = uniform_cone_pdf(cos_max);
        bins.test(
            SAMPLES,
            SEED,
            |u| uniform_cone(u, cos_max),
            |w| if w.z >= cos_max { pdf } else { 0.0 },
        )
        .assert_accepted(&format!("cone with cos_max {cos_max}"));
    }

    #[test]
    fn chi_square_wide_cone() {
        cone_test(-0.5);
    }

    #[test]
    fn chi_square_narrow_cone() {
        cone_test(0.999);
    }

    #[test]
    fn chi_square_sphere() {
        SphericalBins::about_z(-1.0, [20, 40])
            .test(SAMPLES, SEED, uniform_sphere, |_| SPHERE_PDF)
            .assert_accepted("sphere");
    }

    #[test]
    fn chi_square_cosine_hemisphere() {
        // Binned over the whole sphere: a sample below the horizon would fail the test.
        SphericalBins::about_z(-1.0, [40, 40])
            .test(SAMPLES, SEED, cosine_hemisphere, |w| {
                cosine_hemisphere_pdf(w.z)
            })
            .assert_accepted("cosine hemisphere");
    }

    #[test]
    fn chi_square_cosine_hemisphere_in_a_frame() {
        // Samples carried to a tilted normal, binned about world +z: Frame must be a rotation.
        let n = Vec3::new(0.3, -0.5, 0.8).normalized();
        let frame = Frame::from_z(n);
        SphericalBins::about_z(-1.0, [40, 40])
            .test(
                SAMPLES,
                SEED,
                |u| frame.to_world(cosine_hemisphere(u)),
                |w| cosine_hemisphere_pdf(w.dot(n)),
            )
            .assert_accepted("cosine hemisphere about a tilted normal");
    }

    /// The Phong lobe of `exponent` sampled, tested against the pdf of `tested`, binned over
    /// cos α ∈ [cos_low, 1]; what falls below cos_low is one more cell.
    fn phong_test(
        exponent: f64,
        tested: f64,
        cos_low: f64,
    ) -> crate::sampling::chi_square::Outcome {
        SphericalBins::about_z(cos_low, [20, 40]).test(
            SAMPLES,
            SEED,
            |u| phong_lobe(u, exponent),
            |w| phong_lobe_pdf(w.z, tested),
        )
    }

    #[test]
    fn chi_square_phong_lobe() {
        for (exponent, cos_low) in [(1.0, 0.0), (10.0, 0.7), (200.0, 0.97)] {
            phong_test(exponent, exponent, cos_low)
                .assert_accepted(&format!("phong lobe with exponent {exponent}"));
        }
    }

    #[test]
    fn chi_square_rejects_phong_against_wrong_exponent() {
        let outcome = phong_test(10.0, 13.0, 0.7);
        assert!(!outcome.accepted(), "{outcome:?}");
    }
}

// The equal-area octahedral map between the square and the sphere (Clarberg 2008, "Fast
// Equal-Area Mapping of the (Hemi)Sphere using SIMD", as pbrt-v4 §3.8.3 uses it for
// environment maps). The square [0, 1]² is folded like an octahedron: the inner diamond
// |a| + |b| ≤ 1 of (a, b) = 2p − 1 covers the upper hemisphere z ≥ 0, the four corner
// triangles the lower one, and each of the square's edges is glued to itself mirrored about
// its midpoint. Concentric diamonds go to circles of latitude, so the map is continuous and
// its Jacobian is 4π everywhere: uniform points give uniform directions.

/// The unit direction for a point p in [0, 1]² of the equal-area square (Clarberg 2008);
/// density [`SPHERE_PDF`] per steradian for uniform p.
pub fn equal_area_square_to_sphere(p: [f64; 2]) -> Vec3 {
    let a = 2.0 * p[0] - 1.0;
    let b = 2.0 * p[1] - 1.0;
    // The signed distance from the diamond |a| + |b| = 1: positive inside (upper hemisphere).
    let signed_distance = 1.0 - (a.abs() + b.abs());
    // r is the diamond's "radius", 0 at the poles and 1 on the equator.
    let r = 1.0 - signed_distance.abs();
    // The angle within the quadrant, proportional to the position along the diamond's side.
    let phi = if r == 0.0 {
        FRAC_PI_4
    } else {
        ((b.abs() - a.abs()) / r + 1.0) * FRAC_PI_4
    };
    // 1 − |z| = r² gives equal areas: the cap |z| ≥ 1 − r² has area 2πr², its diamond 2r².
    let z = (1.0 - r * r).copysign(signed_distance);
    let sin_theta = r * (2.0 - r * r).max(0.0).sqrt();
    let (sin_phi, cos_phi) = phi.sin_cos();
    Vec3::new(
        (cos_phi * sin_theta).copysign(a),
        (sin_phi * sin_theta).copysign(b),
        z,
    )
}

/// The point of [0, 1]² that [`equal_area_square_to_sphere`] maps to the unit direction `w`.
pub fn equal_area_sphere_to_square(w: Vec3) -> [f64; 2] {
    let (x, y, z) = (w.x.abs(), w.y.abs(), w.z.abs());
    let r = (1.0 - z).max(0.0).sqrt();
    // The angle within the quadrant as a fraction of π/2, from the smaller over the larger
    // component so that the arctangent's argument stays in [0, 1].
    let (large, small) = (x.max(y), x.min(y));
    let ratio = if large == 0.0 { 0.0 } else { small / large };
    let mut phi = ratio.atan() / FRAC_PI_2;
    if x < y {
        phi = 1.0 - phi;
    }
    let mut b = phi * r;
    let mut a = r - b;
    if w.z < 0.0 {
        // The lower hemisphere fills the corner triangles: reflect across the diamond's side.
        (a, b) = (1.0 - b, 1.0 - a);
    }
    let a = a.copysign(w.x);
    let b = b.copysign(w.y);
    [0.5 * (a + 1.0), 0.5 * (b + 1.0)]
}

/// A point of the plane carried into [0, 1]² by the equal-area square's edge gluing, for
/// points at most one square's width outside it (as bilinear filtering produces): across
/// each edge the square continues mirrored, turned half a turn about that edge's midpoint.
pub fn wrap_equal_area_square(p: [f64; 2]) -> [f64; 2] {
    let [mut s, mut t] = p;
    if s < 0.0 {
        s = -s;
        t = 1.0 - t;
    } else if s > 1.0 {
        s = 2.0 - s;
        t = 1.0 - t;
    }
    if t < 0.0 {
        s = 1.0 - s;
        t = -t;
    } else if t > 1.0 {
        s = 1.0 - s;
        t = 2.0 - t;
    }
    [s, t]
}

/// The texel (column, row) of an n × n equal-area image that texel (x, y) names, for x and y
/// at most n outside [0, n): the discrete form of [`wrap_equal_area_square`], where texel
/// −1 is the mirror of texel 0 across the edge.
pub fn wrap_equal_area_texel(x: i64, y: i64, n: usize) -> (usize, usize) {
    let n = n as i64;
    let (mut x, mut y) = (x, y);
    if x < 0 {
        x = -1 - x;
        y = n - 1 - y;
    } else if x >= n {
        x = 2 * n - 1 - x;
        y = n - 1 - y;
    }
    if y < 0 {
        x = n - 1 - x;
        y = -1 - y;
    } else if y >= n {
        x = n - 1 - x;
        y = 2 * n - 1 - y;
    }
    (x.clamp(0, n - 1) as usize, y.clamp(0, n - 1) as usize)
}

#[cfg(test)]
mod equal_area_tests {
    use std::f64::consts::PI;

    use super::*;
    use crate::sampling::chi_square::{PlanarBins, SphericalBins};
    use crate::sampling::Rng;

    const SEED: u64 = 0x5EED00EA;
    const SAMPLES: usize = 1_000_000;

    #[test]
    fn round_trips() {
        let mut rng = Rng::new(SEED, 1);
        for _ in 0..100_000 {
            let p = [rng.uniform(), rng.uniform()];
            let w = equal_area_square_to_sphere(p);
            assert!((w.length() - 1.0).abs() < 1e-12, "{p:?} → {w:?}");
            let back = equal_area_sphere_to_square(w);
            assert!(
                (back[0] - p[0]).abs() < 1e-9 && (back[1] - p[1]).abs() < 1e-9,
                "{p:?} → {w:?} → {back:?}"
            );
            let w = uniform_sphere([rng.uniform(), rng.uniform()]);
            let q = equal_area_sphere_to_square(w);
            assert!((0.0..=1.0).contains(&q[0]) && (0.0..=1.0).contains(&q[1]));
            assert!(
                (equal_area_square_to_sphere(q) - w).length() < 1e-9,
                "{w:?}"
            );
        }
        // Poles, equator and the lower pole at the corners.
        assert!((equal_area_square_to_sphere([0.5, 0.5]) - Vec3::Z).length() < 1e-15);
        for corner in [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]] {
            assert!((equal_area_square_to_sphere(corner) + Vec3::Z).length() < 1e-15);
        }
        assert!((equal_area_square_to_sphere([1.0, 0.5]) - Vec3::X).length() < 1e-15);
        assert!((equal_area_square_to_sphere([0.5, 1.0]) - Vec3::Y).length() < 1e-15);
    }

    #[test]
    fn wrapping_continues_the_sphere() {
        // A point just outside the square names the direction next to the one just inside:
        // the map of the wrapped point is continuous across every edge.
        let mut rng = Rng::new(SEED, 2);
        let h = 1e-7;
        for _ in 0..10_000 {
            let t = rng.uniform();
            for (inside, outside) in [
                ([h, t], [-h, t]),
                ([1.0 - h, t], [1.0 + h, t]),
                ([t, h], [t, -h]),
                ([t, 1.0 - h], [t, 1.0 + h]),
            ] {
                let a = equal_area_square_to_sphere(inside);
                let b = equal_area_square_to_sphere(wrap_equal_area_square(outside));
                assert!((a - b).length() < 1e-5, "{inside:?} vs {outside:?}");
            }
        }
        // Texels: the one outside an edge is the mirror of the one inside.
        let n = 8;
        assert_eq!(wrap_equal_area_texel(-1, 2, n), (0, 5));
        assert_eq!(wrap_equal_area_texel(8, 2, n), (7, 5));
        assert_eq!(wrap_equal_area_texel(3, -1, n), (4, 0));
        assert_eq!(wrap_equal_area_texel(3, 8, n), (4, 7));
        assert_eq!(wrap_equal_area_texel(-1, -1, n), (7, 7));
        assert_eq!(wrap_equal_area_texel(5, 6, n), (5, 6));
        // The centre of texel −1 wraps to the centre of the texel the table names.
        for (x, y) in [(-1i64, 2i64), (8, 2), (3, -1), (3, 8), (-1, -1), (8, 8)] {
            let centre = |v: i64| (v as f64 + 0.5) / n as f64;
            let wrapped = wrap_equal_area_square([centre(x), centre(y)]);
            let (i, j) = wrap_equal_area_texel(x, y, n);
            assert!(
                (wrapped[0] - centre(i as i64)).abs() < 1e-12
                    && (wrapped[1] - centre(j as i64)).abs() < 1e-12,
                "({x}, {y}) → {wrapped:?} vs ({i}, {j})"
            );
        }
    }

    #[test]
    fn equal_area_jacobian_is_four_pi() {
        // |∂w/∂s × ∂w/∂t| by central differences, step 1e-6, is 4π to 1e-5 relative away
        // from the creases (the diamond's sides and the axes), where the map is smooth.
        let mut rng = Rng::new(SEED, 3);
        let h = 1e-6;
        let mut checked = 0;
        while checked < 2_000 {
            let p = [rng.uniform(), rng.uniform()];
            let (a, b) = (2.0 * p[0] - 1.0, 2.0 * p[1] - 1.0);
            if a.abs() < 1e-3 || b.abs() < 1e-3 || (a.abs() + b.abs() - 1.0).abs() < 1e-3 {
                continue;
            }
            let d = |dp: [f64; 2]| {
                let w0 = equal_area_square_to_sphere([p[0] - dp[0], p[1] - dp[1]]);
                let w1 = equal_area_square_to_sphere([p[0] + dp[0], p[1] + dp[1]]);
                (w1 - w0) / (2.0 * h)
            };
            let jacobian = d([h, 0.0]).cross(d([0.0, h])).length();
            assert!(
                (jacobian / (4.0 * PI) - 1.0).abs() < 1e-5,
                "{p:?}: {jacobian}"
            );
            checked += 1;
        }
    }

    #[test]
    fn chi_square_equal_area_square_to_sphere() {
        SphericalBins::about_z(-1.0, [20, 40])
            .test(SAMPLES, SEED, equal_area_square_to_sphere, |_| SPHERE_PDF)
            .assert_accepted("equal-area square to sphere");
    }

    #[test]
    fn chi_square_equal_area_sphere_to_square() {
        // Uniform directions land uniformly in the square: the Jacobian is 4π everywhere.
        PlanarBins::square(0.0, 1.0, 32)
            .test(
                SAMPLES,
                SEED,
                |u| {
                    let p = equal_area_sphere_to_square(uniform_sphere(u));
                    (p[0], p[1])
                },
                |_, _| 1.0,
            )
            .assert_accepted("equal-area sphere to square");
    }
}
