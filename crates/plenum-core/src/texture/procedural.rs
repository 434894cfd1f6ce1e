//! pbrt-v4's procedural patterns on Perlin noise: fBm, wrinkled, windy, marble and polka
//! dots (pbrt-v4, section 10.6). Plenum sums every octave (see [`noise::fbm`]).

use super::noise::{self, fbm, turbulence};
use super::Noise;
use crate::color::Color;
use crate::math::Vec3;

/// The control points of pbrt-v4's marble spline: greys and one dark blue vein.
const MARBLE: [[f64; 3]; 9] = [
    [0.58, 0.58, 0.6],
    [0.58, 0.58, 0.6],
    [0.58, 0.58, 0.6],
    [0.5, 0.5, 0.5],
    [0.6, 0.59, 0.58],
    [0.58, 0.58, 0.6],
    [0.58, 0.58, 0.6],
    [0.2, 0.2, 0.33],
    [0.58, 0.58, 0.6],
];

impl Noise {
    /// The pattern at p, in the texture's space.
    pub fn evaluate(&self, p: Vec3) -> Color {
        match *self {
            Noise::Fbm { omega, octaves } => Color::gray(fbm(p, omega, octaves)),
            Noise::Wrinkled { omega, octaves } => Color::gray(turbulence(p, omega, octaves)),
            Noise::Windy => {
                let strength = fbm(p * 0.1, 0.5, 3);
                let height = fbm(p, 0.5, 6);
                Color::gray(strength.abs() * height)
            }
            Noise::Marble {
                omega,
                octaves,
                scale,
                variation,
            } => {
                let p = p * scale;
                let marble = p.y + variation * fbm(p, omega, octaves);
                marble_colour(0.5 + 0.5 * marble.sin())
            }
        }
    }

    /// An upper bound of the pattern's channels.
    pub fn max_value(&self) -> f64 {
        let octaves_sum = |omega: f64, octaves: u32| {
            (0..octaves)
                .map(|i| omega.abs().powi(i as i32))
                .sum::<f64>()
        };
        // Perlin noise stays within about ±1.04.
        let n = 1.04;
        match *self {
            Noise::Fbm { omega, octaves } => n * octaves_sum(omega, octaves),
            Noise::Wrinkled { omega, octaves } => {
                n * octaves_sum(omega, octaves) + 0.2 * omega.abs().powi(octaves as i32)
            }
            Noise::Windy => n * n * octaves_sum(0.5, 3) * octaves_sum(0.5, 6),
            Noise::Marble { .. } => 1.5 * 0.6,
        }
    }

    /// The pattern's mean over a 16³ lattice of points spaced 0.37 apart (about six noise
    /// cells a side): an estimate.
    pub fn average(&self) -> Color {
        let n = 16;
        let mut sum = Color::BLACK;
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let p = Vec3::new(i as f64, j as f64, k as f64) * 0.37 + Vec3::splat(0.05);
                    sum = sum + self.evaluate(p);
                }
            }
        }
        sum / (n * n * n) as f64
    }
}

/// The marble spline at t ∈ [0, 1]: six cubic Bézier segments over the control points,
/// times 1.5 (as pbrt-v4 brightens it).
fn marble_colour(t: f64) -> Color {
    let segments = MARBLE.len() - 3;
    let first = ((t * segments as f64).floor().max(0.0) as usize).min(segments - 1);
    let t = t * segments as f64 - first as f64;
    let s = 1.0 - t;
    let w = [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t];
    let c = |k: usize| (0..4).map(|i| w[i] * MARBLE[first + i][k]).sum::<f64>() * 1.5;
    Color::new(c(0), c(1), c(2))
}

/// The share of the plane polka dots cover: the share of cells with a dot (over the
/// noise's period of 256 × 256 cells) times a dot's area (each dot lies inside its cell).
pub(super) fn polka_dot_cover() -> f64 {
    let cells = (0..256)
        .flat_map(|s| (0..256).map(move |t| (s, t)))
        .filter(|&(s, t)| noise::noise(Vec3::new(s as f64 + 0.5, t as f64 + 0.5, 0.5)) > 0.0)
        .count();
    cells as f64 / (256.0 * 256.0) * std::f64::consts::PI * 0.35 * 0.35
}

/// Whether (s, t) lies in a polka dot: cells of side 1 centred on integer points; in the
/// cells where noise is positive, a dot of radius 0.35 whose centre noise moves by up to
/// 0.15 along each axis (pbrt-v4's `InsidePolkaDot`).
pub(super) fn in_polka_dot(st: [f64; 2]) -> bool {
    let (s_cell, t_cell) = ((st[0] + 0.5).floor(), (st[1] + 0.5).floor());
    let noise2 = |s: f64, t: f64| noise::noise(Vec3::new(s, t, 0.5));
    if noise2(s_cell + 0.5, t_cell + 0.5) <= 0.0 {
        return false;
    }
    let radius = 0.35;
    let max_shift = 0.5 - radius;
    let s_centre = s_cell + max_shift * noise2(s_cell + 1.5, t_cell + 2.8);
    let t_centre = t_cell + max_shift * noise2(s_cell + 4.5, t_cell + 9.8);
    let (ds, dt) = (st[0] - s_centre, st[1] - t_centre);
    ds * ds + dt * dt < radius * radius
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_marble_spline_passes_through_its_ends() {
        // t = 0: the first control point; t = 1: the last segment's end point.
        let c0 = marble_colour(0.0);
        assert!((c0.r - 0.87).abs() < 1e-12 && (c0.b - 0.9).abs() < 1e-12);
        let c1 = marble_colour(1.0);
        assert!((c1.r - 0.87).abs() < 1e-12);
        // Each value is a convex mix of four control points (times 1.5).
        for i in 0..=600 {
            let c = marble_colour(i as f64 / 600.0);
            assert!(c.r >= 0.3 - 1e-12 && c.r <= 0.9 + 1e-12, "{c:?}");
            assert!(c.b >= 0.495 - 1e-12 && c.b <= 0.9 + 1e-12, "{c:?}");
        }
    }

    #[test]
    fn polka_dots_are_round_and_cover_their_share() {
        // Over many cells, sampled 100 times each, the dots cover what `polka_dot_cover`
        // says (1 %).
        let n = 600;
        let mut inside = 0;
        for i in 0..n {
            for j in 0..n {
                let st = [(i as f64 + 0.5) * 0.1 - 3.0, (j as f64 + 0.5) * 0.1 + 7.0];
                inside += in_polka_dot(st) as usize;
            }
        }
        let covered = inside as f64 / (n * n) as f64;
        let cover = polka_dot_cover();
        assert!((covered - cover).abs() < 0.01, "{covered} against {cover}");
        assert!(cover > 0.05 && cover < std::f64::consts::PI * 0.35 * 0.35);
        // A cell with a dot: its centre (within 0.15 of the cell's centre) is inside, points
        // 0.49 away along s are outside; a cell without one has none.
        let has_dot = |c: f64| noise::noise(Vec3::new(c + 0.5, 0.5, 0.5)) > 0.0;
        let cell = (0..40).find(|&c| has_dot(c as f64)).unwrap() as f64;
        assert!(in_polka_dot([cell, 0.0]));
        assert!(!in_polka_dot([cell + 0.49, 0.0]));
        assert!(!in_polka_dot([cell - 0.49, 0.0]));
        let empty = (0..40).find(|&c| !has_dot(c as f64)).unwrap() as f64;
        assert!(!in_polka_dot([empty, 0.0]));
    }

    #[test]
    fn the_patterns_are_built_as_pbrt_builds_them() {
        let p = Vec3::new(0.31, -1.2, 2.7);
        let windy = Noise::Windy.evaluate(p).r;
        assert!((windy - fbm(p * 0.1, 0.5, 3).abs() * fbm(p, 0.5, 6)).abs() < 1e-15);
        let marble = Noise::Marble {
            omega: 0.5,
            octaves: 8,
            scale: 2.0,
            variation: 0.2,
        };
        let q = p * 2.0;
        let t = 0.5 + 0.5 * (q.y + 0.2 * fbm(q, 0.5, 8)).sin();
        assert_eq!(marble.evaluate(p), marble_colour(t));
        // Bounds hold where the patterns are sampled.
        for pattern in [
            Noise::Fbm {
                omega: 0.5,
                octaves: 8,
            },
            Noise::Wrinkled {
                omega: 0.5,
                octaves: 8,
            },
            Noise::Windy,
            marble,
        ] {
            for i in 0..2000 {
                let x = i as f64 * 0.173;
                let v = pattern.evaluate(Vec3::new(x, x * 0.71 - 3.0, x * 0.37 + 1.0));
                assert!(v.r.abs() <= pattern.max_value(), "{pattern:?}");
            }
        }
    }
}
