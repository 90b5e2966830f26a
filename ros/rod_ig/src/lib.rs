//! # rod-ig-node
//!
//! A ROS 2 node (`rod_ig_node`) serving the inverse geometry of a planar elastic rod held by
//! two grippers: a thin adapter between ROS messages and the solver crate `rod_ig_core`.
//!
//! - [`params`]: parameters, start-up arguments (`-p`, `--params-file`), validation.
//! - [`messages`]: serde mirrors of the ROS message types (byte-checked against rclpy).
//! - [`convert`]: pose ↔ planar target, scaling by rod length and stiffness, path building.
//! - [`solver`]: the only module that calls `rod_ig_core`.
//! - [`pipeline`]: one target in, the messages to publish out (no DDS).
//! - [`diagnostics`]: the solve statistics reported on `/diagnostics`.
//! - [`graph`]: the node's name and its topic and service names.
//! - [`node`]: DDS context, topics, service, parameters and tasks.
//! - [`tf_buffer`]: transforms from `/tf` and `/tf_static` with tf2's semantics.
#![warn(missing_docs)]

pub mod convert;
pub mod diagnostics;
pub mod graph;
pub mod messages;
pub mod node;
pub mod params;
pub mod pipeline;
pub mod ros_args;
pub mod solver;
pub mod tf_buffer;
