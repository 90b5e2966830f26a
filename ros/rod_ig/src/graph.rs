//! The node's default name and the names of its topics and services: a leaf module, so that
//! the argument parser ([`crate::params`]) and the node's wiring ([`crate::node`]) both use
//! them without depending on each other.

/// The node's name.
pub const NODE_NAME: &str = "rod_ig_node";

/// The node's relative topic and service names (resolved through
/// [`crate::ros_args::NodeIdentity`]).
pub mod names {
    /// Targets in (geometry_msgs/PoseStamped).
    pub const TARGET: &str = "rod/target";
    /// Rod shape out (nav_msgs/Path).
    pub const PATH: &str = "rod/path";
    /// Solution out (rod_ig_msgs/RodSolution).
    pub const SOLUTION: &str = "rod/solution";
    /// RViz marker out (visualization_msgs/Marker).
    pub const MARKER: &str = "rod/marker";
    /// The service (rod_ig_msgs/srv/SolveRod).
    pub const SOLVE: &str = "rod/solve";
    /// The planning service (rod_ig_msgs/srv/PlanRod).
    pub const PLAN: &str = "rod/plan";
    /// The planned rods (visualization_msgs/Marker, LINE_LIST).
    pub const PLAN_RODS: &str = "rod/plan_rods";
    /// Diagnostics out (diagnostic_msgs/DiagnosticArray): absolute, as diagnostic_updater's.
    pub const DIAGNOSTICS: &str = "/diagnostics";
    /// The base wrench out (geometry_msgs/WrenchStamped), with `bending_stiffness` set.
    pub const BASE_WRENCH: &str = "rod/base_wrench";
    /// The tip wrench out (geometry_msgs/WrenchStamped, tip frame), with `bending_stiffness` set.
    pub const TIP_WRENCH: &str = "rod/tip_wrench";
    /// Transforms in (tf2_msgs/TFMessage), absolute as tf2's.
    pub const TF: &str = "/tf";
    /// Static transforms in (tf2_msgs/TFMessage, transient local).
    pub const TF_STATIC: &str = "/tf_static";
}
