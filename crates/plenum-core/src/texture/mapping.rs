//! Texture mappings: how a texture finds its coordinates at a hit, when not by the surface's
//! own (u, v) as given. pbrt-v4's mappings (section 10.2 of its book): a scaled and offset
//! (u, v); spherical, cylindrical and planar projections of the hit point; and, for solid
//! textures, the hit point in the texture's own space.

use super::TextureCoords;
use crate::math::{Transform, Vec3};
use std::f64::consts::{FRAC_1_PI, PI};

#[derive(Clone, Debug)]
pub enum Mapping {
    /// (s, t) = (su·u + du, sv·v + dv).
    Uv { scale: [f64; 2], delta: [f64; 2] },
    /// (θ/π, φ/2π) of the direction from the texture space's origin to the hit point, θ
    /// from +z, φ from +x toward +y. The transform takes world points to texture space.
    Spherical(Transform),
    /// ((π + atan2(y, x))/2π, z) of the hit point in texture space.
    Cylindrical(Transform),
    /// (s, t) = (ds + p·vs, dt + p·vt) of the hit point p in texture space.
    Planar {
        to_texture: Transform,
        axes: [Vec3; 2],
        delta: [f64; 2],
    },
    /// Solid textures are looked up at the hit point in texture space (rather than in the
    /// object's space).
    Solid(Transform),
}

impl Mapping {
    /// The coordinates a texture under this mapping is looked up at.
    #[inline]
    pub fn apply(&self, at: &TextureCoords) -> TextureCoords {
        let with_uv = |uv: [f64; 2]| TextureCoords { uv, ..*at };
        match self {
            Mapping::Uv { scale, delta } => with_uv([
                scale[0] * at.uv[0] + delta[0],
                scale[1] * at.uv[1] + delta[1],
            ]),
            Mapping::Spherical(to_texture) => {
                let d = to_texture.point(at.point).normalized();
                let phi = d.y.atan2(d.x);
                let phi = if phi < 0.0 { phi + 2.0 * PI } else { phi };
                with_uv([d.z.clamp(-1.0, 1.0).acos() * FRAC_1_PI, phi / (2.0 * PI)])
            }
            Mapping::Cylindrical(to_texture) => {
                let p = to_texture.point(at.point);
                with_uv([(PI + p.y.atan2(p.x)) / (2.0 * PI), p.z])
            }
            Mapping::Planar {
                to_texture,
                axes,
                delta,
            } => {
                let p = to_texture.point(at.point);
                with_uv([delta[0] + p.dot(axes[0]), delta[1] + p.dot(axes[1])])
            }
            Mapping::Solid(to_texture) => TextureCoords {
                object_point: to_texture.point(at.point),
                ..*at
            },
        }
    }

    /// Whether the mapping reads the surface's (u, v).
    pub fn needs_uv(&self) -> bool {
        matches!(self, Mapping::Uv { .. })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(point: Vec3, uv: [f64; 2]) -> TextureCoords {
        TextureCoords {
            object_point: Vec3::ZERO,
            ..TextureCoords::new(uv, point)
        }
    }

    fn close(a: [f64; 2], b: [f64; 2]) -> bool {
        (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12
    }

    #[test]
    fn each_mapping_places_a_known_point() {
        let uv = Mapping::Uv {
            scale: [2.0, 3.0],
            delta: [0.5, -1.0],
        };
        assert!(close(uv.apply(&at(Vec3::ZERO, [0.25, 0.5])).uv, [1.0, 0.5]));
        // The texture space moved by (0, 0, 5): world (0, 1, 5) is texture (0, 1, 0).
        let to_texture = Transform::translate(Vec3::new(0.0, 0.0, -5.0));
        let p = Vec3::new(0.0, 1.0, 5.0);
        // On the equator (θ = π/2) a quarter turn from +x (φ = π/2).
        let spherical = Mapping::Spherical(to_texture.clone());
        assert!(close(spherical.apply(&at(p, [0.0; 2])).uv, [0.5, 0.25]));
        // The pole: θ = 0.
        let pole = spherical.apply(&at(Vec3::new(0.0, 0.0, 7.0), [0.0; 2])).uv;
        assert!(pole[0].abs() < 1e-12);
        // −y is φ = 3π/2.
        let below = spherical.apply(&at(Vec3::new(0.0, -1.0, 5.0), [0.0; 2])).uv;
        assert!(close(below, [0.5, 0.75]));
        let cylindrical = Mapping::Cylindrical(to_texture.clone());
        let q = Vec3::new(1.0, 0.0, 7.0);
        assert!(close(cylindrical.apply(&at(q, [0.0; 2])).uv, [0.5, 2.0]));
        let planar = Mapping::Planar {
            to_texture: to_texture.clone(),
            axes: [Vec3::X, Vec3::Z * 2.0],
            delta: [0.1, 0.2],
        };
        assert!(close(planar.apply(&at(q, [0.0; 2])).uv, [1.1, 4.2]));
        let solid = Mapping::Solid(to_texture).apply(&at(q, [0.3, 0.4]));
        assert_eq!(solid.object_point, Vec3::new(1.0, 0.0, 2.0));
        assert_eq!(solid.uv, [0.3, 0.4]);
    }
}
