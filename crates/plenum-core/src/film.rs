//! The film: linear RGB radiance per pixel, row-major from the top-left.
//!
//! It accumulates two kinds of contribution, as pbrt-v4's `RGBFilm` does: weighted samples
//! of a pixel's own estimate (`add_sample`: the pixel is Σ w·L / Σ w), and splats, which
//! integrators that start paths on the lights (light tracing, bidirectional path tracing)
//! add to whatever pixel a path reaches (`add_splat`: summed, then scaled once by
//! `resolve`, by 1/spp for such an integrator). Splats are added in a fixed order by the
//! caller, so the image stays the same for any thread count.

use crate::color::Color;

#[derive(Clone, Debug)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    /// Σ w·L and Σ w per pixel.
    samples: Vec<[f64; 4]>,
    /// Σ L of the splats per pixel.
    splats: Vec<[f64; 3]>,
    /// The resolved image.
    pixels: Vec<[f32; 3]>,
}

impl Film {
    pub fn new(width: u32, height: u32) -> Film {
        let n = width as usize * height as usize;
        Film {
            width,
            height,
            samples: vec![[0.0; 4]; n],
            splats: vec![[0.0; 3]; n],
            pixels: vec![[0.0; 3]; n],
        }
    }

    fn index(&self, x: u32, y: u32) -> usize {
        y as usize * self.width as usize + x as usize
    }

    /// Sets pixel (x, y)'s own estimate to `c`, replacing its samples.
    pub fn set(&mut self, x: u32, y: u32, c: Color) {
        let i = self.index(x, y);
        self.samples[i] = [c.r, c.g, c.b, 1.0];
        self.pixels[i] = [c.r as f32, c.g as f32, c.b as f32];
    }

    /// Adds a sample of radiance `c` with filter weight `w` to pixel (x, y).
    pub fn add_sample(&mut self, x: u32, y: u32, c: Color, w: f64) {
        let i = self.index(x, y);
        let s = &mut self.samples[i];
        s[0] += w * c.r;
        s[1] += w * c.g;
        s[2] += w * c.b;
        s[3] += w;
    }

    /// Adds `c` to the pixel that raster point (px, py) falls in (a box filter); points off
    /// the film are dropped.
    pub fn add_splat(&mut self, px: f64, py: f64, c: Color) {
        if !(px >= 0.0 && py >= 0.0 && px < self.width as f64 && py < self.height as f64) {
            return;
        }
        let i = self.index(px as u32, py as u32);
        let s = &mut self.splats[i];
        s[0] += c.r;
        s[1] += c.g;
        s[2] += c.b;
    }

    /// Makes the image: each pixel's weighted mean of its samples (black without any) plus
    /// its splats times `splat_scale`.
    pub fn resolve(&mut self, splat_scale: f64) {
        for ((p, s), sp) in self.pixels.iter_mut().zip(&self.samples).zip(&self.splats) {
            let inv = if s[3] != 0.0 { 1.0 / s[3] } else { 0.0 };
            for c in 0..3 {
                p[c] = (s[c] * inv + sp[c] * splat_scale) as f32;
            }
        }
    }

    /// The resolved pixel (x, y).
    pub fn get(&self, x: u32, y: u32) -> Color {
        let p = self.pixels[self.index(x, y)];
        Color::new(p[0] as f64, p[1] as f64, p[2] as f64)
    }

    /// The resolved image, row by row.
    pub fn pixels(&self) -> &[[f32; 3]] {
        &self.pixels
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_average_by_weight_and_splats_add_scaled() {
        let mut film = Film::new(2, 2);
        film.add_sample(0, 0, Color::new(1.0, 2.0, 3.0), 1.0);
        film.add_sample(0, 0, Color::new(3.0, 2.0, 1.0), 3.0);
        film.add_splat(1.5, 0.2, Color::gray(4.0));
        film.add_splat(1.9, 0.9, Color::gray(2.0));
        film.add_splat(-0.1, 0.5, Color::gray(100.0));
        film.add_splat(2.0, 0.5, Color::gray(100.0));
        film.set(0, 1, Color::gray(0.5));
        film.resolve(0.25);
        assert_eq!(film.get(0, 0), Color::new(2.5, 2.0, 1.5));
        assert_eq!(film.get(1, 0), Color::gray(1.5));
        assert_eq!(film.get(0, 1), Color::gray(0.5));
        assert_eq!(film.get(1, 1), Color::BLACK);
    }
}
