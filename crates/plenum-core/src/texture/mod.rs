//! Textures: colours that vary over a surface. 2-D textures are looked up by the surface's
//! (u, v); solid textures by the hit point in the object's own coordinates, so they move
//! with the object (or, under a [`Mapping`], in a space of the texture's own).

mod mapping;
pub mod noise;
mod procedural;

pub use mapping::Mapping;
use procedural::in_polka_dot;

use crate::color::Color;
use crate::math::Vec3;
use std::sync::Arc;

#[derive(Clone, Debug)]
pub enum Texture {
    Constant(Color),
    /// Squares of side 1/`scale` in (u, v).
    Checker2d {
        even: Color,
        odd: Color,
        scale: f64,
    },
    /// Cubes of side 1/`scale` in object space.
    Checker3d {
        even: Color,
        odd: Color,
        scale: f64,
    },
    Image(Arc<ImageTexture>),
    /// Bilinear between four colours at the corners of the unit square in (u, v), repeats
    /// of it `scale` per unit (pbrt-v4's `bilerp`): [v00, v10, v01, v11], v10 at (1, 0).
    Bilerp(Arc<([Color; 4], [f64; 2])>),
    /// The product of two textures, channel by channel (pbrt-v4's `scale`).
    Scale(Arc<[Texture; 2]>),
    /// (1 − t)·a + t·b with t the mean of the third texture's channels (pbrt-v4's `mix`).
    Mix(Arc<[Texture; 3]>),
    /// t·a + (1 − t)·b with t = |n·d|, n the surface normal and d the unit direction given
    /// (pbrt-v4's `directionmix`): a where the surface faces along d.
    DirectionMix(Arc<(Vec3, [Texture; 2])>),
    /// Noise patterns, solid (looked up at the object point).
    Noise(Arc<Noise>),
    /// Polka dots over (u, v) (pbrt-v4's `dots`), white on black: in the unit cells noise
    /// chooses, a dot of radius 0.35 moved off the cell's centre by noise. (A `Mix` with it
    /// as the amount puts textures in and between the dots.)
    Dots,
    /// The texture looked up where the mapping says.
    Mapped(Arc<(Mapping, Texture)>),
}

/// pbrt-v4's noise textures (section 10.6 of its book), by [`noise`]'s Perlin noise.
#[derive(Clone, Debug)]
pub enum Noise {
    /// Fractional Brownian motion: octaves weighted by omega per octave.
    Fbm { omega: f64, octaves: u32 },
    /// Turbulence: fBm of the noise's magnitude.
    Wrinkled { omega: f64, octaves: u32 },
    /// Waves whose height is scaled by a slower fBm, the wind's strength.
    Windy,
    /// Marble: veins along y, bent by fBm, coloured by pbrt-v4's grey and blue spline.
    Marble {
        omega: f64,
        octaves: u32,
        scale: f64,
        variation: f64,
    },
}

/// Where a texture is looked up.
#[derive(Clone, Copy, Debug)]
pub struct TextureCoords {
    pub uv: [f64; 2],
    /// The hit point in the object's coordinates.
    pub object_point: Vec3,
    /// The hit point in the world.
    pub point: Vec3,
    /// The surface's unit geometric normal in the world (either side).
    pub normal: Vec3,
}

impl TextureCoords {
    /// At (u, v), the point `p` in the object and in the world, the normal along +z: for
    /// tests and tools that look textures up outside a scene.
    pub fn new(uv: [f64; 2], p: Vec3) -> Self {
        TextureCoords {
            uv,
            object_point: p,
            point: p,
            normal: Vec3::Z,
        }
    }
}

/// Whether the whole number `s` is even, as `s.rem_euclid(2.0) == 0.0` says (infinite and
/// NaN: no) without its library call: halving, flooring and doubling are exact.
#[inline]
fn is_even(s: f64) -> bool {
    s - 2.0 * (0.5 * s).floor() == 0.0
}

impl Texture {
    /// The value at `at`. A constant, as most of a material's coefficients are, is read
    /// where the caller is: the call to the whole match, whose entry and exit save and
    /// restore a dozen registers, cost the built-in scene 5 % of its instructions.
    #[inline]
    pub fn evaluate(&self, at: &TextureCoords) -> Color {
        match self {
            Texture::Constant(c) => *c,
            _ => self.evaluate_varying(at),
        }
    }

    #[inline(never)]
    fn evaluate_varying(&self, at: &TextureCoords) -> Color {
        match self {
            Texture::Constant(c) => *c,
            Texture::Checker2d { even, odd, scale } => {
                let s = (at.uv[0] * scale).floor() + (at.uv[1] * scale).floor();
                if is_even(s) {
                    *even
                } else {
                    *odd
                }
            }
            Texture::Checker3d { even, odd, scale } => {
                let p = at.object_point * *scale;
                let s = p.x.floor() + p.y.floor() + p.z.floor();
                if is_even(s) {
                    *even
                } else {
                    *odd
                }
            }
            Texture::Image(image) => image.bilinear(at.uv),
            Texture::Bilerp(b) => {
                let ([v00, v10, v01, v11], scale) = **b;
                let (u, v) = (at.uv[0] * scale[0], at.uv[1] * scale[1]);
                v00 * ((1.0 - u) * (1.0 - v))
                    + v10 * (u * (1.0 - v))
                    + v01 * ((1.0 - u) * v)
                    + v11 * (u * v)
            }
            Texture::Scale(t) => {
                let (a, b) = (t[0].evaluate(at), t[1].evaluate(at));
                Color::new(a.r * b.r, a.g * b.g, a.b * b.b)
            }
            Texture::Mix(t) => {
                let amount = t[2].evaluate(at);
                let w = (amount.r + amount.g + amount.b) / 3.0;
                t[0].evaluate(at) * (1.0 - w) + t[1].evaluate(at) * w
            }
            Texture::DirectionMix(m) => {
                let (d, [a, b]) = &**m;
                let w = at.normal.dot(*d).abs().min(1.0);
                a.evaluate(at) * w + b.evaluate(at) * (1.0 - w)
            }
            Texture::Noise(n) => n.evaluate(at.object_point),
            Texture::Dots => Color::gray(in_polka_dot(at.uv) as u8 as f64),
            Texture::Mapped(m) => m.1.evaluate(&m.0.apply(at)),
        }
    }

    /// Its one value, where it has the same everywhere: a constant, or a product or mix of
    /// constants (which readers fold into one).
    pub fn constant_value(&self) -> Option<Color> {
        match self {
            Texture::Constant(c) => Some(*c),
            Texture::Scale(t) => {
                let (a, b) = (t[0].constant_value()?, t[1].constant_value()?);
                Some(Color::new(a.r * b.r, a.g * b.g, a.b * b.b))
            }
            Texture::Mix(t) => {
                let (a, b, amount) = (
                    t[0].constant_value()?,
                    t[1].constant_value()?,
                    t[2].constant_value()?,
                );
                let w = (amount.r + amount.g + amount.b) / 3.0;
                Some(a * (1.0 - w) + b * w)
            }
            Texture::DirectionMix(m) => {
                let (a, b) = (m.1[0].constant_value()?, m.1[1].constant_value()?);
                (a == b).then_some(a)
            }
            Texture::Mapped(m) => m.1.constant_value(),
            _ => None,
        }
    }

    /// Whether the texture is looked up by (u, v) (rather than being constant or solid).
    pub fn needs_uv(&self) -> bool {
        match self {
            Texture::Constant(_) | Texture::Checker3d { .. } | Texture::Noise(_) => false,
            Texture::Checker2d { .. } | Texture::Image(_) | Texture::Bilerp(_) | Texture::Dots => {
                true
            }
            Texture::Scale(t) => t.iter().any(Texture::needs_uv),
            Texture::Mix(t) => t.iter().any(Texture::needs_uv),
            Texture::DirectionMix(m) => m.1.iter().any(Texture::needs_uv),
            // A mapping other than (u, v)'s makes the uv its texture reads.
            Texture::Mapped(m) => m.0.needs_uv() && m.1.needs_uv(),
        }
    }

    /// The largest channel value the texture takes anywhere (an image's: at most 1 after
    /// decoding, so 1 is an upper bound).
    pub fn max_component(&self) -> f64 {
        let max = |c: &Color| c.r.max(c.g).max(c.b);
        match self {
            Texture::Constant(c) => max(c),
            Texture::Checker2d { even, odd, .. } | Texture::Checker3d { even, odd, .. } => {
                max(even).max(max(odd))
            }
            Texture::Image(_) => 1.0,
            Texture::Bilerp(b) => b.0.iter().map(max).fold(0.0, f64::max),
            Texture::Scale(t) => t[0].max_component() * t[1].max_component(),
            Texture::Mix(t) => t[0].max_component().max(t[1].max_component()),
            Texture::DirectionMix(m) => m.1[0].max_component().max(m.1[1].max_component()),
            Texture::Dots => 1.0,
            Texture::Noise(n) => n.max_value(),
            Texture::Mapped(m) => m.1.max_component(),
        }
    }

    /// The texture's mean over (u, v): exact for constants, checkers, images and bilerps,
    /// the product or mix of the operands' means for `Scale` and `Mix`, and over a cube of
    /// sample points for noise (an estimate, what weighing lights by their power needs).
    pub fn average(&self) -> Color {
        match self {
            Texture::Constant(c) => *c,
            Texture::Checker2d { even, odd, .. } | Texture::Checker3d { even, odd, .. } => {
                (*even + *odd) * 0.5
            }
            Texture::Image(image) => image.average(),
            Texture::Bilerp(b) => b.0.iter().fold(Color::BLACK, |a, &c| a + c) * 0.25,
            Texture::Scale(t) => t[0].average() * t[1].average(),
            Texture::Mix(t) => {
                let m = t[2].average();
                let w = (m.r + m.g + m.b) / 3.0;
                t[0].average() * (1.0 - w) + t[1].average() * w
            }
            Texture::DirectionMix(m) => (m.1[0].average() + m.1[1].average()) * 0.5,
            Texture::Dots => Color::gray(procedural::polka_dot_cover()),
            Texture::Noise(n) => n.average(),
            Texture::Mapped(m) => m.1.average(),
        }
    }

    /// True when the texture is black everywhere: lets the integrator skip work.
    pub fn is_black(&self) -> bool {
        match self {
            Texture::Constant(c) => c.is_black(),
            Texture::Checker2d { even, odd, .. } | Texture::Checker3d { even, odd, .. } => {
                even.is_black() && odd.is_black()
            }
            Texture::Image(_) => false,
            Texture::Bilerp(b) => b.0.iter().all(|c| c.is_black()),
            Texture::Scale(t) => t[0].is_black() || t[1].is_black(),
            Texture::Mix(t) => t[0].is_black() && t[1].is_black(),
            Texture::DirectionMix(m) => m.1.iter().all(Texture::is_black),
            Texture::Dots => false,
            Texture::Noise(_) => false,
            Texture::Mapped(m) => m.1.is_black(),
        }
    }
}

/// An image in linear RGB over (u, v), (0, 0) at its bottom-left corner, repeated (or
/// otherwise continued, see [`Wrap`]) beyond [0, 1].
#[derive(Clone, Debug)]
pub struct ImageTexture {
    width: usize,
    height: usize,
    /// Row-major from the top row.
    texels: Vec<Color>,
    /// Repeats of the image per unit of u and v.
    pub scale: [f64; 2],
    /// An affine map of (u, v) applied before `scale` (rows: u′ = m[0]·(u, v, 1), v′ =
    /// m[1]·(u, v, 1)): an atlas's region, turned (glTF's `KHR_texture_transform`).
    uv_transform: Option<Box<[[f64; 3]; 2]>>,
    /// What lies beyond the image's edges, along u and along v.
    wrap: [Wrap; 2],
}

/// What an image shows outside [0, 1] (the formats' wrap modes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// The image again (pbrt's and Mitsuba's default, glTF's `REPEAT`).
    #[default]
    Repeat,
    /// The edge texel (glTF's `CLAMP_TO_EDGE`, pbrt's and Mitsuba's `clamp`).
    Clamp,
    /// The image reflected, every other copy (glTF's `MIRRORED_REPEAT`, Mitsuba's `mirror`).
    Mirror,
    /// Black (pbrt's `black`).
    Black,
}

impl Wrap {
    /// The texel index `i` of a row or column of `n` stands for; `None`: black.
    #[inline]
    fn index(self, i: i64, n: usize) -> Option<usize> {
        let n = n as i64;
        Some(match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::Mirror => {
                let k = i.rem_euclid(2 * n);
                if k < n {
                    k
                } else {
                    2 * n - 1 - k
                }
            }
            Wrap::Black if (0..n).contains(&i) => i,
            Wrap::Black => return None,
        } as usize)
    }
}

impl ImageTexture {
    /// `None` when the texel count does not match the size or the image is empty.
    pub fn new(width: usize, height: usize, texels: Vec<Color>, scale: [f64; 2]) -> Option<Self> {
        (width > 0 && height > 0 && texels.len() == width * height).then_some(ImageTexture {
            width,
            height,
            texels,
            scale,
            uv_transform: None,
            wrap: [Wrap::Repeat; 2],
        })
    }

    /// The image with `wrap` beyond its edges along u and along v.
    pub fn with_wrap(mut self, wrap: [Wrap; 2]) -> Self {
        self.wrap = wrap;
        self
    }

    /// The image looked up at (u, v) mapped by the affine `m` first (see `uv_transform`).
    pub fn with_uv_transform(mut self, m: [[f64; 3]; 2]) -> Self {
        let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        self.uv_transform = (m != identity).then(|| Box::new(m));
        self
    }

    /// The mean of all texels.
    pub fn average(&self) -> Color {
        let sum = self.texels.iter().fold(Color::BLACK, |a, &c| a + c);
        sum / self.texels.len() as f64
    }

    fn texel(&self, x: i64, y: i64) -> Color {
        match (
            self.wrap[0].index(x, self.width),
            self.wrap[1].index(y, self.height),
        ) {
            (Some(x), Some(y)) => self.texels[y * self.width + x],
            _ => Color::BLACK,
        }
    }

    /// Bilinear interpolation between the four nearest texel centres, wrapping at the edges.
    pub fn bilinear(&self, uv: [f64; 2]) -> Color {
        let uv = match &self.uv_transform {
            None => uv,
            Some(m) => [
                m[0][0] * uv[0] + m[0][1] * uv[1] + m[0][2],
                m[1][0] * uv[0] + m[1][1] * uv[1] + m[1][2],
            ],
        };
        let x = uv[0] * self.scale[0] * self.width as f64 - 0.5;
        let y = (1.0 - uv[1] * self.scale[1]) * self.height as f64 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        self.texel(x0, y0) * ((1.0 - fx) * (1.0 - fy))
            + self.texel(x0 + 1, y0) * (fx * (1.0 - fy))
            + self.texel(x0, y0 + 1) * ((1.0 - fx) * fy)
            + self.texel(x0 + 1, y0 + 1) * (fx * fy)
    }
}

#[cfg(test)]
mod tests {
    /// The checkers' parity against the library's remainder: signs, infinities, NaN, and
    /// odd numbers up to where f64 has no odd integers left.
    #[test]
    fn evenness_is_the_remainder_of_two() {
        let mut cases = vec![
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            9.007_199_254_740_992e15,
            -1e300,
        ];
        cases.extend((-6..=6).map(f64::from));
        cases.extend((0..64).map(|k| 2f64.powi(k) + 1.0));
        for s in cases {
            assert_eq!(super::is_even(s), s.rem_euclid(2.0) == 0.0, "{s}");
        }
    }

    use super::*;

    fn at(u: f64, v: f64) -> TextureCoords {
        TextureCoords::new([u, v], Vec3::new(u, v, 0.0))
    }

    #[test]
    fn checkerboard_alternates() {
        let t = Texture::Checker2d {
            even: Color::WHITE,
            odd: Color::BLACK,
            scale: 2.0,
        };
        assert_eq!(t.evaluate(&at(0.1, 0.1)), Color::WHITE);
        assert_eq!(t.evaluate(&at(0.6, 0.1)), Color::BLACK);
        assert_eq!(t.evaluate(&at(-0.1, 0.1)), Color::BLACK);
        let solid = Texture::Checker3d {
            even: Color::WHITE,
            odd: Color::BLACK,
            scale: 1.0,
        };
        assert_eq!(solid.evaluate(&at(1.5, 0.5)), Color::BLACK);
    }

    #[test]
    fn bilerp_scale_and_mix_combine_as_pbrt_defines_them() {
        let corners = [
            Color::new(1.0, 0.0, 0.0),
            Color::new(0.0, 1.0, 0.0),
            Color::new(0.0, 0.0, 1.0),
            Color::new(1.0, 1.0, 1.0),
        ];
        let bilerp = Texture::Bilerp(Arc::new((corners, [1.0, 1.0])));
        // At (0.25, 0.5): weights ¾·½ (v00), ¼·½ (v10), ¾·½ (v01), ¼·½ (v11).
        let c = bilerp.evaluate(&at(0.25, 0.5));
        let want = Color::new(0.375 + 0.125, 0.125 + 0.125, 0.375 + 0.125);
        let off = (c.r - want.r).abs() + (c.g - want.g).abs() + (c.b - want.b).abs();
        assert!(off < 1e-12, "{c:?}");
        assert_eq!(bilerp.evaluate(&at(1.0, 0.0)), corners[1]);
        let checker = Texture::Checker2d {
            even: Color::WHITE,
            odd: Color::BLACK,
            scale: 2.0,
        };
        let scaled = Texture::Scale(Arc::new([
            checker.clone(),
            Texture::Constant(Color::new(0.5, 0.25, 2.0)),
        ]));
        assert_eq!(scaled.evaluate(&at(0.1, 0.1)), Color::new(0.5, 0.25, 2.0));
        assert_eq!(scaled.evaluate(&at(0.6, 0.1)), Color::BLACK);
        assert!(scaled.needs_uv() && (scaled.max_component() - 2.0).abs() < 1e-12);
        let mix = Texture::Mix(Arc::new([
            Texture::Constant(Color::gray(0.2)),
            Texture::Constant(Color::gray(0.6)),
            checker,
        ]));
        // Amount 1 on even squares (the second), 0 on odd ones (the first).
        assert_eq!(mix.evaluate(&at(0.1, 0.1)), Color::gray(0.6));
        assert_eq!(mix.evaluate(&at(0.6, 0.1)), Color::gray(0.2));
        let solid = Texture::Mix(Arc::new([
            Texture::Constant(Color::BLACK),
            Texture::Constant(Color::BLACK),
            Texture::Constant(Color::gray(0.5)),
        ]));
        assert!(solid.is_black() && !solid.needs_uv());
    }

    #[test]
    fn wrap_modes_continue_the_image_past_its_edges() {
        // Four texels in a row, values 1, 2, 3, 4 (one row: v plays no part).
        let row: Vec<Color> = (1..=4).map(|i| Color::gray(i as f64)).collect();
        let image = |wrap| {
            ImageTexture::new(4, 1, row.clone(), [1.0, 1.0])
                .unwrap()
                .with_wrap([wrap, wrap])
        };
        // Texel centres at u = 0.125 + k/4: k = −1 and k = 4, 5 lie outside.
        let at = |img: &ImageTexture, k: f64| img.bilinear([0.125 + k / 4.0, 0.5]).r;
        let repeat = image(Wrap::Repeat);
        assert_eq!(
            [at(&repeat, -1.0), at(&repeat, 4.0), at(&repeat, 5.0)],
            [4.0, 1.0, 2.0]
        );
        let clamp = image(Wrap::Clamp);
        assert_eq!(
            [at(&clamp, -1.0), at(&clamp, 4.0), at(&clamp, 5.0)],
            [1.0, 4.0, 4.0]
        );
        let mirror = image(Wrap::Mirror);
        assert_eq!(
            [at(&mirror, -1.0), at(&mirror, 4.0), at(&mirror, 5.0)],
            [1.0, 4.0, 3.0]
        );
        let black = image(Wrap::Black);
        assert_eq!(
            [at(&black, -1.0), at(&black, 4.0), at(&black, 1.0)],
            [0.0, 0.0, 2.0]
        );
        // Halfway from the last texel to beyond it: repeat blends 4 with 1, clamp keeps 4.
        assert!((at(&repeat, 3.5) - 2.5).abs() < 1e-12);
        assert!((at(&clamp, 3.5) - 4.0).abs() < 1e-12);
    }

    #[test]
    fn bilinear_interpolates_between_texel_centres() {
        let img = ImageTexture::new(2, 1, vec![Color::BLACK, Color::WHITE], [1.0, 1.0]).unwrap();
        // Halfway between the two texel centres (u = 0.25 and u = 0.75).
        let c = img.bilinear([0.5, 0.5]);
        assert!((c.r - 0.5).abs() < 1e-12);
        assert!((img.bilinear([0.25, 0.5]).r - 0.0).abs() < 1e-12);
    }
}
