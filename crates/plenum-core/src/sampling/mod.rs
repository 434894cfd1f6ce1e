//! Random numbers, pixel sample patterns, warps and tabulated distributions.
//!
//! **Invariant:** a sample's random numbers derive from (seed, pixel, sample index) alone,
//! never from the thread that computes it, so images do not depend on the thread count.

#[cfg(test)]
pub(crate) mod chi_square;
mod distribution;
mod filter;
mod mis;
mod pixel;
mod rng;
mod warp;

pub use distribution::{AliasTable, PiecewiseConstant1D, PiecewiseConstant2D};
pub use filter::{Filter, FilterKind, FilterSample};
pub use mis::power_heuristic;
pub use pixel::{permute, PixelSampler, SampleStream, SamplerKind, MAX_SPP};
pub use rng::Rng;
pub use warp::*;
