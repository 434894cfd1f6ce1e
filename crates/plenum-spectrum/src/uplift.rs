//! RGB to spectrum uplift after Jakob and Hanika 2019, "A Low-Dimensional Function Space for
//! Efficient Spectral Upsampling" (Computer Graphics Forum 38(2)): a reflectance is
//! s(c0 λ² + c1 λ + c2) with the sigmoid s(x) = ½ + x / (2 √(1 + x²)), its three coefficients
//! found by Gauss–Newton on the CIELAB difference between the target colour and the
//! spectrum's colour under the colour space's illuminant (D65 for sRGB).
//!
//! [`RgbSigmoid::fit`] solves per call; [`RgbToSpectrumTable`] holds solutions on the paper's
//! grid (the largest component `z` and the other two divided by it, `z` spaced by a doubled
//! smoothstep) and interpolates them trilinearly. The table is built lazily on first use, by
//! continuation along `z` from neighbouring solutions.

use std::sync::OnceLock;

use crate::cie::{cie_xyz, CIE_LAMBDA_MAX, CIE_LAMBDA_MIN, CIE_Y_INTEGRAL};
use crate::color::{linear_srgb_to_xyz, xyz_to_lab, XYZ_TO_SRGB};
use crate::data::illuminants::{ILLUM_D65, ILLUM_D65_START};

/// s(x) = ½ + x / (2 √(1 + x²)), the sigmoid of the uplift: (0, 1), with s(±∞) = 1 or 0.
#[inline]
pub fn sigmoid(x: f64) -> f64 {
    if x.is_infinite() {
        return if x > 0.0 { 1.0 } else { 0.0 };
    }
    0.5 + x / (2.0 * (1.0 + x * x).sqrt())
}

/// CIE D65 (relative spectral power, CIE 015:2018 table, linearly interpolated) scaled so that
/// its luminance ∫ D65 ȳ dλ / [`CIE_Y_INTEGRAL`] is 1 (the colour space's illuminant for the
/// illuminant uplift, as pbrt-v4 normalises `stdillum-D65`). `lambda` in nm; 0 outside
/// 300–830 nm.
pub fn d65_normalized(lambda: f64) -> f64 {
    static SCALE: OnceLock<f64> = OnceLock::new();
    let scale = *SCALE.get_or_init(|| {
        let y: f64 = (0..crate::cie::CIE_SAMPLES)
            .map(|i| {
                let l = CIE_LAMBDA_MIN + i as f64;
                d65_raw(l) * cie_xyz(l)[1]
            })
            .sum();
        CIE_Y_INTEGRAL / y
    });
    d65_raw(lambda) * scale
}

fn d65_raw(lambda: f64) -> f64 {
    uniform_lerp(&ILLUM_D65, ILLUM_D65_START, 5.0, lambda)
}

/// Linear interpolation in a table sampled every `step` nm from `start` nm; 0 outside.
fn uniform_lerp(table: &[f64], start: f64, step: f64, lambda: f64) -> f64 {
    let x = (lambda - start) / step;
    let last = (table.len() - 1) as f64;
    if !(0.0..=last).contains(&x) {
        return 0.0;
    }
    let i = (x as usize).min(table.len() - 2);
    let t = x - i as f64;
    table[i] + t * (table[i + 1] - table[i])
}

/// A reflectance-like spectrum s(c0 λ² + c1 λ + c2), λ in nm, values in (0, 1).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RgbSigmoid {
    /// Coefficient of λ², nm⁻².
    pub c0: f64,
    /// Coefficient of λ, nm⁻¹.
    pub c1: f64,
    /// Constant term.
    pub c2: f64,
}

/// Wavelengths are mapped to [0, 1] over 360–830 nm while fitting, which keeps the normal
/// equations well conditioned; coefficients are converted to nm afterwards.
const SPAN: f64 = CIE_LAMBDA_MAX - CIE_LAMBDA_MIN;

impl RgbSigmoid {
    /// The value at `lambda` nm, in (0, 1).
    #[inline]
    pub fn eval(&self, lambda: f64) -> f64 {
        sigmoid((self.c0 * lambda + self.c1) * lambda + self.c2)
    }

    /// [`Self::eval`] at each of `lambda`, the same values, written without branches so
    /// that the lanes are computed together.
    #[inline]
    pub fn eval_lanes<const N: usize>(&self, lambda: &[f64; N]) -> [f64; N] {
        std::array::from_fn(|i| {
            let x = (self.c0 * lambda[i] + self.c1) * lambda[i] + self.c2;
            let s = 0.5 + x / (2.0 * (1.0 + x * x).sqrt());
            // A constant of 0 or 1 has x = ∓∞, where the quotient is NaN.
            let limit = if x > 0.0 { 1.0 } else { 0.0 };
            if x.is_infinite() {
                limit
            } else {
                s
            }
        })
    }

    /// The spectrum of constant value `v` in [0, 1] (exact: s⁻¹(v) as c2).
    pub fn constant(v: f64) -> Self {
        let v = v.clamp(0.0, 1.0);
        let c2 = if v <= 0.0 {
            f64::NEG_INFINITY
        } else if v >= 1.0 {
            f64::INFINITY
        } else {
            (v - 0.5) / (v * (1.0 - v)).sqrt()
        };
        RgbSigmoid {
            c0: 0.0,
            c1: 0.0,
            c2,
        }
    }

    /// The largest value over 360–830 nm (the sigmoid is monotonic, so at an end or at the
    /// polynomial's vertex).
    pub fn max_value(&self) -> f64 {
        let mut m = self.eval(CIE_LAMBDA_MIN).max(self.eval(CIE_LAMBDA_MAX));
        if self.c0 != 0.0 {
            let v = -self.c1 / (2.0 * self.c0);
            if (CIE_LAMBDA_MIN..=CIE_LAMBDA_MAX).contains(&v) {
                m = m.max(self.eval(v));
            }
        }
        m
    }

    /// Coefficients of the polynomial in normalised wavelength t = (λ − 360) / 470 to
    /// coefficients in nm.
    fn from_normalized(c: [f64; 3]) -> Self {
        let (a, b) = (CIE_LAMBDA_MIN, SPAN);
        RgbSigmoid {
            c0: c[0] / (b * b),
            c1: c[1] / b - 2.0 * c[0] * a / (b * b),
            c2: c[0] * a * a / (b * b) - c[1] * a / b + c[2],
        }
    }

    fn to_normalized(self) -> [f64; 3] {
        let (a, b) = (CIE_LAMBDA_MIN, SPAN);
        [
            self.c0 * b * b,
            (self.c1 + 2.0 * self.c0 * a) * b,
            (self.c0 * a + self.c1) * a + self.c2,
        ]
    }

    /// The sigmoid spectrum whose linear-sRGB colour as a reflectance under D65 is `rgb`
    /// (components clamped to [0, 1]), by Gauss–Newton on the CIELAB residual, from the grey
    /// of the same mean and then along the line towards the target (a homotopy, so saturated
    /// colours converge). Exact up to the solver's tolerance (ΔE < 1e-6 where reachable);
    /// greys are solved in closed form.
    pub fn fit(rgb: [f64; 3]) -> RgbSigmoid {
        let rgb = rgb.map(|v| v.clamp(0.0, 1.0));
        if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
            return RgbSigmoid::constant(rgb[0]);
        }
        let q = quadrature();
        let mean = ((rgb[0] + rgb[1] + rgb[2]) / 3.0).clamp(0.02, 0.98);
        let mut c = RgbSigmoid::constant(mean).to_normalized();
        const STEPS: usize = 8;
        for k in 1..=STEPS {
            let t = k as f64 / STEPS as f64;
            let target = [0, 1, 2].map(|i| mean + t * (rgb[i] - mean));
            c = q
                .gauss_newton(c, target, if k == STEPS { 60 } else { 8 }, 1e-6)
                .0;
        }
        RgbSigmoid::from_normalized(c)
    }
}

/// The colour of a sigmoid reflectance under D65 is Σ_k w_k s(x(t_k)) over 5 nm bins, with
/// w_k the linear-sRGB matching functions times D65 summed at 1 nm over the bin: the same
/// integral as `Spectrum::to_rgb_reflectance`, with the sigmoid taken at the bin's centre.
struct Quadrature {
    t: Vec<f64>,
    w: Vec<[f64; 3]>,
    white_xyz: [f64; 3],
}

fn quadrature() -> &'static Quadrature {
    static Q: OnceLock<Quadrature> = OnceLock::new();
    Q.get_or_init(|| {
        const BIN: usize = 5;
        let mut t = Vec::new();
        let mut w = Vec::new();
        let mut norm = 0.0;
        let mut i = 0;
        while i < crate::cie::CIE_SAMPLES {
            let n = BIN.min(crate::cie::CIE_SAMPLES - i);
            let mut acc = [0.0; 3];
            for j in i..i + n {
                let l = CIE_LAMBDA_MIN + j as f64;
                let xyz = cie_xyz(l);
                let d = d65_normalized(l);
                norm += d * xyz[1];
                let rgb = crate::color::mul3(&XYZ_TO_SRGB, xyz);
                for c in 0..3 {
                    acc[c] += rgb[c] * d;
                }
            }
            let centre = CIE_LAMBDA_MIN + i as f64 + (n - 1) as f64 / 2.0;
            t.push((centre - CIE_LAMBDA_MIN) / SPAN);
            w.push(acc);
            i += n;
        }
        for wk in &mut w {
            for v in wk.iter_mut() {
                *v /= norm;
            }
        }
        Quadrature {
            t,
            w,
            white_xyz: linear_srgb_to_xyz([1.0; 3]),
        }
    })
}

impl Quadrature {
    /// Colour of the normalised-coefficient sigmoid and its Jacobian d rgb / d c.
    fn eval(&self, c: [f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
        let mut rgb = [0.0; 3];
        let mut jac = [[0.0; 3]; 3];
        for (&t, w) in self.t.iter().zip(&self.w) {
            let x = (c[0] * t + c[1]) * t + c[2];
            let r = 1.0 / (1.0 + x * x).sqrt();
            let s = 0.5 + 0.5 * x * r;
            let ds = 0.5 * r * r * r;
            let dx = [t * t, t, 1.0];
            for i in 0..3 {
                rgb[i] += w[i] * s;
                for j in 0..3 {
                    jac[i][j] += w[i] * ds * dx[j];
                }
            }
        }
        (rgb, jac)
    }

    fn lab(&self, rgb: [f64; 3]) -> [f64; 3] {
        xyz_to_lab(linear_srgb_to_xyz(rgb), self.white_xyz)
    }

    /// Gauss–Newton iterations (with step halving when the residual grows) from `c` towards
    /// the colour `target`; returns the coefficients and the final CIELAB residual norm.
    fn gauss_newton(
        &self,
        mut c: [f64; 3],
        target: [f64; 3],
        iterations: usize,
        tolerance: f64,
    ) -> ([f64; 3], f64) {
        let goal = self.lab(target);
        let residual = |rgb: [f64; 3]| {
            let lab = self.lab(rgb);
            [lab[0] - goal[0], lab[1] - goal[1], lab[2] - goal[2]]
        };
        let norm = |r: [f64; 3]| (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
        let (mut rgb, mut jac) = self.eval(c);
        let mut r = residual(rgb);
        let mut err = norm(r);
        for _ in 0..iterations {
            if err < tolerance {
                break;
            }
            // d lab / d rgb by central differences (cheap: no spectral sums), times d rgb / d c.
            let mut dlab = [[0.0; 3]; 3];
            const H: f64 = 1e-6;
            for j in 0..3 {
                let (mut p, mut m) = (rgb, rgb);
                p[j] += H;
                m[j] -= H;
                let (lp, lm) = (self.lab(p), self.lab(m));
                for i in 0..3 {
                    dlab[i][j] = (lp[i] - lm[i]) / (2.0 * H);
                }
            }
            let mut j = [[0.0; 3]; 3];
            for i in 0..3 {
                for k in 0..3 {
                    j[i][k] = (0..3).map(|m| dlab[i][m] * jac[m][k]).sum();
                }
            }
            let Some(delta) = solve3(j, r.map(|v| -v)) else {
                break;
            };
            let mut step = 1.0;
            let mut improved = false;
            for _ in 0..12 {
                let cn = [0, 1, 2].map(|i| c[i] + step * delta[i]);
                let (rgb_n, jac_n) = self.eval(cn);
                let r_n = residual(rgb_n);
                let e_n = norm(r_n);
                if e_n.is_finite() && e_n < err {
                    (c, rgb, jac, r, err) = (cn, rgb_n, jac_n, r_n, e_n);
                    improved = true;
                    break;
                }
                step *= 0.5;
            }
            if !improved {
                break;
            }
        }
        (c, err)
    }
}

/// Solves the 3×3 system a x = b by Gaussian elimination with partial pivoting; `None` when
/// singular.
fn solve3(mut a: [[f64; 3]; 3], mut b: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let p = (col..3).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[p][col].abs() < 1e-300 || !a[p][col].is_finite() {
            return None;
        }
        a.swap(col, p);
        b.swap(col, p);
        for row in col + 1..3 {
            let f = a[row][col] / a[col][col];
            let pivot = a[col];
            for (v, p) in a[row].iter_mut().zip(pivot).skip(col) {
                *v -= f * p;
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let s: f64 = (row + 1..3).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Solves one plane of the table (`c`: the largest component) into `part`, [z][y][x].
fn build_plane(
    q: &Quadrature,
    z_nodes: &[f64],
    res: usize,
    start: usize,
    c: usize,
    part: &mut [[f64; 3]],
) {
    let mut column_start: Option<[f64; 3]> = None;
    for yi in 0..res {
        let mut row_start = column_start;
        for xi in 0..res {
            let x = xi as f64 / (res - 1) as f64;
            let y = yi as f64 / (res - 1) as f64;
            let rgb_at = |z: f64| {
                let mut rgb = [0.0; 3];
                rgb[c] = z;
                rgb[(c + 1) % 3] = x * z;
                rgb[(c + 2) % 3] = y * z;
                rgb
            };
            let solve = |guess: Option<[f64; 3]>, rgb: [f64; 3]| {
                if let Some(g) = guess {
                    let (sol, err) = q.gauss_newton(g, rgb, 20, TABLE_TOLERANCE);
                    if err < 1e-3 {
                        return sol;
                    }
                }
                RgbSigmoid::fit(rgb).to_normalized()
            };
            let idx = |zi: usize| (zi * res + yi) * res + xi;
            let first = solve(row_start, rgb_at(z_nodes[start]));
            if xi == 0 {
                column_start = Some(first);
            }
            row_start = Some(first);
            part[idx(start)] = first;
            let mut guess = first;
            for zi in start + 1..res {
                guess = solve(Some(guess), rgb_at(z_nodes[zi]));
                part[idx(zi)] = guess;
            }
            guess = first;
            for zi in (1..start).rev() {
                guess = solve(Some(guess), rgb_at(z_nodes[zi]));
                part[idx(zi)] = guess;
            }
            // z = 0 is black, which no finite sigmoid reaches: reuse the next node's
            // (nearly black) solution.
            part[idx(0)] = part[idx(1)];
        }
    }
}

/// Sigmoid coefficients tabulated over RGB in [0, 1]³ (Jakob and Hanika's parametrisation):
/// for each choice of largest component, a `res`³ grid over that component z (at
/// smoothstep(smoothstep(i/(res−1))), denser near 0 and 1) and the other two components
/// divided by z (uniform), looked up with trilinear interpolation.
pub struct RgbToSpectrumTable {
    res: usize,
    z_nodes: Vec<f64>,
    /// [max component][z][y][x] → coefficients in nm.
    coeffs: Vec<[f64; 3]>,
}

/// CIELAB residual at which a table node's solve stops (ΔE 1e-4, far below visibility).
const TABLE_TOLERANCE: f64 = 1e-4;

/// The resolution of [`RgbToSpectrumTable::srgb`]: build time and accuracy measured in the
/// benchmark `benches/uplift_table.rs` (see docs/spectra.md).
pub const SRGB_TABLE_RES: usize = 24;

impl RgbToSpectrumTable {
    /// The table for linear sRGB reflectances under D65, at [`SRGB_TABLE_RES`]: built when
    /// the crate is (its build script runs [`RgbToSpectrumTable::build`], 0.2–0.3 s of
    /// solves that every spectral render paid at its start before), read on first use and
    /// shared.
    pub fn srgb() -> &'static RgbToSpectrumTable {
        static TABLE: OnceLock<RgbToSpectrumTable> = OnceLock::new();
        TABLE.get_or_init(|| {
            RgbToSpectrumTable::from_bytes(SRGB_TABLE_RES, crate::SRGB_TABLE)
                .expect("the build script's table, of SRGB_TABLE_RES")
        })
    }

    /// The table as bytes: its z nodes, then its coefficients, little-endian f64.
    pub fn to_bytes(&self) -> Vec<u8> {
        let values = self.z_nodes.iter().chain(self.coeffs.iter().flatten());
        values.flat_map(|v| v.to_le_bytes()).collect()
    }

    /// The table of `res` nodes per axis that [`RgbToSpectrumTable::to_bytes`] wrote; `None`
    /// where `bytes` is not one.
    pub fn from_bytes(res: usize, bytes: &[u8]) -> Option<RgbToSpectrumTable> {
        let count = res + 9 * res * res * res;
        if res < 3 || bytes.len() != 8 * count {
            return None;
        }
        let values: Vec<f64> = bytes
            .chunks_exact(8)
            .map(|b| f64::from_le_bytes(b.try_into().unwrap_or_default()))
            .collect();
        let (z_nodes, coeffs) = values.split_at(res);
        Some(RgbToSpectrumTable {
            res,
            z_nodes: z_nodes.to_vec(),
            coeffs: coeffs.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        })
    }

    /// Builds a table of `res` ≥ 3 nodes per axis (3·res³ solves). Each column of constant
    /// (x, y) is solved from z = res/5 upwards and then downwards, each solve starting from
    /// its neighbour's solution; the first of each column starts from the neighbouring
    /// column's, or from a full [`RgbSigmoid::fit`].
    pub fn build(res: usize) -> RgbToSpectrumTable {
        assert!(res >= 3, "table resolution below 3");
        let smoothstep = |x: f64| x * x * (3.0 - 2.0 * x);
        let z_nodes: Vec<f64> = (0..res)
            .map(|i| smoothstep(smoothstep(i as f64 / (res - 1) as f64)))
            .collect();
        let q = quadrature();
        let start = res / 5;
        let plane = res * res * res;
        let mut coeffs = vec![[0.0; 3]; 3 * plane];
        // The three planes (which component is largest) are independent: one thread each.
        // Each plane's solves run in a fixed order, so the table is the same every time.
        std::thread::scope(|scope| {
            for (c, part) in coeffs.chunks_mut(plane).enumerate() {
                let (q, z_nodes) = (&q, &z_nodes);
                scope.spawn(move || build_plane(q, z_nodes, res, start, c, part));
            }
        });
        for v in &mut coeffs {
            let s = RgbSigmoid::from_normalized(*v);
            *v = [s.c0, s.c1, s.c2];
        }
        RgbToSpectrumTable {
            res,
            z_nodes,
            coeffs,
        }
    }

    /// The table's nodes per axis.
    pub fn resolution(&self) -> usize {
        self.res
    }

    /// The sigmoid spectrum for the reflectance `rgb` (clamped to [0, 1]), interpolated from
    /// the table; greys are exact.
    pub fn lookup(&self, rgb: [f64; 3]) -> RgbSigmoid {
        let rgb = rgb.map(|v| v.clamp(0.0, 1.0));
        if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
            return RgbSigmoid::constant(rgb[0]);
        }
        let c = if rgb[0] >= rgb[1] && rgb[0] >= rgb[2] {
            0
        } else if rgb[1] >= rgb[2] {
            1
        } else {
            2
        };
        let z = rgb[c];
        let n = (self.res - 1) as f64;
        let x = rgb[(c + 1) % 3] / z * n;
        let y = rgb[(c + 2) % 3] / z * n;
        let xi = (x as usize).min(self.res - 2);
        let yi = (y as usize).min(self.res - 2);
        let zi = self
            .z_nodes
            .partition_point(|&v| v <= z)
            .saturating_sub(1)
            .min(self.res - 2);
        let (tx, ty) = (x - xi as f64, y - yi as f64);
        let tz = (z - self.z_nodes[zi]) / (self.z_nodes[zi + 1] - self.z_nodes[zi]);
        let at = |dz: usize, dy: usize, dx: usize| {
            self.coeffs[((c * self.res + zi + dz) * self.res + yi + dy) * self.res + xi + dx]
        };
        let mut out = [0.0; 3];
        for (dz, wz) in [(0, 1.0 - tz), (1, tz)] {
            for (dy, wy) in [(0, 1.0 - ty), (1, ty)] {
                for (dx, wx) in [(0, 1.0 - tx), (1, tx)] {
                    let w = wz * wy * wx;
                    let v = at(dz, dy, dx);
                    for i in 0..3 {
                        out[i] += w * v[i];
                    }
                }
            }
        }
        RgbSigmoid {
            c0: out[0],
            c1: out[1],
            c2: out[2],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::reflectance_to_rgb;

    /// PCG32 (O'Neill 2014), enough for reproducible test colours.
    pub(crate) struct Pcg(u64);
    impl Pcg {
        pub(crate) fn next_f64(&mut self) -> f64 {
            let old = self.0;
            self.0 = old
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
            let rot = (old >> 59) as u32;
            xorshifted.rotate_right(rot) as f64 / 4294967296.0
        }
    }

    fn max_err(a: [f64; 3], b: [f64; 3]) -> f64 {
        (0..3).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max)
    }

    #[test]
    fn lanes_evaluate_as_one_at_a_time() {
        let lambda = [360.0, 451.5, 600.25, 830.0];
        for s in [
            RgbSigmoid::constant(0.0),
            RgbSigmoid::constant(1.0),
            RgbSigmoid::constant(0.3),
            RgbSigmoid {
                c0: 1e-4,
                c1: -0.1,
                c2: 20.0,
            },
        ] {
            assert_eq!(s.eval_lanes(&lambda), lambda.map(|l| s.eval(l)), "{s:?}");
        }
    }

    #[test]
    fn sigmoid_limits() {
        assert_eq!(sigmoid(0.0), 0.5);
        assert_eq!(sigmoid(f64::INFINITY), 1.0);
        assert_eq!(sigmoid(f64::NEG_INFINITY), 0.0);
        assert!((RgbSigmoid::constant(0.3).eval(500.0) - 0.3).abs() < 1e-12);
    }

    #[test]
    fn normalized_coefficients_round_trip() {
        let s = RgbSigmoid::from_normalized([3.0, -2.0, 0.5]);
        let t: f64 = (600.0 - CIE_LAMBDA_MIN) / SPAN;
        let x = (3.0 * t - 2.0) * t + 0.5;
        assert!((s.eval(600.0) - sigmoid(x)).abs() < 1e-12);
        let back = s.to_normalized();
        assert!((back[0] - 3.0).abs() < 1e-9 && (back[1] + 2.0).abs() < 1e-9);
    }

    #[test]
    fn fit_round_trips_100_random_albedos() {
        let mut rng = Pcg(0x853c49e6748fea9b);
        let mut worst = 0.0f64;
        for _ in 0..100 {
            let rgb = [rng.next_f64(), rng.next_f64(), rng.next_f64()];
            let s = RgbSigmoid::fit(rgb);
            let back = reflectance_to_rgb(|l| s.eval(l));
            worst = worst.max(max_err(rgb, back));
        }
        assert!(worst < 0.01, "worst {worst}");
    }

    #[test]
    fn fit_saturated_primaries() {
        for rgb in [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 0.0],
            [0.9, 0.1, 0.6],
        ] {
            let s = RgbSigmoid::fit(rgb);
            let back = reflectance_to_rgb(|l| s.eval(l));
            // Pure primaries lie outside what a bounded reflectance can show exactly; a few
            // hundredths is what the sigmoid space reaches there.
            assert!(max_err(rgb, back) < 0.05, "{rgb:?} → {back:?}");
        }
    }

    #[test]
    fn table_round_trips_100_random_albedos() {
        let table = RgbToSpectrumTable::srgb();
        let mut rng = Pcg(0xda3e39cb94b95bdb);
        let mut worst = 0.0f64;
        for _ in 0..100 {
            let rgb = [rng.next_f64(), rng.next_f64(), rng.next_f64()];
            let s = table.lookup(rgb);
            let back = reflectance_to_rgb(|l| s.eval(l));
            worst = worst.max(max_err(rgb, back));
        }
        assert!(worst < 0.01, "worst {worst}");
    }

    /// The table the build script made is the one this build of the code makes, value for
    /// value; bytes of another size are refused.
    #[test]
    fn the_built_table_is_the_table_the_code_builds() {
        let built = RgbToSpectrumTable::srgb();
        let fresh = RgbToSpectrumTable::build(SRGB_TABLE_RES);
        assert_eq!(built.z_nodes, fresh.z_nodes);
        assert_eq!(built.coeffs, fresh.coeffs);
        assert!(RgbToSpectrumTable::from_bytes(SRGB_TABLE_RES, &fresh.to_bytes()[8..]).is_none());
        assert!(RgbToSpectrumTable::from_bytes(SRGB_TABLE_RES + 1, &fresh.to_bytes()).is_none());
    }
}
