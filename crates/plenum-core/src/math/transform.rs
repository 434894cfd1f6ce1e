//! Affine transforms with their inverses, and the error bounds of transformed points
//! (pbrt-v4 §6.8.6).

use super::{gamma, Ray, Vec3};

/// A row-major 4×4 matrix acting on column vectors: p' = M·p.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Matrix4(pub [[f64; 4]; 4]);

impl Matrix4 {
    pub const IDENTITY: Matrix4 = Matrix4([
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]);

    pub fn mul(&self, o: &Matrix4) -> Matrix4 {
        let mut r = [[0.0; 4]; 4];
        for (i, row) in r.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = (0..4).map(|k| self.0[i][k] * o.0[k][j]).sum();
            }
        }
        Matrix4(r)
    }

    pub fn transpose(&self) -> Matrix4 {
        let mut r = [[0.0; 4]; 4];
        for (i, row) in r.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = self.0[j][i];
            }
        }
        Matrix4(r)
    }

    /// The inverse by Gauss–Jordan elimination with partial pivoting; `None` when singular.
    pub fn inverse(&self) -> Option<Matrix4> {
        let mut a = self.0;
        let mut inv = Matrix4::IDENTITY.0;
        for col in 0..4 {
            let pivot = (col..4).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
            if a[pivot][col].abs() < 1e-300 || !a[pivot][col].is_finite() {
                return None;
            }
            a.swap(col, pivot);
            inv.swap(col, pivot);
            let p = a[col][col];
            for j in 0..4 {
                a[col][j] /= p;
                inv[col][j] /= p;
            }
            for row in 0..4 {
                if row != col {
                    let f = a[row][col];
                    for j in 0..4 {
                        a[row][j] -= f * a[col][j];
                        inv[row][j] -= f * inv[col][j];
                    }
                }
            }
        }
        Some(Matrix4(inv))
    }
}

/// An affine transform and its inverse, so that rays go into object space and hits come out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub matrix: Matrix4,
    pub inverse: Matrix4,
    /// How far the stored inverse is from the true one (see [`Transform::inverse_residual`]),
    /// measured once when the transform is made, not per hit.
    residual: f64,
}

impl Default for Transform {
    fn default() -> Self {
        Transform::IDENTITY
    }
}

impl Transform {
    pub const IDENTITY: Transform = Transform {
        matrix: Matrix4::IDENTITY,
        inverse: Matrix4::IDENTITY,
        residual: gamma(4),
    };

    /// A transform from a matrix and its inverse, measuring how well they agree.
    fn with_inverse(matrix: Matrix4, inverse: Matrix4) -> Transform {
        let r = inverse.mul(&matrix).0;
        let mut worst = 0.0f64;
        for (i, row) in r.iter().enumerate().take(3) {
            for (j, v) in row.iter().enumerate() {
                let identity = if i == j { 1.0 } else { 0.0 };
                worst = worst.max((v - identity).abs());
            }
        }
        Transform {
            matrix,
            inverse,
            residual: 2.0 * worst + gamma(4),
        }
    }

    /// `None` when the matrix is singular (a zero scale, say) or not affine.
    pub fn from_matrix(m: Matrix4) -> Option<Transform> {
        if m.0[3] != [0.0, 0.0, 0.0, 1.0] {
            return None;
        }
        Some(Transform::with_inverse(m, m.inverse()?))
    }

    pub fn translate(d: Vec3) -> Transform {
        let m = Matrix4([
            [1.0, 0.0, 0.0, d.x],
            [0.0, 1.0, 0.0, d.y],
            [0.0, 0.0, 1.0, d.z],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        let inv = Matrix4([
            [1.0, 0.0, 0.0, -d.x],
            [0.0, 1.0, 0.0, -d.y],
            [0.0, 0.0, 1.0, -d.z],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        Transform::with_inverse(m, inv)
    }

    /// `None` when a factor is zero.
    pub fn scale(s: Vec3) -> Option<Transform> {
        if s.x == 0.0 || s.y == 0.0 || s.z == 0.0 {
            return None;
        }
        let m = |a: Vec3| {
            Matrix4([
                [a.x, 0.0, 0.0, 0.0],
                [0.0, a.y, 0.0, 0.0],
                [0.0, 0.0, a.z, 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ])
        };
        Some(Transform::with_inverse(
            m(s),
            m(Vec3::new(1.0 / s.x, 1.0 / s.y, 1.0 / s.z)),
        ))
    }

    /// A right-handed rotation by `degrees` about `axis` (Rodrigues' formula);
    /// `None` for a zero axis.
    pub fn rotate(axis: Vec3, degrees: f64) -> Option<Transform> {
        let a = axis.normalized();
        if a.length_squared() == 0.0 {
            return None;
        }
        let (s, c) = degrees.to_radians().sin_cos();
        let t = 1.0 - c;
        let m = Matrix4([
            [
                t * a.x * a.x + c,
                t * a.x * a.y - s * a.z,
                t * a.x * a.z + s * a.y,
                0.0,
            ],
            [
                t * a.x * a.y + s * a.z,
                t * a.y * a.y + c,
                t * a.y * a.z - s * a.x,
                0.0,
            ],
            [
                t * a.x * a.z - s * a.y,
                t * a.y * a.z + s * a.x,
                t * a.z * a.z + c,
                0.0,
            ],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        Some(Transform::with_inverse(m, m.transpose()))
    }

    /// The rigid transform taking the object frame (origin, x, y, z axes) to the world.
    pub fn frame(origin: Vec3, x: Vec3, y: Vec3, z: Vec3) -> Option<Transform> {
        Transform::from_matrix(Matrix4([
            [x.x, y.x, z.x, origin.x],
            [x.y, y.y, z.y, origin.y],
            [x.z, y.z, z.z, origin.z],
            [0.0, 0.0, 0.0, 1.0],
        ]))
    }

    /// `self` applied after `first`: (self ∘ first)(p) = self(first(p)).
    pub fn after(&self, first: &Transform) -> Transform {
        Transform::with_inverse(
            self.matrix.mul(&first.matrix),
            first.inverse.mul(&self.inverse),
        )
    }

    pub fn inverted(&self) -> Transform {
        Transform::with_inverse(self.inverse, self.matrix)
    }

    pub fn is_identity(&self) -> bool {
        self.matrix == Matrix4::IDENTITY
    }

    pub fn point(&self, p: Vec3) -> Vec3 {
        apply_point(&self.matrix, p)
    }

    pub fn vector(&self, v: Vec3) -> Vec3 {
        apply_vector(&self.matrix, v)
    }

    /// Normals transform by the inverse transpose, so they stay perpendicular to surfaces.
    pub fn normal(&self, n: Vec3) -> Vec3 {
        let m = &self.inverse.0;
        Vec3::new(
            m[0][0] * n.x + m[1][0] * n.y + m[2][0] * n.z,
            m[0][1] * n.x + m[1][1] * n.y + m[2][1] * n.z,
            m[0][2] * n.x + m[1][2] * n.y + m[2][2] * n.z,
        )
    }

    /// A point with absolute error `err` mapped to the world, with the bound on the result's
    /// error: the input error carried through the matrix plus the rounding of the product.
    pub fn point_with_error(&self, p: Vec3, err: Vec3) -> (Vec3, Vec3) {
        let m = &self.matrix.0;
        let g3 = gamma(3);
        let row = |r: &[f64; 4]| {
            (g3 + 1.0) * (r[0].abs() * err.x + r[1].abs() * err.y + r[2].abs() * err.z)
                + g3 * ((r[0] * p.x).abs() + (r[1] * p.y).abs() + (r[2] * p.z).abs() + r[3].abs())
        };
        (self.point(p), Vec3::new(row(&m[0]), row(&m[1]), row(&m[2])))
    }

    /// How far the stored inverse is from the true one: the largest entry of
    /// |M⁻¹·M − I|, doubled to cover the rounding of the check itself. An inverse computed in
    /// floating point is off by about the condition number times ε, which for strong
    /// anisotropic scales dwarfs the rounding of a single product.
    pub fn inverse_residual(&self) -> f64 {
        self.residual
    }

    /// Bound on the rounding error, in object space, of the world point `p` taken into object
    /// space: what a ray starting at `p` suffers when it is transformed for intersection.
    pub fn inverse_error(&self, p: Vec3) -> Vec3 {
        let inv = &self.inverse.0;
        let g3 = gamma(3);
        let e = |r: &[f64; 4]| {
            g3 * ((r[0] * p.x).abs() + (r[1] * p.y).abs() + (r[2] * p.z).abs() + r[3].abs())
        };
        Vec3::new(e(&inv[0]), e(&inv[1]), e(&inv[2]))
    }

    /// The world ray in object space, and the parameter shift `dt` to add back to an
    /// object-space distance. The origin's rounding error from the transform is absorbed by
    /// advancing it along the direction by `dt` (pbrt-v4 §6.8.6), so a ray leaving a surface
    /// cannot start behind it in object space.
    pub fn ray_to_object(&self, ray: &Ray) -> (Ray, f64) {
        let m = &self.inverse.0;
        let p = ray.origin;
        let g3 = gamma(3);
        let err = |r: &[f64; 4]| {
            g3 * ((r[0] * p.x).abs() + (r[1] * p.y).abs() + (r[2] * p.z).abs() + r[3].abs())
        };
        let o_err = Vec3::new(err(&m[0]), err(&m[1]), err(&m[2]));
        let o = apply_point(&self.inverse, p);
        let d = apply_vector(&self.inverse, ray.direction);
        let len2 = d.length_squared();
        let dt = if len2 > 0.0 {
            d.abs().dot(o_err) / len2
        } else {
            0.0
        };
        (Ray::new(o + d * dt, d).at_time(ray.time), dt)
    }
}

fn apply_point(m: &Matrix4, p: Vec3) -> Vec3 {
    let m = &m.0;
    Vec3::new(
        m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
        m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
        m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3],
    )
}

fn apply_vector(m: &Matrix4, v: Vec3) -> Vec3 {
    let m = &m.0;
    Vec3::new(
        m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
        m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
        m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-12
    }

    #[test]
    fn rotation_about_z_by_90_degrees() {
        let r = Transform::rotate(Vec3::Z, 90.0).unwrap();
        assert!(close(r.point(Vec3::X), Vec3::Y));
    }

    #[test]
    fn composition_applies_first_then_self() {
        let s = Transform::scale(Vec3::splat(2.0)).unwrap();
        let t = Transform::translate(Vec3::X);
        // Scale first, then translate: (1,0,0) → (2,0,0) → (3,0,0).
        assert!(close(t.after(&s).point(Vec3::X), Vec3::new(3.0, 0.0, 0.0)));
        let both = t.after(&s);
        assert!(close(both.inverted().point(both.point(Vec3::Y)), Vec3::Y));
    }

    #[test]
    fn inverse_of_a_general_matrix() {
        let m = Matrix4([
            [2.0, 1.0, 0.0, 3.0],
            [0.0, 1.0, 4.0, -1.0],
            [1.0, 0.0, 1.0, 2.0],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        let p = m.mul(&m.inverse().unwrap());
        for i in 0..4 {
            for j in 0..4 {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((p.0[i][j] - want).abs() < 1e-12);
            }
        }
        assert!(Transform::scale(Vec3::new(1.0, 0.0, 1.0)).is_none());
    }

    #[test]
    fn normals_stay_perpendicular_under_nonuniform_scale() {
        let s = Transform::scale(Vec3::new(1.0, 4.0, 1.0)).unwrap();
        let tangent = Vec3::new(1.0, -1.0, 0.0);
        let n = Vec3::new(1.0, 1.0, 0.0);
        assert!(s.vector(tangent).dot(s.normal(n)).abs() < 1e-12);
    }
}
