//! The camera: a pinhole, or a thin lens with an aperture and a focus distance (depth of
//! field), optionally moving while its shutter is open (motion blur).
//!
//! Times: objects and the camera are posed at time 0 (shutter open) and time 1 (shutter
//! close) and move in between; each ray's time is drawn uniformly from the shutter interval.

use crate::math::{Ray, Vec3};
use crate::sampling::{concentric_disk, regular_polygon};

/// The lens: a pinhole when `radius` is zero.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lens {
    /// Radius of the aperture, in scene units.
    pub radius: f64,
    /// Distance along the view direction to the plane in sharp focus.
    pub focus_distance: f64,
    /// Number of aperture blades: 0 for a round aperture, 3 or more for a regular polygon,
    /// which gives out-of-focus highlights that shape (bokeh).
    pub blades: u32,
    /// Turn of the polygonal aperture, in degrees.
    pub rotation_degrees: f64,
}

impl Default for Lens {
    fn default() -> Self {
        Lens {
            radius: 0.0,
            focus_distance: 1.0,
            blades: 0,
            rotation_degrees: 0.0,
        }
    }
}

/// Where the camera is and what it sees; the resolution is chosen at render time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSettings {
    pub position: Vec3,
    pub look_at: Vec3,
    pub up: Vec3,
    /// Vertical field of view, in degrees.
    pub fov_degrees: f64,
    pub lens: Lens,
    /// Times the shutter opens and closes; rays are spread uniformly between them.
    pub shutter: [f64; 2],
    /// Where the camera is and looks at time 1, when it moves; at time 0 it is at
    /// `position` looking at `look_at`, and in between on the straight line.
    pub motion: Option<(Vec3, Vec3)>,
}

impl Default for CameraSettings {
    fn default() -> Self {
        CameraSettings {
            position: Vec3::new(0.0, 0.0, 5.0),
            look_at: Vec3::ZERO,
            up: Vec3::Y,
            fov_degrees: 45.0,
            lens: Lens::default(),
            shutter: [0.0, 1.0],
            motion: None,
        }
    }
}

/// The camera's frame at one moment.
#[derive(Clone, Copy, Debug)]
struct Frame {
    position: Vec3,
    forward: Vec3,
    /// Unit vectors to the right of and above the view direction.
    right: Vec3,
    up: Vec3,
}

impl Frame {
    fn new(position: Vec3, look_at: Vec3, up: Vec3) -> Frame {
        let forward = (look_at - position).normalized();
        let right = forward.cross(up).normalized();
        Frame {
            position,
            forward,
            right,
            up: right.cross(forward),
        }
    }
}

/// A camera for an image of `width` × `height` pixels.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    settings: CameraSettings,
    frame: Frame,
    /// Half the image plane's extent at distance 1, and its size per pixel.
    half_width: f64,
    half_height: f64,
    pixel_size: f64,
}

impl Camera {
    pub fn new(s: &CameraSettings, width: u32, height: u32) -> Camera {
        let half_height = (s.fov_degrees.to_radians() * 0.5).tan();
        Camera {
            settings: *s,
            frame: Frame::new(s.position, s.look_at, s.up),
            half_width: half_height * width as f64 / height as f64,
            half_height,
            pixel_size: 2.0 * half_height / height as f64,
        }
    }

    /// The ray through raster position (x, y) from the lens centre at time 0: (0, 0) is the
    /// top-left corner of the image and (width, height) the bottom-right; pixel (i, j) covers
    /// [i, i+1) × [j, j+1).
    pub fn ray(&self, x: f64, y: f64) -> Ray {
        let d = self.direction(&self.frame, x, y);
        Ray::new(self.frame.position, d.normalized())
    }

    /// The ray through raster position (x, y) from the lens point `lens` ∈ [0, 1)² at the
    /// shutter fraction `shutter` ∈ [0, 1).
    pub fn sample_ray(&self, x: f64, y: f64, lens: [f64; 2], shutter: f64) -> Ray {
        let [open, close] = self.settings.shutter;
        let time = open + (close - open) * shutter;
        let frame = match self.settings.motion {
            None => self.frame,
            Some((position, look_at)) => {
                let s = &self.settings;
                let t = time.clamp(0.0, 1.0);
                Frame::new(
                    s.position + (position - s.position) * t,
                    s.look_at + (look_at - s.look_at) * t,
                    s.up,
                )
            }
        };
        let d = self.direction(&frame, x, y);
        let l = &self.settings.lens;
        if l.radius <= 0.0 {
            return Ray::new(frame.position, d.normalized()).at_time(time);
        }
        // Every ray through the same image point meets the others on the plane of focus.
        let focus = frame.position + d * l.focus_distance;
        let (lx, ly) = if l.blades >= 3 {
            let (px, py) = regular_polygon(lens, l.blades);
            let (s, c) = l.rotation_degrees.to_radians().sin_cos();
            (px * c - py * s, px * s + py * c)
        } else {
            concentric_disk(lens)
        };
        let origin = frame.position + (frame.right * lx + frame.up * ly) * l.radius;
        Ray::new(origin, (focus - origin).normalized()).at_time(time)
    }

    /// The direction through raster (x, y), with unit length along the view direction.
    fn direction(&self, f: &Frame, x: f64, y: f64) -> Vec3 {
        f.forward
            + f.right * (x * self.pixel_size - self.half_width)
            + f.up * (self.half_height - y * self.pixel_size)
    }

    /// Size of one pixel on a plane facing the camera at distance `depth`, in scene units.
    pub fn pixel_footprint(&self, depth: f64) -> f64 {
        self.pixel_size * depth
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
            ..CameraSettings::default()
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
