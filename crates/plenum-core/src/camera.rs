//! The pinhole camera: rays from one eye point through the image plane.

use crate::math::{Ray, Vec3};

/// Where the camera is and what it sees; the resolution is chosen at render time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSettings {
    pub position: Vec3,
    pub look_at: Vec3,
    pub up: Vec3,
    /// Vertical field of view, in degrees.
    pub fov_degrees: f64,
}

impl Default for CameraSettings {
    fn default() -> Self {
        CameraSettings {
            position: Vec3::new(0.0, 0.0, 5.0),
            look_at: Vec3::ZERO,
            up: Vec3::Y,
            fov_degrees: 45.0,
        }
    }
}

/// A pinhole camera for an image of `width` × `height` pixels.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    position: Vec3,
    /// Ray direction through the top-left image corner.
    corner: Vec3,
    /// Direction change per pixel to the right and per pixel down.
    right: Vec3,
    down: Vec3,
}

impl Camera {
    pub fn new(s: &CameraSettings, width: u32, height: u32) -> Camera {
        let forward = (s.look_at - s.position).normalized();
        let right = forward.cross(s.up).normalized();
        let up = right.cross(forward);
        let half_height = (s.fov_degrees.to_radians() * 0.5).tan();
        let half_width = half_height * width as f64 / height as f64;
        Camera {
            position: s.position,
            corner: forward - right * half_width + up * half_height,
            right: right * (2.0 * half_width / width as f64),
            down: -up * (2.0 * half_height / height as f64),
        }
    }

    /// The ray through raster position (x, y): (0, 0) is the top-left corner of the image
    /// and (width, height) the bottom-right; pixel (i, j) covers [i, i+1) × [j, j+1).
    pub fn ray(&self, x: f64, y: f64) -> Ray {
        let d = self.corner + self.right * x + self.down * y;
        Ray::new(self.position, d.normalized())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_looks_at_target_and_edges_span_the_fov() {
        let s = CameraSettings {
            position: Vec3::new(0.0, 0.0, 10.0),
            look_at: Vec3::ZERO,
            up: Vec3::Y,
            fov_degrees: 90.0,
        };
        let cam = Camera::new(&s, 200, 100);
        let centre = cam.ray(100.0, 50.0);
        assert!((centre.direction - -Vec3::Z).length() < 1e-12);
        // The top edge is 45° up; the right edge 2× as far out on the image plane.
        let top = cam.ray(100.0, 0.0).direction;
        assert!((top.y / -top.z - 1.0).abs() < 1e-12);
        let right = cam.ray(200.0, 50.0).direction;
        assert!((right.x / -right.z - 2.0).abs() < 1e-12);
    }
}
