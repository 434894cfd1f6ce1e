//! Random numbers and pixel sample patterns.
//!
//! **Invariant:** a sample's random numbers derive from (seed, pixel, sample index) alone,
//! never from the thread that computes it, so images do not depend on the thread count.

mod pixel;
mod rng;

pub use pixel::{PixelSampler, SamplerKind, MAX_SPP};
pub use rng::Rng;
