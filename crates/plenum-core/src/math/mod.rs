//! Vectors, rays, bounds, transforms and floating-point error bounds.

mod bounds;
pub mod float;
mod motion;
mod ray;
mod transform;
mod vector;

pub use bounds::Bounds3;
pub use float::{gamma, offset_ray_origin, solve_quadratic};
pub use motion::Motion;
pub use ray::Ray;
pub use transform::{Matrix4, Transform};
pub use vector::Vec3;
