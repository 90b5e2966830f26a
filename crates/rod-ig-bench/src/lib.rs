//! # rod-ig-bench
//!
//! The benchmark harness of rod-ig: sampled workloads (paper Table 1 protocol, random stable
//! rods in a box, tracking paths, 3-D random targets) and the report structs the CLI's
//! `rod-ig bench` prints and the solver tests assert on. It lives outside the math crate
//! (`rod-ig-core`), which it uses only through its public API; criterion benches of the hot
//! functions stay next to them in `rod-ig-core/benches`.
#![warn(missing_docs)]

pub mod families;
pub mod planar;
pub mod spatial;

pub use rod_ig_core::rng::SplitMix64;
