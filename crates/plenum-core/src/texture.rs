//! Textures: colours that vary over a surface. 2-D textures are looked up by the surface's
//! (u, v); solid textures by the hit point in the object's own coordinates, so they move
//! with the object.

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
}

/// Where a texture is looked up.
#[derive(Clone, Copy, Debug)]
pub struct TextureCoords {
    pub uv: [f64; 2],
    /// The hit point in the object's coordinates.
    pub object_point: Vec3,
}

impl Texture {
    pub fn evaluate(&self, at: &TextureCoords) -> Color {
        match self {
            Texture::Constant(c) => *c,
            Texture::Checker2d { even, odd, scale } => {
                let s = (at.uv[0] * scale).floor() + (at.uv[1] * scale).floor();
                if s.rem_euclid(2.0) == 0.0 {
                    *even
                } else {
                    *odd
                }
            }
            Texture::Checker3d { even, odd, scale } => {
                let p = at.object_point * *scale;
                let s = p.x.floor() + p.y.floor() + p.z.floor();
                if s.rem_euclid(2.0) == 0.0 {
                    *even
                } else {
                    *odd
                }
            }
            Texture::Image(image) => image.bilinear(at.uv),
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
        }
    }
}

/// An image in linear RGB, repeated over (u, v) with (0, 0) at the bottom-left corner.
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
        })
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
        let x = x.rem_euclid(self.width as i64) as usize;
        let y = y.rem_euclid(self.height as i64) as usize;
        self.texels[y * self.width + x]
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
    use super::*;

    fn at(u: f64, v: f64) -> TextureCoords {
        TextureCoords {
            uv: [u, v],
            object_point: Vec3::new(u, v, 0.0),
        }
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
    fn bilinear_interpolates_between_texel_centres() {
        let img = ImageTexture::new(2, 1, vec![Color::BLACK, Color::WHITE], [1.0, 1.0]).unwrap();
        // Halfway between the two texel centres (u = 0.25 and u = 0.75).
        let c = img.bilinear([0.5, 0.5]);
        assert!((c.r - 0.5).abs() < 1e-12);
        assert!((img.bilinear([0.25, 0.5]).r - 0.0).abs() < 1e-12);
    }
}
