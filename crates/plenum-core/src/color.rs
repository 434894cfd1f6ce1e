//! Linear RGB colours: radiance, reflectances and weights.

use std::ops::{Add, AddAssign, Div, Mul, MulAssign};

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Color {
    pub r: f64,
    pub g: f64,
    pub b: f64,
}

impl Color {
    pub const BLACK: Color = Color::new(0.0, 0.0, 0.0);
    pub const WHITE: Color = Color::new(1.0, 1.0, 1.0);

    pub const fn new(r: f64, g: f64, b: f64) -> Self {
        Color { r, g, b }
    }

    pub const fn gray(v: f64) -> Self {
        Color::new(v, v, v)
    }

    pub fn max_component(self) -> f64 {
        self.r.max(self.g).max(self.b)
    }

    pub fn is_black(self) -> bool {
        self.r == 0.0 && self.g == 0.0 && self.b == 0.0
    }

    pub fn to_array(self) -> [f64; 3] {
        [self.r, self.g, self.b]
    }

    /// Rec. 709 luminance.
    pub fn luminance(self) -> f64 {
        0.2126 * self.r + 0.7152 * self.g + 0.0722 * self.b
    }
}

impl Add for Color {
    type Output = Color;
    fn add(self, o: Color) -> Color {
        Color::new(self.r + o.r, self.g + o.g, self.b + o.b)
    }
}

impl AddAssign for Color {
    fn add_assign(&mut self, o: Color) {
        *self = *self + o;
    }
}

impl Mul for Color {
    type Output = Color;
    fn mul(self, o: Color) -> Color {
        Color::new(self.r * o.r, self.g * o.g, self.b * o.b)
    }
}

impl MulAssign for Color {
    fn mul_assign(&mut self, o: Color) {
        *self = *self * o;
    }
}

impl Mul<f64> for Color {
    type Output = Color;
    fn mul(self, s: f64) -> Color {
        Color::new(self.r * s, self.g * s, self.b * s)
    }
}

impl Div<f64> for Color {
    type Output = Color;
    fn div(self, s: f64) -> Color {
        self * (1.0 / s)
    }
}

impl From<[f64; 4]> for Color {
    /// The first three lanes of a sampled spectrum, as seen in RGB mode (the ray tree's
    /// weights; spectral lanes are shown as they are).
    fn from(v: [f64; 4]) -> Color {
        Color::new(v[0], v[1], v[2])
    }
}
