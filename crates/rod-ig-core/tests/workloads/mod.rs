//! The benchmark workloads of `crates/rod-ig-bench`, compiled into these tests and benches from
//! that crate's sources: a dev-dependency on rod-ig-bench (which depends on this crate) would
//! be a dependency cycle, which colcon cannot order.
#![allow(dead_code, unused_imports)]

#[path = "../../../rod-ig-bench/src/planar.rs"]
pub mod planar;
#[path = "../../../rod-ig-bench/src/spatial.rs"]
pub mod spatial;

pub use rod_ig_core::rng::SplitMix64;
