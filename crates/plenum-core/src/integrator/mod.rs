//! Integrators: turn a camera ray into the radiance it carries back.

mod medium;
mod ray_tree;
mod whitted;

pub use medium::MediumStack;
pub use ray_tree::{RayKind, RayNode, RayTree, ShadowInfo, Stop};
pub use whitted::{RayCounts, Whitted, WhittedConfig, MAX_DEPTH};
