//! The Plenum renderer: geometry, acceleration, cameras, materials, lights and integrators.
//!
//! **Architecture invariant:** this crate does no file I/O and knows no file format. Scenes
//! arrive already built (see `plenum-scene`); images leave as a [`film::Film`] of linear RGB.

pub mod accel;
pub mod geometry;
pub mod math;
