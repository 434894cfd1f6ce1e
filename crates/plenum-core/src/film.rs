//! The film: linear RGB radiance per pixel, row-major from the top-left.

use crate::color::Color;

#[derive(Clone, Debug)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    pixels: Vec<[f32; 3]>,
}

impl Film {
    pub fn new(width: u32, height: u32) -> Film {
        Film {
            width,
            height,
            pixels: vec![[0.0; 3]; width as usize * height as usize],
        }
    }

    pub fn set(&mut self, x: u32, y: u32, c: Color) {
        let i = y as usize * self.width as usize + x as usize;
        self.pixels[i] = [c.r as f32, c.g as f32, c.b as f32];
    }

    pub fn get(&self, x: u32, y: u32) -> Color {
        let p = self.pixels[y as usize * self.width as usize + x as usize];
        Color::new(p[0] as f64, p[1] as f64, p[2] as f64)
    }

    pub fn pixels(&self) -> &[[f32; 3]] {
        &self.pixels
    }
}
