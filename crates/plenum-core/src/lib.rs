//! The Plenum renderer: geometry, acceleration, cameras, materials, lights and integrators.
//!
//! **Architecture invariant:** this crate does no file I/O and knows no file format. Scenes
//! arrive already built (see `plenum-scene`); images leave as a [`film::Film`] of linear RGB.

pub mod accel;
pub mod aov;
pub mod bxdf;
pub mod camera;
pub mod color;
pub mod environment;
pub mod film;
pub mod geometry;
pub mod integrator;
#[cfg(test)]
mod kit;
pub mod light;
pub mod light_sampler;
pub mod material;
pub mod math;
pub mod optics;
pub mod raw_film;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod settings;
pub mod texture;

pub use color::Color;
pub use math::Vec3;
