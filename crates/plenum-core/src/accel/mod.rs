//! Acceleration structures. A bounding-volume hierarchy serves both levels of the scene: the
//! primitives of a scene, and the triangles inside each mesh.

mod bvh;

pub use bvh::Bvh;
