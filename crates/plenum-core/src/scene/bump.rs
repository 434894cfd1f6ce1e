//! Shading normals from textures: normal maps, which store the normal itself in the surface's
//! tangent space (Cohen et al. 1998; as pbrt-v4, Mitsuba 3 and glTF read them), and bump maps,
//! which displace the surface along its normal by a height field and shade it with the
//! displaced surface's normal (Blinn 1978). The geometry stays where it is: only the normal
//! that shading, cosines and BSDF frames use turns.

use crate::material::FloatTexture;
use crate::math::Vec3;
use crate::texture::{ImageTexture, TextureCoords};
use std::sync::Arc;

/// How a surface's shading normal is perturbed.
#[derive(Clone, Debug)]
pub enum Bump {
    /// An image of tangent-space normals, each channel c ∈ [0, 1] read as 2c − 1: red along
    /// ∂p/∂u, green along the bitangent, blue along the normal. The image must be linear
    /// (not sRGB-decoded). `scale` multiplies the red and green components (glTF's
    /// `normalTexture.scale`; 1 elsewhere).
    NormalMap {
        image: Arc<ImageTexture>,
        scale: f64,
        bitangent: Bitangent,
    },
    /// A displacement along the normal, in scene units, times `scale` (Mitsuba's
    /// `bumpmap` scale; 1 for pbrt's `displacement`).
    HeightMap { height: FloatTexture, scale: f64 },
}

/// Which way a normal map's green channel points. The two agree wherever the (u, v) map
/// turns counter-clockwise about the normal (∂p/∂u × ∂p/∂v along it), which is how maps
/// are usually made; they differ on mirrored maps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bitangent {
    /// Along ∂p/∂v, up the image however the map is turned: glTF, whose tangents carry
    /// MikkTSpace's handedness sign.
    AlongV,
    /// n × ∂p/∂u, as pbrt-v4 and Mitsuba 3 build their shading frames.
    NormalCrossU,
}

/// The step in u and v over which a height map's derivatives are taken: pbrt-v4's step for
/// a lookup without ray differentials.
const DU: f64 = 0.0005;

/// The parametrisation at a hit: ∂p/∂u and ∂p/∂v in world space, and in the object's own
/// space (where solid textures are looked up).
#[derive(Clone, Copy, Debug)]
pub struct UvDerivatives {
    pub world: [Vec3; 2],
    pub object: [Vec3; 2],
}

impl Bump {
    /// The perturbed unit shading normal at `at`, from the unperturbed `shading_n`; kept on
    /// the side of the geometric normal `n` (at most a hair off the tangent plane), which
    /// the integrators' cosines assume.
    pub fn shading_normal(
        &self,
        at: &TextureCoords,
        n: Vec3,
        shading_n: Vec3,
        dp: &UvDerivatives,
    ) -> Vec3 {
        let bumped = match self {
            Bump::NormalMap {
                image,
                scale,
                bitangent,
            } => {
                let c = image.bilinear(at.uv);
                let local = Vec3::new(
                    (2.0 * c.r - 1.0) * scale,
                    (2.0 * c.g - 1.0) * scale,
                    2.0 * c.b - 1.0,
                );
                let [dpdu, dpdv] = dp.world;
                let x = dpdu - shading_n * shading_n.dot(dpdu);
                if x.length_squared() <= 1e-24 * dpdu.length_squared() || !x.is_finite() {
                    return shading_n;
                }
                let x = x.normalized();
                let y = shading_n.cross(x);
                let y = match bitangent {
                    Bitangent::AlongV if y.dot(dpdv) < 0.0 => -y,
                    _ => y,
                };
                x * local.x + y * local.y + shading_n * local.z
            }
            Bump::HeightMap { height, scale } => {
                let h = |du: f64, dv: f64| {
                    let ([ou, ov], [wu, wv]) = (dp.object, dp.world);
                    let shifted = TextureCoords {
                        uv: [at.uv[0] + du, at.uv[1] + dv],
                        object_point: at.object_point + ou * du + ov * dv,
                        point: at.point + wu * du + wv * dv,
                        ..*at
                    };
                    height.evaluate(&shifted) * scale
                };
                let h0 = h(0.0, 0.0);
                let (hu, hv) = ((h(DU, 0.0) - h0) / DU, (h(0.0, DU) - h0) / DU);
                let [dpdu, dpdv] = dp.world;
                let bumped = (dpdu + shading_n * hu).cross(dpdv + shading_n * hv);
                // The cross product's side follows the (u, v) map's handedness: turn it to
                // the unperturbed normal's.
                if bumped.dot(shading_n) < 0.0 {
                    -bumped
                } else {
                    bumped
                }
            }
        };
        let len = bumped.length();
        if !(len > 0.0) || !len.is_finite() {
            return shading_n;
        }
        let m = bumped / len;
        // A normal turned past the tangent plane would face away from the side the ray is
        // on: lay it just above the plane instead.
        let above = m.dot(n);
        if above >= 1e-3 {
            return m;
        }
        let flat = m - n * above;
        let len = flat.length();
        if len == 0.0 {
            return shading_n;
        }
        (flat / len * (1.0 - 1e-6f64).sqrt() + n * 1e-3).normalized()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::Color;
    use crate::texture::Texture;

    fn coords(u: f64, v: f64) -> TextureCoords {
        TextureCoords::new([u, v], Vec3::new(u, v, 0.0))
    }

    fn flat_square(scale: f64) -> UvDerivatives {
        // The z = 0 square, u along x and v along y, `scale` units per unit of (u, v).
        let d = [Vec3::X * scale, Vec3::Y * scale];
        UvDerivatives {
            world: d,
            object: d,
        }
    }

    fn one_texel(c: Color) -> Arc<ImageTexture> {
        Arc::new(ImageTexture::new(1, 1, vec![c], [1.0, 1.0]).unwrap())
    }

    fn close(a: Vec3, b: Vec3, tol: f64) -> bool {
        (a - b).length() < tol
    }

    #[test]
    fn a_flat_normal_map_leaves_the_normal_and_a_tilted_one_turns_it_toward_u() {
        let flat = Bump::NormalMap {
            image: one_texel(Color::new(0.5, 0.5, 1.0)),
            scale: 1.0,
            bitangent: Bitangent::AlongV,
        };
        let dp = flat_square(3.0);
        let got = flat.shading_normal(&coords(0.3, 0.7), Vec3::Z, Vec3::Z, &dp);
        assert!(close(got, Vec3::Z, 1e-12), "{got:?}");
        // (sin 30°, 0, cos 30°) encoded as (1 + x)/2.
        let (s, c) = (0.5f64, 0.75f64.sqrt());
        let tilted = Bump::NormalMap {
            image: one_texel(Color::new((1.0 + s) / 2.0, 0.5, (1.0 + c) / 2.0)),
            scale: 1.0,
            bitangent: Bitangent::AlongV,
        };
        let got = tilted.shading_normal(&coords(0.3, 0.7), Vec3::Z, Vec3::Z, &dp);
        assert!(close(got, Vec3::new(s, 0.0, c), 1e-12), "{got:?}");
        // Green follows ∂p/∂v, also when v runs the other way (a mirrored uv map).
        let up = Bump::NormalMap {
            image: one_texel(Color::new(0.5, (1.0 + s) / 2.0, (1.0 + c) / 2.0)),
            scale: 1.0,
            bitangent: Bitangent::AlongV,
        };
        let got = up.shading_normal(&coords(0.3, 0.7), Vec3::Z, Vec3::Z, &dp);
        assert!(close(got, Vec3::new(0.0, s, c), 1e-12), "{got:?}");
        let mirrored = UvDerivatives {
            world: [Vec3::X, -Vec3::Y],
            object: [Vec3::X, -Vec3::Y],
        };
        let got = up.shading_normal(&coords(0.3, 0.7), Vec3::Z, Vec3::Z, &mirrored);
        assert!(close(got, Vec3::new(0.0, -s, c), 1e-12), "{got:?}");
        // pbrt's and Mitsuba's n × ∂p/∂u does not turn with the map.
        let Bump::NormalMap { image, .. } = up else {
            unreachable!()
        };
        let crossed = Bump::NormalMap {
            image,
            scale: 1.0,
            bitangent: Bitangent::NormalCrossU,
        };
        let got = crossed.shading_normal(&coords(0.3, 0.7), Vec3::Z, Vec3::Z, &mirrored);
        assert!(close(got, Vec3::new(0.0, s, c), 1e-12), "{got:?}");
        // glTF's scale multiplies x and y before normalising.
        let scaled = Bump::NormalMap {
            image: one_texel(Color::new((1.0 + s) / 2.0, 0.5, (1.0 + c) / 2.0)),
            scale: 0.0,
            bitangent: Bitangent::AlongV,
        };
        let got = scaled.shading_normal(&coords(0.3, 0.7), Vec3::Z, Vec3::Z, &dp);
        assert!(close(got, Vec3::Z, 1e-12), "{got:?}");
    }

    #[test]
    fn a_height_ramp_tilts_the_normal_by_its_slope() {
        // A linear height over a square of 2 units per unit of u: the difference quotient
        // is exact, and the normal is (−slope, 0, 1) normalised, slope = dh/du ÷ 2.
        let ramp = Bump::HeightMap {
            height: FloatTexture::Texture(Texture::Image(Arc::new(
                ImageTexture::new(
                    2,
                    1,
                    vec![
                        Color::new(-0.05, -0.05, -0.05),
                        Color::new(0.05, 0.05, 0.05),
                    ],
                    [1.0, 1.0],
                )
                .unwrap(),
            ))),
            scale: 2.0,
        };
        // Between the two texel centres (u = 0.25 and 0.75) the bilinear lookup is
        // h = 2·(−0.05 + 0.1·(u − 0.25)/0.5) = 0.4·u − 0.2: dh/du = 0.4, a slope of 0.2.
        let got = ramp.shading_normal(&coords(0.5, 0.5), Vec3::Z, Vec3::Z, &flat_square(2.0));
        let want = Vec3::new(-0.2, 0.0, 1.0).normalized();
        assert!(close(got, want, 1e-9), "{got:?} vs {want:?}");
        // A constant height turns nothing.
        let level = Bump::HeightMap {
            height: FloatTexture::Constant(0.3),
            scale: 1.0,
        };
        let got = level.shading_normal(&coords(0.5, 0.5), Vec3::Z, Vec3::Z, &flat_square(2.0));
        assert!(close(got, Vec3::Z, 1e-12), "{got:?}");
    }

    #[test]
    fn a_normal_past_the_tangent_plane_is_laid_just_above_it() {
        // Nearly (1, 0, −0.2): below the plane of the geometric normal z.
        let under = Bump::NormalMap {
            image: one_texel(Color::new(1.0, 0.5, 0.4)),
            scale: 1.0,
            bitangent: Bitangent::AlongV,
        };
        let got = under.shading_normal(&coords(0.5, 0.5), Vec3::Z, Vec3::Z, &flat_square(1.0));
        assert!(got.dot(Vec3::Z) > 0.0 && got.dot(Vec3::Z) < 2e-3, "{got:?}");
        assert!((got.length() - 1.0).abs() < 1e-12);
        assert!(got.x > 0.99);
    }
}
