//! Objects that move while the shutter is open: a pose at time 0 and a pose at time 1,
//! interpolated in between.
//!
//! Each pose (an affine matrix M) is split as M = T·R·S (Shoemake and Duff 1992): a
//! translation T, a rotation R (a unit quaternion) and a symmetric stretch S, by polar
//! decomposition. Between the poses T and S are interpolated linearly and R by spherical
//! linear interpolation (slerp), so a spinning object turns at a constant rate about a fixed
//! axis instead of shrinking through the straight line between two matrices.

use super::{Bounds3, Matrix4, Transform, Vec3};

/// A unit quaternion w + (x, y, z)·(i, j, k).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Quaternion {
    w: f64,
    v: Vec3,
}

impl Quaternion {
    fn dot(self, o: Quaternion) -> f64 {
        self.w * o.w + self.v.dot(o.v)
    }

    fn scaled(self, s: f64) -> Quaternion {
        Quaternion {
            w: self.w * s,
            v: self.v * s,
        }
    }

    fn plus(self, o: Quaternion) -> Quaternion {
        Quaternion {
            w: self.w + o.w,
            v: self.v + o.v,
        }
    }

    fn normalized(self) -> Quaternion {
        self.scaled(1.0 / self.dot(self).sqrt())
    }

    /// The quaternion of a rotation matrix (the upper 3 × 3 of `m`), by the largest of the
    /// four candidate components so that no division is by a small number.
    fn from_rotation(m: &[[f64; 4]; 4]) -> Quaternion {
        let trace = m[0][0] + m[1][1] + m[2][2];
        let q = if trace > 0.0 {
            let s = (trace + 1.0).sqrt() * 2.0;
            Quaternion {
                w: 0.25 * s,
                v: Vec3::new(
                    (m[2][1] - m[1][2]) / s,
                    (m[0][2] - m[2][0]) / s,
                    (m[1][0] - m[0][1]) / s,
                ),
            }
        } else if m[0][0] > m[1][1] && m[0][0] > m[2][2] {
            let s = (1.0 + m[0][0] - m[1][1] - m[2][2]).sqrt() * 2.0;
            Quaternion {
                w: (m[2][1] - m[1][2]) / s,
                v: Vec3::new(0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s),
            }
        } else if m[1][1] > m[2][2] {
            let s = (1.0 + m[1][1] - m[0][0] - m[2][2]).sqrt() * 2.0;
            Quaternion {
                w: (m[0][2] - m[2][0]) / s,
                v: Vec3::new((m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s),
            }
        } else {
            let s = (1.0 + m[2][2] - m[0][0] - m[1][1]).sqrt() * 2.0;
            Quaternion {
                w: (m[1][0] - m[0][1]) / s,
                v: Vec3::new((m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s),
            }
        };
        q.normalized()
    }

    /// The rotation matrix, as rows of a 3 × 3.
    fn to_rotation(self) -> [[f64; 3]; 3] {
        let (w, x, y, z) = (self.w, self.v.x, self.v.y, self.v.z);
        [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - w * z),
                2.0 * (x * z + w * y),
            ],
            [
                2.0 * (x * y + w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - w * x),
            ],
            [
                2.0 * (x * z - w * y),
                2.0 * (y * z + w * x),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ]
    }

    /// Spherical linear interpolation from `self` (t = 0) to `o` (t = 1), the short way.
    fn slerp(self, o: Quaternion, t: f64) -> Quaternion {
        let cos = self.dot(o);
        let (o, cos) = if cos < 0.0 {
            (o.scaled(-1.0), -cos)
        } else {
            (o, cos)
        };
        if cos > 0.9995 {
            // Nearly equal: the straight line, renormalised, is as good and stays finite.
            return self.scaled(1.0 - t).plus(o.scaled(t)).normalized();
        }
        let theta = cos.clamp(-1.0, 1.0).acos();
        let (a, b) = (((1.0 - t) * theta).sin(), (t * theta).sin());
        self.scaled(a).plus(o.scaled(b)).scaled(1.0 / theta.sin())
    }

    /// The angle of the rotation taking `self` to `o`, in radians (0 to π).
    fn angle_to(self, o: Quaternion) -> f64 {
        2.0 * self.dot(o).abs().clamp(0.0, 1.0).acos()
    }
}

/// One pose: M = T·R·S.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Pose {
    translation: Vec3,
    rotation: Quaternion,
    stretch: [[f64; 3]; 3],
}

impl Pose {
    /// Polar decomposition of the linear part by Higham's iteration Q ← (Q + Q⁻ᵀ)/2, which
    /// converges to the nearest orthogonal matrix; S = Qᵀ·A. A reflection (det < 0) stays in
    /// S, so R is always a rotation.
    fn decompose(t: &Transform) -> Pose {
        let m = &t.matrix.0;
        let a = [
            [m[0][0], m[0][1], m[0][2]],
            [m[1][0], m[1][1], m[1][2]],
            [m[2][0], m[2][1], m[2][2]],
        ];
        let flip = if det3(&a) < 0.0 { -1.0 } else { 1.0 };
        let mut q = a.map(|row| row.map(|v| v * flip));
        for _ in 0..100 {
            let Some(inv) = inverse3(&q) else { break };
            let mut next = q;
            let mut change = 0.0f64;
            for i in 0..3 {
                for j in 0..3 {
                    next[i][j] = 0.5 * (q[i][j] + inv[j][i]);
                    change = change.max((next[i][j] - q[i][j]).abs());
                }
            }
            q = next;
            if change < 1e-15 {
                break;
            }
        }
        let mut stretch = [[0.0; 3]; 3];
        for (i, row) in stretch.iter_mut().enumerate() {
            for (j, s) in row.iter_mut().enumerate() {
                *s = (0..3).map(|k| q[k][i] * a[k][j]).sum();
            }
        }
        let mut rotation4 = [[0.0; 4]; 4];
        for i in 0..3 {
            rotation4[i][..3].copy_from_slice(&q[i]);
        }
        Pose {
            translation: Vec3::new(m[0][3], m[1][3], m[2][3]),
            rotation: Quaternion::from_rotation(&rotation4),
            stretch,
        }
    }
}

/// An object's motion between its pose at time 0 and its pose at time 1.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    open: Pose,
    close: Pose,
    /// The poses themselves, returned exactly at times 0 and 1.
    open_transform: Transform,
    close_transform: Transform,
}

/// Times at which the swept bounds are taken; the gaps between are padded by a bound on
/// the path's curvature.
const BOUND_STEPS: usize = 32;

impl Motion {
    pub fn new(open: &Transform, close: &Transform) -> Motion {
        Motion {
            open: Pose::decompose(open),
            close: Pose::decompose(close),
            open_transform: *open,
            close_transform: *close,
        }
    }

    /// The object-to-world transform at `time`, clamped to [0, 1].
    pub fn at(&self, time: f64) -> Transform {
        if time <= 0.0 {
            return self.open_transform;
        }
        if time >= 1.0 {
            return self.close_transform;
        }
        let (a, b) = (&self.open, &self.close);
        let r = a.rotation.slerp(b.rotation, time).to_rotation();
        let t = a.translation + (b.translation - a.translation) * time;
        let mut m = Matrix4::IDENTITY;
        for (row, r_row) in m.0.iter_mut().zip(&r) {
            for (j, m_ij) in row.iter_mut().take(3).enumerate() {
                *m_ij = (0..3)
                    .map(|k| {
                        let s = a.stretch[k][j] + (b.stretch[k][j] - a.stretch[k][j]) * time;
                        r_row[k] * s
                    })
                    .sum();
            }
        }
        m.0[0][3] = t.x;
        m.0[1][3] = t.y;
        m.0[2][3] = t.z;
        // A pose between two invertible ones can only be singular if the stretch passes
        // through zero (a mirror turning inside out); fall back to the nearer end.
        Transform::from_matrix(m).unwrap_or(if time < 0.5 {
            self.open_transform
        } else {
            self.close_transform
        })
    }

    /// World bounds of object-space box `b` over the whole motion. The box's corners are
    /// moved to BOUND_STEPS + 1 times; between two, a corner's path p(t) = R(t)·S(t)·c + T(t)
    /// strays from the straight chord by at most Δt²/8 · max|p''|, and
    /// |p''| ≤ θ²·max|S·c| + 2θ·|ΔS·c| (θ the total rotation angle), so that much padding
    /// makes the bounds conservative.
    pub fn bounds(&self, b: &Bounds3) -> Bounds3 {
        let mut out = Bounds3::default();
        for k in 0..=BOUND_STEPS {
            let t = self.at(k as f64 / BOUND_STEPS as f64);
            for c in b.corners() {
                out = out.union_point(t.point(c));
            }
        }
        let theta = self.open.rotation.angle_to(self.close.rotation);
        let apply = |s: &[[f64; 3]; 3], c: Vec3| {
            Vec3::new(
                s[0][0] * c.x + s[0][1] * c.y + s[0][2] * c.z,
                s[1][0] * c.x + s[1][1] * c.y + s[1][2] * c.z,
                s[2][0] * c.x + s[2][1] * c.y + s[2][2] * c.z,
            )
        };
        let curvature = b
            .corners()
            .iter()
            .map(|&c| {
                let (s0, s1) = (apply(&self.open.stretch, c), apply(&self.close.stretch, c));
                theta * theta * s0.length().max(s1.length()) + 2.0 * theta * (s1 - s0).length()
            })
            .fold(0.0, f64::max);
        let dt = 1.0 / BOUND_STEPS as f64;
        let pad = dt * dt / 8.0 * curvature * (1.0 + 1e-9) + 1e-12 * out.diagonal().length();
        out.expanded(pad)
    }
}

fn det3(a: &[[f64; 3]; 3]) -> f64 {
    a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
        - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
        + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
}

fn inverse3(a: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let det = det3(a);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let c = |i: usize, j: usize| {
        let (r0, r1) = ((i + 1) % 3, (i + 2) % 3);
        let (c0, c1) = ((j + 1) % 3, (j + 2) % 3);
        a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0]
    };
    let mut inv = [[0.0; 3]; 3];
    for (i, row) in inv.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            // The cyclic cofactor already carries its sign; the inverse is its transpose.
            *v = c(j, i) / det;
        }
    }
    Some(inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn near(a: Vec3, b: Vec3, tol: f64) -> bool {
        (a - b).length() <= tol
    }

    #[test]
    fn poses_are_exact_at_the_ends_and_translation_is_linear() {
        let open = Transform::translate(Vec3::new(1.0, 2.0, 3.0));
        let close = Transform::translate(Vec3::new(5.0, 2.0, 3.0));
        let m = Motion::new(&open, &close);
        assert_eq!(m.at(0.0), open);
        assert_eq!(m.at(1.0), close);
        let p = m.at(0.25).point(Vec3::ZERO);
        assert!(near(p, Vec3::new(2.0, 2.0, 3.0), 1e-12), "{p:?}");
    }

    /// A quarter turn about z interpolates through the eighth turn, keeping lengths (slerp,
    /// not a straight line between matrices), with scale interpolated linearly.
    #[test]
    fn rotation_is_slerped_and_scale_lerped() {
        let open = Transform::scale(Vec3::splat(1.0)).unwrap();
        let close = Transform::rotate(Vec3::Z, 90.0)
            .unwrap()
            .after(&Transform::scale(Vec3::splat(3.0)).unwrap());
        let m = Motion::new(&open, &close);
        let half = m.at(0.5).point(Vec3::X);
        let r = 2.0 / 2f64.sqrt();
        assert!(near(half, Vec3::new(r, r, 0.0), 1e-9), "{half:?}");
        let third = m.at(1.0 / 3.0).point(Vec3::X);
        assert!((third.length() - 5.0 / 3.0).abs() < 1e-9);
        assert!((third.y.atan2(third.x).to_degrees() - 30.0).abs() < 1e-9);
    }

    #[test]
    fn decomposition_rebuilds_the_matrix() {
        let t = Transform::translate(Vec3::new(-1.0, 4.0, 2.0))
            .after(&Transform::rotate(Vec3::new(1.0, 2.0, 3.0), 70.0).unwrap())
            .after(&Transform::scale(Vec3::new(2.0, 0.5, -1.5)).unwrap());
        let other = Transform::translate(Vec3::new(3.0, 0.0, 0.0)).after(&t);
        let m = Motion::new(&t, &other);
        // Interpolating a pose with itself (as t → 0) gives the pose back.
        let start = m.at(1e-12);
        for p in [Vec3::X, Vec3::Y, Vec3::new(0.3, -2.0, 5.0)] {
            assert!(near(start.point(p), t.point(p), 1e-9));
        }
    }

    /// Every point of a spinning, moving, growing box stays inside the swept bounds.
    #[test]
    fn swept_bounds_contain_the_whole_path() {
        let b = Bounds3::new(Vec3::new(-1.0, -0.5, -0.2), Vec3::new(2.0, 0.5, 0.3));
        let open = Transform::IDENTITY;
        let close = Transform::translate(Vec3::new(0.5, 1.0, 0.0))
            .after(&Transform::rotate(Vec3::new(0.0, 1.0, 1.0), 170.0).unwrap())
            .after(&Transform::scale(Vec3::new(1.5, 1.0, 0.5)).unwrap());
        let m = Motion::new(&open, &close);
        let swept = m.bounds(&b);
        for k in 0..=2000 {
            let t = m.at(k as f64 / 2000.0);
            for c in b.corners() {
                let p = t.point(c);
                assert!(
                    p.x >= swept.min.x && p.y >= swept.min.y && p.z >= swept.min.z,
                    "{p:?} below {swept:?}"
                );
                assert!(p.x <= swept.max.x && p.y <= swept.max.y && p.z <= swept.max.z);
            }
        }
    }
}
