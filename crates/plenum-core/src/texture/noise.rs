//! Perlin's gradient noise and the sums of it that procedural textures are made of.
//!
//! The noise is Perlin's "improved noise" (K. Perlin, "Improving Noise", SIGGRAPH 2002):
//! gradients from twelve cube-edge directions chosen by hashing the lattice point through a
//! permutation table, blended by the quintic 6t⁵ − 15t⁴ + 10t³. pbrt-v4 uses the same
//! noise, table and octave sums (pbrt-v4, Pharr, Jakob and Humphreys, section 10.6), so
//! its procedural textures look the same here. It is zero at every lattice point.

use crate::math::Vec3;

/// Perlin's permutation of 0..=255, from his reference implementation (2002); pbrt-v4's
/// `NoisePerm` is this table twice.
const PERMUTATION: [u8; 256] = [
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30, 69,
    142, 8, 99, 37, 240, 21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219,
    203, 117, 35, 11, 32, 57, 177, 33, 88, 237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175,
    74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231, 83, 111, 229, 122, 60, 211, 133, 230,
    220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25, 63, 161, 1, 216, 80, 73, 209, 76,
    132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86, 164, 100, 109, 198, 173,
    186, 3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212, 207, 206,
    59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170, 213, 119, 248, 152, 2, 44, 154, 163,
    70, 221, 153, 101, 155, 167, 43, 172, 9, 129, 22, 39, 253, 19, 98, 108, 110, 79, 113, 224, 232,
    178, 185, 112, 104, 218, 246, 97, 228, 251, 34, 242, 193, 238, 210, 144, 12, 191, 179, 162,
    241, 81, 51, 145, 235, 249, 14, 239, 107, 49, 192, 214, 31, 181, 199, 106, 157, 184, 84, 204,
    176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205, 93, 222, 114, 67, 29, 24, 72, 243, 141,
    128, 195, 78, 66, 215, 61, 156, 180,
];

#[inline]
fn perm(i: usize) -> usize {
    PERMUTATION[i & 255] as usize
}

/// The gradient at lattice point (x, y, z) dotted with the offset (dx, dy, dz) from it.
#[inline]
fn gradient(x: usize, y: usize, z: usize, d: [f64; 3]) -> f64 {
    let h = perm(perm(perm(x) + y) + z) & 15;
    let [dx, dy, dz] = d;
    let u = if h < 8 || h == 12 || h == 13 { dx } else { dy };
    let v = if h < 4 || h == 12 || h == 13 { dy } else { dz };
    (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
}

/// Perlin's quintic fade: zero first and second derivatives at 0 and 1.
#[inline]
fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

#[inline]
fn lerp(t: f64, a: f64, b: f64) -> f64 {
    a + t * (b - a)
}

/// Perlin noise at p: a smooth function in about [−1, 1], zero at integer points, with a
/// feature size of one unit.
pub fn noise(p: Vec3) -> f64 {
    // Coordinates too large for the lattice index wrap around (as pbrt-v4's do, at 2³⁰).
    let wrap = |x: f64| x % (1u64 << 30) as f64;
    let (x, y, z) = (wrap(p.x), wrap(p.y), wrap(p.z));
    let (fx, fy, fz) = (x.floor(), y.floor(), z.floor());
    let (dx, dy, dz) = (x - fx, y - fy, z - fz);
    // The table repeats every 256 lattice cells.
    let cell = |f: f64| (f as i64 & 255) as usize;
    let (ix, iy, iz) = (cell(fx), cell(fy), cell(fz));
    let g = |i: usize, j: usize, k: usize| {
        gradient(
            ix + i,
            iy + j,
            iz + k,
            [dx - i as f64, dy - j as f64, dz - k as f64],
        )
    };
    let (wx, wy, wz) = (fade(dx), fade(dy), fade(dz));
    let x00 = lerp(wx, g(0, 0, 0), g(1, 0, 0));
    let x10 = lerp(wx, g(0, 1, 0), g(1, 1, 0));
    let x01 = lerp(wx, g(0, 0, 1), g(1, 0, 1));
    let x11 = lerp(wx, g(0, 1, 1), g(1, 1, 1));
    lerp(wz, lerp(wy, x00, x10), lerp(wy, x01, x11))
}

/// The most octaves a sum takes: the 32nd's frequency, 1.99³¹ ≈ 2·10⁹, is where the noise
/// lattice wraps around.
pub const MAX_OCTAVES: u32 = 32;

/// Each octave's frequency over the one before: just under 2, so that the octaves' lattices
/// do not line up (pbrt-v4's 1.99).
const LACUNARITY: f64 = 1.99;

/// Fractional Brownian motion: `octaves` octaves of noise, the i-th at frequency 1.99ⁱ and
/// weight omegaⁱ.
///
/// pbrt-v4 drops the octaves finer than a pixel's footprint (from ray differentials);
/// Plenum has no differentials and filters by taking many samples per pixel, so every
/// octave is summed (what pbrt-v4 does where the footprint is small).
pub fn fbm(p: Vec3, omega: f64, octaves: u32) -> f64 {
    let (mut sum, mut lambda, mut o) = (0.0, 1.0, 1.0);
    for _ in 0..octaves {
        sum += o * noise(p * lambda);
        lambda *= LACUNARITY;
        o *= omega;
    }
    sum
}

/// Turbulence: fBm of the noise's magnitude. As in pbrt-v4, the octave beyond the last
/// counts as its mean magnitude, 0.2.
pub fn turbulence(p: Vec3, omega: f64, octaves: u32) -> f64 {
    let (mut sum, mut lambda, mut o) = (0.0, 1.0, 1.0);
    for _ in 0..octaves {
        sum += o * noise(p * lambda).abs();
        lambda *= LACUNARITY;
        o *= omega;
    }
    sum + o * 0.2
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_is_a_permutation() {
        let mut seen = [false; 256];
        PERMUTATION.iter().for_each(|&i| seen[i as usize] = true);
        assert!(seen.iter().all(|&s| s));
    }

    #[test]
    fn noise_is_zero_on_the_lattice_and_follows_its_gradients() {
        for p in [[0.0, 0.0, 0.0], [3.0, -7.0, 12.0], [255.0, 256.0, -1.0]] {
            let p = Vec3::new(p[0], p[1], p[2]);
            assert_eq!(noise(p), 0.0);
            // Near a lattice point the noise is linear: the gradient there, one of the
            // twelve (±1, ±1, 0)-like cube edges, dotted with the offset.
            let e = 1e-5;
            let d = Vec3::new(
                noise(p + Vec3::X * e) - noise(p - Vec3::X * e),
                noise(p + Vec3::Y * e) - noise(p - Vec3::Y * e),
                noise(p + Vec3::Z * e) - noise(p - Vec3::Z * e),
            ) / (2.0 * e);
            let rounded = [d.x.round(), d.y.round(), d.z.round()];
            assert!((d - Vec3::new(rounded[0], rounded[1], rounded[2])).length() < 1e-6);
            let zeros = rounded.iter().filter(|&&c| c == 0.0).count();
            assert_eq!(zeros, 1, "{d:?}");
            assert!(rounded.iter().all(|c| c.abs() <= 1.0));
        }
    }

    #[test]
    fn noise_repeats_every_256_cells_and_stays_in_range() {
        let mut lo: f64 = 0.0;
        let mut hi: f64 = 0.0;
        let mut sum = 0.0;
        let n = 40;
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let p = Vec3::new(i as f64, j as f64, k as f64) * 0.377 + Vec3::splat(0.01);
                    let v = noise(p);
                    assert!((v - noise(p + Vec3::new(256.0, -512.0, 256.0))).abs() < 1e-9);
                    lo = lo.min(v);
                    hi = hi.max(v);
                    sum += v;
                }
            }
        }
        assert!(
            lo > -1.05 && hi < 1.05 && lo < -0.5 && hi > 0.5,
            "{lo} {hi}"
        );
        // Its mean is zero (each gradient's opposite is as likely).
        assert!((sum / (n * n * n) as f64).abs() < 0.02);
    }

    /// Values of pbrt-v4's `Noise`, `FBm` and `Turbulence` (omega 0.5, 8 octaves, no
    /// differentials), printed by pbrt-v4's own noise.cpp (commit 5f7a606, single
    /// precision) built by hand; 1e-5 allows for its f32 arithmetic.
    #[test]
    fn noise_and_its_sums_match_pbrt_v4() {
        let cases: [([f32; 3], [f64; 3]); 5] = [
            ([0.3, 1.7, -2.2], [-0.473802865, -0.572995722, 0.711996555]),
            ([10.25, -3.5, 0.75], [0.275424004, 0.464208007, 0.539170742]),
            ([-0.6, 0.1, 100.9], [0.187448591, 0.087820828, 0.342629313]),
            ([2.5, 2.5, 2.5], [0.125, 0.202873275, 0.206291825]),
            ([0.5, 0.5, 0.5], [-0.125, -0.118037701, 0.188431874]),
        ];
        for (p, [n, f, t]) in cases {
            let p = Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
            let got = [noise(p), fbm(p, 0.5, 8), turbulence(p, 0.5, 8)];
            for (g, want) in got.into_iter().zip([n, f, t]) {
                assert!(
                    (g - want).abs() < 1e-5,
                    "at {p:?}: {got:?}, pbrt-v4 {n} {f} {t}"
                );
            }
        }
    }

    #[test]
    fn octave_sums_weigh_each_octave() {
        let p = Vec3::new(0.3, 1.7, -2.2);
        assert_eq!(fbm(p, 0.5, 1), noise(p));
        let two = noise(p) + 0.5 * noise(p * 1.99);
        assert!((fbm(p, 0.5, 2) - two).abs() < 1e-15);
        let t = noise(p).abs() + 0.5 * noise(p * 1.99).abs() + 0.25 * 0.2;
        assert!((turbulence(p, 0.5, 2) - t).abs() < 1e-15);
    }
}
