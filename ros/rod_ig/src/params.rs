//! The node's parameters: defaults, validation, start-up parsing (command line and ROS 2
//! parameter YAML files) and conversion to and from ROS `ParameterValue`s.
//!
//! ros2-client does not parse `--ros-args`; [`parse_args`] reads the command line with
//! [`crate::ros_args`] (remapping, namespaces, `-p`, `--params-file`, `--log-level`, ...) and
//! applies the parameter sources in order. At run time the same validation
//! ([`Params::apply`]) guards the ROS parameter services.

use rod_ig_core::ends::EndCondition;
use std::path::{Path, PathBuf};

use ros2_client::ParameterValue;
use thiserror::Error;

use crate::ros_args::{self, NodeIdentity, ParamSource};

/// Solver method, as named in the `method` parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Damped, guarded Newton that keeps the rod stable (default).
    Robust,
    /// The paper's plain Newton iteration.
    Newton,
}

impl Method {
    /// Parses "robust" / "newton" (case-insensitive).
    pub fn parse(s: &str) -> Result<Self, ParamError> {
        match s.trim().to_ascii_lowercase().as_str() {
            "robust" => Ok(Self::Robust),
            "newton" => Ok(Self::Newton),
            _ => Err(ParamError::Invalid {
                name: "method".into(),
                reason: format!("unknown method {s:?}, expected \"robust\" or \"newton\""),
            }),
        }
    }

    /// The parameter spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Robust => "robust",
            Self::Newton => "newton",
        }
    }
}

/// All parameters of `rod_ig_node`, always valid (construct with [`Params::default`] and
/// change with [`Params::apply`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Params {
    /// `rod_length` (m) > 0: physical length L of the rod.
    pub rod_length: f64,
    /// `base_frame`: frame_id used when a target's frame_id is empty.
    pub base_frame: String,
    /// `path_samples` in [2, 100000]: poses per published path.
    pub path_samples: usize,
    /// `tolerance` > 0: solver convergence tolerance (normalised units).
    pub tolerance: f64,
    /// `max_iterations` in [1, 100000].
    pub max_iterations: u32,
    /// `method`: "robust" or "newton".
    pub method: Method,
    /// `bending_stiffness` EI (N·m²) ≥ 0; 0 = unknown (no wrench or joules reported).
    pub bending_stiffness: f64,
    /// `linear_density` ρA (kg/m) ≥ 0: the rod's weight per length is ρA·|gravity| (0: no
    /// weight, the default). With weight, `bending_stiffness` and `gravity` are required.
    pub linear_density: f64,
    /// `gravity` (m/s², base frame): gravity's acceleration vector; [0, 0, 0] = not set.
    pub gravity: [f64; 3],
    /// `planar_tolerance` ≥ 0: largest |z| (m) and tilt out of the plane (rad) accepted.
    pub planar_tolerance: f64,
    /// `publish_marker`: publish the RViz line strip on /rod/marker.
    pub publish_marker: bool,
    /// `marker_width` (m) > 0: line width of the marker.
    pub marker_width: f64,
    /// `solve_3d`: answer non-planar targets (beyond `planar_tolerance`) with the 3-D solver
    /// instead of rejecting them (default false).
    pub solve_3d: bool,
    /// `follow_branch`: targets on `rod/target` move the gripper and the rod follows its
    /// equilibrium branch, snapping where it folds (`event` in RodSolution); false: each target
    /// is solved on its own from the previous solution (default true).
    pub follow_branch: bool,
    /// `deadline_ms` in (0, 10000]: wall-time budget of one solve (default 250 ms, the
    /// library's `ig::DEFAULT_DEADLINE`); a solve that runs out answers "deadline reached".
    pub deadline_ms: f64,
    /// `use_sim_time` (rclcpp's built-in): stamp outputs of targets stamped zero with the time
    /// of `/clock` (rosgraph_msgs/msg/Clock) instead of the system clock.
    pub use_sim_time: bool,
    /// `use_tf`: a target stamped in another frame than `base_frame` is transformed into it
    /// through TF (`/tf`, `/tf_static`) at its stamp (stamp zero: the latest transform), and
    /// the outputs carry `base_frame`; false (default): a target's frame is taken as the base
    /// gripper's and echoed.
    pub use_tf: bool,
    /// `tf_timeout` in [0, 10] s: how long a target waits for its transform before it is
    /// refused with the frame named (default 0.2 s).
    pub tf_timeout: f64,
    /// `tip_frame`: when set, the node follows this TF frame (the tip gripper's) relative to
    /// `base_frame`, solving for each new pose as for a target on `rod/target` (default
    /// empty: off).
    pub tip_frame: String,
    /// `tf_rate` in (0, 1000] Hz: at most how often `tip_frame` is looked up, after TF updates
    /// (default 30).
    pub tf_rate: f64,
    /// `base_condition`: how the base gripper holds the rod, "clamped" (default) or "pinned"
    /// (position held, angle free: a hook or a pin joint; docs/ends.md).
    pub base_condition: EndCondition,
    /// `tip_condition`: "clamped" (default), "pinned" (the target's position is held, its
    /// orientation ignored) or "free" (nothing held: the cable hangs from its base, the target
    /// only asks for the answer).
    pub tip_condition: EndCondition,
    /// `world_frame`: when set (and `linear_density` > 0), gravity is −9.80665 m/s² along this
    /// TF frame's z, expressed in `base_frame` at each target's stamp (it replaces `gravity`);
    /// default empty: `gravity` as set.
    pub world_frame: String,
    /// `qos_overrides.<topic>.{subscription,publisher}.{reliability,durability,history,depth}`:
    /// the QoS of the target subscription and of every publisher, read-only (set at
    /// start-up), as rclcpp's `QosOverridingOptions`. Topics by their resolved names.
    pub qos_overrides: Vec<QosOverride>,
}

/// The QoS of one of the node's endpoints, as its `qos_overrides` parameters set it.
#[derive(Clone, Debug, PartialEq)]
pub struct QosOverride {
    /// The topic's name in [`crate::graph::names`] (before remapping).
    pub name: &'static str,
    /// Its resolved name (remapped, namespaced): it names the parameters.
    pub topic: String,
    /// `subscription` or `publisher`.
    pub role: &'static str,
    /// The QoS.
    pub qos: TopicQos,
}

/// The endpoints whose QoS the `qos_overrides` parameters set: the target subscription, then
/// the publishers.
const QOS_ENDPOINTS: [(&str, &str); 8] = {
    use crate::graph::names;
    [
        (names::TARGET, "subscription"),
        (names::PATH, "publisher"),
        (names::SOLUTION, "publisher"),
        (names::MARKER, "publisher"),
        (names::PLAN_RODS, "publisher"),
        (names::DIAGNOSTICS, "publisher"),
        (names::BASE_WRENCH, "publisher"),
        (names::TIP_WRENCH, "publisher"),
    ]
};

impl QosOverride {
    /// The node's endpoints at their defaults, their topics resolved by `resolve`.
    pub fn for_node<E>(resolve: impl Fn(&str) -> Result<String, E>) -> Result<Vec<Self>, E> {
        QOS_ENDPOINTS
            .iter()
            .map(|&(name, role)| {
                Ok(Self {
                    name,
                    topic: resolve(name)?,
                    role,
                    qos: TopicQos::default(),
                })
            })
            .collect()
    }
}

/// QoS of one endpoint (see [`Params::qos_overrides`]). The default, reliable + volatile +
/// keep last 10, matches rclpy's `create_publisher(T, topic, 10)`; a BEST_EFFORT (sensor data)
/// target publisher needs `reliability: best_effort` on the subscription, and an RViz display
/// or late joiner that asks for TRANSIENT_LOCAL needs `durability: transient_local` on the
/// publisher.
#[derive(Clone, Debug, PartialEq)]
pub struct TopicQos {
    /// `reliable` (default) or `best_effort`.
    pub best_effort: bool,
    /// `volatile` (default) or `transient_local`.
    pub transient_local: bool,
    /// `keep_last` (default) or `keep_all`.
    pub keep_all: bool,
    /// `depth` in [1, 10000] for keep_last (default 10).
    pub depth: i64,
}

impl Default for TopicQos {
    fn default() -> Self {
        Self {
            best_effort: false,
            transient_local: false,
            keep_all: false,
            depth: 10,
        }
    }
}

/// The QoS policies a `qos_overrides` parameter may set, in declaration order.
pub const QOS_POLICIES: [&str; 4] = ["reliability", "durability", "history", "depth"];

impl Default for Params {
    /// The defaults of the parameter table.
    fn default() -> Self {
        let mut p = Self {
            rod_length: 1.0,
            base_frame: String::new(),
            path_samples: 0,
            tolerance: 0.0,
            max_iterations: 0,
            method: Method::Robust,
            bending_stiffness: 0.0,
            linear_density: 0.0,
            gravity: [0.0; 3],
            planar_tolerance: 0.0,
            publish_marker: false,
            marker_width: 0.0,
            solve_3d: false,
            follow_branch: false,
            deadline_ms: 0.0,
            use_sim_time: false,
            use_tf: false,
            tf_timeout: 0.0,
            tip_frame: String::new(),
            tf_rate: 0.0,
            world_frame: String::new(),
            base_condition: EndCondition::Clamped,
            tip_condition: EndCondition::Clamped,
            qos_overrides: QosOverride::for_node(|n| {
                Ok::<_, std::convert::Infallible>(if n.starts_with('/') {
                    n.to_string()
                } else {
                    format!("/{n}")
                })
            })
            .unwrap_or_default(),
        };
        for spec in &TABLE {
            // The table's defaults are within its ranges (tested: `defaults`).
            let _ = (spec.set)(&mut p, &spec.default.value());
        }
        p
    }
}

/// Why a parameter or a start-up argument was rejected.
#[derive(Debug, Error, PartialEq)]
pub enum ParamError {
    /// No such parameter.
    #[error("unknown parameter '{0}' (known: {known})", known = names().collect::<Vec<_>>().join(", "))]
    Unknown(String),
    /// Wrong ROS type.
    #[error("parameter '{name}' must be {expected}, got {got}")]
    WrongType {
        /// Parameter name.
        name: String,
        /// Expected type.
        expected: &'static str,
        /// What was given.
        got: String,
    },
    /// Out of range or otherwise invalid.
    #[error("parameter '{name}': {reason}")]
    Invalid {
        /// Parameter name.
        name: String,
        /// Why.
        reason: String,
    },
    /// Bad command line.
    #[error("command line: {0}")]
    Args(String),
    /// Unreadable or malformed parameters file.
    #[error("parameters file {path}: {reason}")]
    File {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
}

/// A parameter's ROS type and the values it accepts.
#[derive(Clone, Copy, Debug)]
enum Kind {
    /// A finite double in [lo, hi] (hi may be infinite); `lo_open`: lo itself excluded.
    Double { lo: f64, hi: f64, lo_open: bool },
    /// An integer in [lo, hi].
    Integer { lo: i64, hi: i64 },
    /// A bool.
    Bool,
    /// A string, checked by the row's `set`.
    Str,
    /// Three finite doubles (a vector of the base frame).
    Vector3,
}

/// A parameter's default, as written in the table.
#[derive(Clone, Copy, Debug)]
enum DefaultValue {
    Double(f64),
    Integer(i64),
    Bool(bool),
    Str(&'static str),
    Vector3([f64; 3]),
}

/// One row of the parameter table: everything about one parameter, written once. The
/// descriptors (`ros2 param describe`), get, set, the params-file reader and `--help` all
/// come from [`TABLE`].
struct Spec {
    name: &'static str,
    kind: Kind,
    default: DefaultValue,
    /// Meaning and unit, as `ros2 param describe` shows it.
    description: &'static str,
    /// What a range cannot express (the allowed strings), or "".
    constraints: &'static str,
    /// The current value.
    get: fn(&Params) -> ParameterValue,
    /// How it applies: stores a value that passed `kind`'s check into [`Params`], which every
    /// request reads (strings are parsed and checked here).
    set: fn(&mut Params, &ParameterValue) -> Result<(), String>,
}

fn f64_of(v: &ParameterValue) -> f64 {
    match v {
        ParameterValue::Double(d) => *d,
        ParameterValue::Integer(i) => *i as f64,
        _ => f64::NAN,
    }
}

fn i64_of(v: &ParameterValue) -> i64 {
    match v {
        ParameterValue::Integer(i) => *i,
        _ => 0,
    }
}

fn bool_of(v: &ParameterValue) -> bool {
    matches!(v, ParameterValue::Boolean(true))
}

fn str_of(v: &ParameterValue) -> &str {
    match v {
        ParameterValue::String(s) => s,
        _ => "",
    }
}

const MAX_DEADLINE_MS: f64 = rod_ig_core::planar::ig::MAX_DEADLINE.as_secs_f64() * 1e3;
/// Most poses per published path: a nav_msgs/Path of 100,000 poses is ~6 MB.
const MAX_PATH_SAMPLES: i64 = 100_000;

/// Every parameter of `rod_ig_node` (beside the `qos_overrides` ones), in declaration order.
const TABLE: [Spec; 23] = [
    Spec {
        name: "rod_length",
        kind: Kind::Double {
            lo: 0.0,
            hi: f64::INFINITY,
            lo_open: true,
        },
        default: DefaultValue::Double(1.0),
        description: "Physical length L of the rod (m); outputs are scaled by it",
        constraints: "",
        get: |p| ParameterValue::Double(p.rod_length),
        set: |p, v| {
            p.rod_length = f64_of(v);
            Ok(())
        },
    },
    Spec {
        name: "base_frame",
        kind: Kind::Str,
        default: DefaultValue::Str("rod_base"),
        description: "frame_id used when a target's frame_id is empty (the base gripper's frame)",
        constraints: "a TF frame id: letters, digits, '_', '-', '.', '/' (not leading)",
        get: |p| ParameterValue::String(p.base_frame.clone()),
        set: |p, v| {
            p.base_frame = check_frame_id(str_of(v))?.to_string();
            Ok(())
        },
    },
    Spec {
        name: "path_samples",
        kind: Kind::Integer {
            lo: 2,
            hi: MAX_PATH_SAMPLES,
        },
        default: DefaultValue::Integer(100),
        description: "Poses per published nav_msgs/Path",
        constraints: "",
        get: |p| ParameterValue::Integer(p.path_samples as i64),
        set: |p, v| {
            p.path_samples = i64_of(v) as usize;
            Ok(())
        },
    },
    Spec {
        name: "tolerance",
        kind: Kind::Double {
            lo: rod_ig_core::planar::ig::MIN_TOLERANCE,
            hi: rod_ig_core::planar::ig::MAX_TOLERANCE,
            lo_open: false,
        },
        default: DefaultValue::Double(rod_ig_core::solver::DEFAULT_TOLERANCE),
        description: "Solver convergence tolerance on the tip pose (normalised by rod length)",
        constraints: "",
        get: |p| ParameterValue::Double(p.tolerance),
        set: |p, v| {
            p.tolerance = f64_of(v);
            Ok(())
        },
    },
    Spec {
        name: "max_iterations",
        kind: Kind::Integer {
            lo: 1,
            hi: rod_ig_core::planar::ig::MAX_ITERATIONS_LIMIT as i64,
        },
        default: DefaultValue::Integer(rod_ig_core::solver::DEFAULT_MAX_ITERATIONS as i64),
        description: "Solver iteration limit per start of the search (Newton: of the run)",
        constraints: "",
        get: |p| ParameterValue::Integer(i64::from(p.max_iterations)),
        set: |p, v| {
            p.max_iterations = i64_of(v) as u32;
            Ok(())
        },
    },
    Spec {
        name: "method",
        kind: Kind::Str,
        default: DefaultValue::Str("robust"),
        description: "Solver: robust (stable, default) or newton (the paper's iteration)",
        constraints: "robust or newton",
        get: |p| ParameterValue::String(p.method.as_str().into()),
        set: |p, v| {
            p.method = Method::parse(str_of(v)).map_err(|e| e.to_string())?;
            Ok(())
        },
    },
    Spec {
        name: "bending_stiffness",
        kind: Kind::Double {
            lo: 0.0,
            hi: f64::INFINITY,
            lo_open: false,
        },
        default: DefaultValue::Double(0.0),
        description:
            "Bending stiffness EI (N m^2) for the wrench and energy in joules; 0 = unknown",
        constraints: "",
        get: |p| ParameterValue::Double(p.bending_stiffness),
        set: |p, v| {
            p.bending_stiffness = f64_of(v);
            Ok(())
        },
    },
    Spec {
        name: "linear_density",
        kind: Kind::Double {
            lo: 0.0,
            hi: f64::INFINITY,
            lo_open: false,
        },
        default: DefaultValue::Double(0.0),
        description: "Mass per length of the rod (kg/m) for its weight; 0 = weightless (needs bending_stiffness and gravity when > 0)",
        constraints: "",
        get: |p| ParameterValue::Double(p.linear_density),
        set: |p, v| {
            p.linear_density = f64_of(v);
            Ok(())
        },
    },
    Spec {
        name: "gravity",
        kind: Kind::Vector3,
        default: DefaultValue::Vector3([0.0, 0.0, 0.0]),
        description: "Gravity's acceleration in the base frame (m/s^2), e.g. [0.0, -9.81, 0.0]; [0, 0, 0] = not set",
        constraints: "",
        get: |p| ParameterValue::DoubleArray(p.gravity.to_vec()),
        set: |p, v| {
            p.gravity = vector3("gravity", v).map_err(|e| e.to_string())?;
            Ok(())
        },
    },
    Spec {
        name: "planar_tolerance",
        kind: Kind::Double {
            lo: 0.0,
            hi: 0.5,
            lo_open: false,
        },
        default: DefaultValue::Double(1e-4),
        description: "Largest |z| (m) and tilt out of the plane (rad) accepted as planar",
        constraints: "",
        get: |p| ParameterValue::Double(p.planar_tolerance),
        set: |p, v| {
            p.planar_tolerance = f64_of(v);
            Ok(())
        },
    },
    Spec {
        name: "publish_marker",
        kind: Kind::Bool,
        default: DefaultValue::Bool(true),
        description: "Publish the RViz line strip on rod/marker",
        constraints: "",
        get: |p| ParameterValue::Boolean(p.publish_marker),
        set: |p, v| {
            p.publish_marker = bool_of(v);
            Ok(())
        },
    },
    Spec {
        name: "marker_width",
        kind: Kind::Double {
            lo: 0.0,
            hi: f64::INFINITY,
            lo_open: true,
        },
        default: DefaultValue::Double(0.01),
        description: "Line width of the marker (m)",
        constraints: "",
        get: |p| ParameterValue::Double(p.marker_width),
        set: |p, v| {
            p.marker_width = f64_of(v);
            Ok(())
        },
    },
    Spec {
        name: "solve_3d",
        kind: Kind::Bool,
        default: DefaultValue::Bool(false),
        description: "Answer non-planar targets with the 3-D solver instead of rejecting them",
        constraints: "",
        get: |p| ParameterValue::Boolean(p.solve_3d),
        set: |p, v| {
            p.solve_3d = bool_of(v);
            Ok(())
        },
    },
    Spec {
        name: "follow_branch",
        kind: Kind::Bool,
        default: DefaultValue::Bool(true),
        description: "rod/target moves the gripper: the rod follows its branch and snaps where it \
                      folds (event in RodSolution); false: independent solves",
        constraints: "",
        get: |p| ParameterValue::Boolean(p.follow_branch),
        set: |p, v| {
            p.follow_branch = bool_of(v);
            Ok(())
        },
    },
    Spec {
        name: "deadline_ms",
        kind: Kind::Double {
            lo: 0.0,
            hi: MAX_DEADLINE_MS,
            lo_open: true,
        },
        default: DefaultValue::Double(
            rod_ig_core::planar::ig::DEFAULT_DEADLINE.as_secs_f64() * 1e3,
        ),
        description: "Wall-time budget of one solve (ms); a solve that runs out answers \
                      'deadline reached'",
        constraints: "",
        get: |p| ParameterValue::Double(p.deadline_ms),
        set: |p, v| {
            p.deadline_ms = f64_of(v);
            Ok(())
        },
    },
    Spec {
        name: "use_sim_time",
        kind: Kind::Bool,
        default: DefaultValue::Bool(false),
        description: "Use /clock (rosgraph_msgs/Clock) as the node's time",
        constraints: "",
        get: |p| ParameterValue::Boolean(p.use_sim_time),
        set: |p, v| {
            p.use_sim_time = bool_of(v);
            Ok(())
        },
    },
    Spec {
        name: "use_tf",
        kind: Kind::Bool,
        default: DefaultValue::Bool(false),
        description: "Transform targets stamped in another frame into base_frame through TF \
                      (/tf, /tf_static) at their stamp; false: a target's frame is the base's",
        constraints: "",
        get: |p| ParameterValue::Boolean(p.use_tf),
        set: |p, v| {
            p.use_tf = bool_of(v);
            Ok(())
        },
    },
    Spec {
        name: "tf_timeout",
        kind: Kind::Double {
            lo: 0.0,
            hi: 10.0,
            lo_open: false,
        },
        default: DefaultValue::Double(0.2),
        description: "How long a target waits for its transform (s) before it is refused",
        constraints: "",
        get: |p| ParameterValue::Double(p.tf_timeout),
        set: |p, v| {
            p.tf_timeout = f64_of(v);
            Ok(())
        },
    },
    Spec {
        name: "tip_frame",
        kind: Kind::Str,
        default: DefaultValue::Str(""),
        description: "Follow this TF frame (the tip gripper's) relative to base_frame: each new \
                      pose is solved as a target on rod/target; empty: off",
        constraints: "empty, or a TF frame id",
        get: |p| ParameterValue::String(p.tip_frame.clone()),
        set: |p, v| {
            p.tip_frame = optional_frame_id(str_of(v))?;
            Ok(())
        },
    },
    Spec {
        name: "tf_rate",
        kind: Kind::Double {
            lo: 0.0,
            hi: 1000.0,
            lo_open: true,
        },
        default: DefaultValue::Double(30.0),
        description: "At most how often tip_frame is looked up in TF, after its updates (Hz)",
        constraints: "",
        get: |p| ParameterValue::Double(p.tf_rate),
        set: |p, v| {
            p.tf_rate = f64_of(v);
            Ok(())
        },
    },
    Spec {
        name: "world_frame",
        kind: Kind::Str,
        default: DefaultValue::Str(""),
        description: "With weight: gravity is -9.80665 m/s^2 along this TF frame's z, in \
                      base_frame at each target's stamp (replaces gravity); empty: gravity",
        constraints: "empty, or a TF frame id",
        get: |p| ParameterValue::String(p.world_frame.clone()),
        set: |p, v| {
            p.world_frame = optional_frame_id(str_of(v))?;
            Ok(())
        },
    },
    Spec {
        name: "base_condition",
        kind: Kind::Str,
        default: DefaultValue::Str("clamped"),
        description: "How the base gripper holds the rod: clamped (pose) or pinned (position \
                      only, angle free)",
        constraints: "clamped or pinned",
        get: |p| ParameterValue::String(p.base_condition.name().into()),
        set: |p, v| {
            p.base_condition = end_condition("base_condition", str_of(v), false)?;
            Ok(())
        },
    },
    Spec {
        name: "tip_condition",
        kind: Kind::Str,
        default: DefaultValue::Str("clamped"),
        description: "How the tip gripper holds the rod: clamped (pose), pinned (position only) \
                      or free (the cable hangs from its base)",
        constraints: "clamped, pinned or free",
        get: |p| ParameterValue::String(p.tip_condition.name().into()),
        set: |p, v| {
            p.tip_condition = end_condition("tip_condition", str_of(v), true)?;
            Ok(())
        },
    },
];

/// An end condition parameter's value ("free" only where `free_allowed`).
fn end_condition(name: &str, v: &str, free_allowed: bool) -> Result<EndCondition, String> {
    match v.parse::<EndCondition>() {
        Ok(EndCondition::Free) if !free_allowed => Err(format!(
            "{name} cannot be \"free\": the base gripper holds the rod (clamped or pinned)"
        )),
        Ok(c) => Ok(c),
        Err(_) => Err(format!(
            "{name} must be {}, got {v:?}",
            if free_allowed {
                "\"clamped\", \"pinned\" or \"free\""
            } else {
                "\"clamped\" or \"pinned\""
            }
        )),
    }
}

/// The row of parameter `name`.
fn spec(name: &str) -> Option<&'static Spec> {
    TABLE.iter().find(|s| s.name == name)
}

/// The names of all parameters (beside `qos_overrides`), in declaration order.
pub fn names() -> impl Iterator<Item = &'static str> {
    TABLE.iter().map(|s| s.name)
}

/// An optional TF frame id: empty (off), or one [`check_frame_id`] accepts.
fn optional_frame_id(id: &str) -> Result<String, String> {
    if id.is_empty() {
        Ok(String::new())
    } else {
        check_frame_id(id).map(str::to_string)
    }
}

/// Checks a TF frame id (REP 105 names such as `base_link`, `arm/base`): non-empty, letters,
/// digits, `_`, `-`, `.` and `/`, no leading `/` (tf2 rejects it), no empty segment.
pub fn check_frame_id(id: &str) -> Result<&str, String> {
    let ok_char = |c: char| c.is_ascii_alphanumeric() || "_-./".contains(c);
    if id.is_empty() || id.starts_with('/') || id.contains("//") || id.ends_with('/') {
        return Err(format!(
            "{id:?} is not a TF frame id (empty, or a leading, trailing or double '/')"
        ));
    }
    if let Some(c) = id.chars().find(|&c| !ok_char(c)) {
        return Err(format!(
            "{id:?} is not a TF frame id ({c:?}: use letters, digits, '_', '-', '.', '/')"
        ));
    }
    Ok(id)
}

impl Kind {
    /// Checks the type and range of `v` for parameter `name`.
    fn check(self, name: &str, v: &ParameterValue) -> Result<(), ParamError> {
        match self {
            Kind::Double { lo, hi, lo_open } => {
                let x = double(name, v)?;
                let above = if lo_open { x > lo } else { x >= lo };
                check(name, x.is_finite() && above && x <= hi, || {
                    format!("must be {}, got {x}", self.constraint())
                })
            }
            Kind::Integer { lo, hi } => integer(name, v, lo, hi).map(|_| ()),
            Kind::Bool => boolean(name, v).map(|_| ()),
            Kind::Str => match v {
                ParameterValue::String(_) => Ok(()),
                other => Err(ParamError::WrongType {
                    name: name.into(),
                    expected: "a string",
                    got: type_name(other),
                }),
            },
            Kind::Vector3 => vector3(name, v).map(|_| ()),
        }
    }

    /// The accepted values, in words ("> 0", "in [1e-14, 1e-2]").
    fn constraint(self) -> String {
        match self {
            Kind::Double { lo, hi, lo_open } if hi.is_infinite() => {
                format!("{} {lo}", if lo_open { ">" } else { ">=" })
            }
            Kind::Double { lo, hi, lo_open } => {
                let (lo, hi) = (number(lo), number(hi));
                format!("in {}{lo}, {hi}]", if lo_open { "(" } else { "[" })
            }
            Kind::Integer { lo, hi } => format!("in [{lo}, {hi}]"),
            Kind::Vector3 => "three finite numbers [x, y, z]".into(),
            Kind::Bool | Kind::Str => String::new(),
        }
    }

    /// The numeric range of the descriptor (ROS ranges include both bounds).
    fn range(self) -> Range {
        match self {
            Kind::Double { lo, hi, .. } if hi.is_finite() => Range::Double(lo, hi),
            Kind::Integer { lo, hi } => Range::Integer(lo, hi),
            _ => Range::Unbounded,
        }
    }
}

/// A bound as people write it: 0.5, 10000, 1e-14.
fn number(x: f64) -> String {
    if x != 0.0 && !(1e-3..1e5).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

impl DefaultValue {
    fn value(self) -> ParameterValue {
        match self {
            DefaultValue::Double(d) => ParameterValue::Double(d),
            DefaultValue::Integer(i) => ParameterValue::Integer(i),
            DefaultValue::Bool(b) => ParameterValue::Boolean(b),
            DefaultValue::Str(s) => ParameterValue::String(s.into()),
            DefaultValue::Vector3(v) => ParameterValue::DoubleArray(v.to_vec()),
        }
    }
}

/// Three finite numbers (a double or integer array of length 3).
fn vector3(name: &str, v: &ParameterValue) -> Result<[f64; 3], ParamError> {
    let values: Vec<f64> = match v {
        ParameterValue::DoubleArray(d) => d.clone(),
        ParameterValue::IntegerArray(i) => i.iter().map(|&x| x as f64).collect(),
        other => {
            return Err(ParamError::WrongType {
                name: name.into(),
                expected: "an array of three numbers",
                got: type_name(other),
            })
        }
    };
    match values[..] {
        [x, y, z] if values.iter().all(|v| v.is_finite()) => Ok([x, y, z]),
        _ => Err(ParamError::Invalid {
            name: name.into(),
            reason: format!("must be three finite numbers [x, y, z], got {values:?}"),
        }),
    }
}

/// A parameter's value as a user writes it (`250`, `true`, `"world"`, `[0, 0, -9.81]`).
fn value_text(v: &ParameterValue) -> String {
    match v {
        ParameterValue::NotSet => "not set".into(),
        ParameterValue::Boolean(b) => b.to_string(),
        ParameterValue::Integer(i) => i.to_string(),
        ParameterValue::Double(d) => d.to_string(),
        ParameterValue::String(s) => format!("{s:?}"),
        ParameterValue::DoubleArray(a) => format!("{a:?}"),
        other => format!("{other:?}"),
    }
}

fn type_name(v: &ParameterValue) -> String {
    match v {
        ParameterValue::NotSet => "not set".into(),
        ParameterValue::Boolean(b) => format!("bool {b}"),
        ParameterValue::Integer(i) => format!("integer {i}"),
        ParameterValue::Double(d) => format!("double {d}"),
        ParameterValue::String(s) => format!("string {s:?}"),
        other => format!("{:?}", other.to_parameter_type()),
    }
}

fn double(name: &str, v: &ParameterValue) -> Result<f64, ParamError> {
    match v {
        ParameterValue::Double(d) => Ok(*d),
        // Integers are accepted where a double is expected (`-p rod_length:=1`, YAML `1`).
        ParameterValue::Integer(i) => Ok(*i as f64),
        other => Err(ParamError::WrongType {
            name: name.into(),
            expected: "a double",
            got: type_name(other),
        }),
    }
}

fn integer(name: &str, v: &ParameterValue, lo: i64, hi: i64) -> Result<i64, ParamError> {
    match v {
        ParameterValue::Integer(i) if (lo..=hi).contains(i) => Ok(*i),
        ParameterValue::Integer(i) => Err(ParamError::Invalid {
            name: name.into(),
            reason: format!("{i} is outside [{lo}, {hi}]"),
        }),
        other => Err(ParamError::WrongType {
            name: name.into(),
            expected: "an integer",
            got: type_name(other),
        }),
    }
}

fn boolean(name: &str, v: &ParameterValue) -> Result<bool, ParamError> {
    match v {
        ParameterValue::Boolean(b) => Ok(*b),
        other => Err(ParamError::WrongType {
            name: name.into(),
            expected: "a bool",
            got: type_name(other),
        }),
    }
}

fn check(name: &str, ok: bool, reason: impl FnOnce() -> String) -> Result<(), ParamError> {
    if ok {
        Ok(())
    } else {
        Err(ParamError::Invalid {
            name: name.into(),
            reason: reason(),
        })
    }
}

/// One of `choices` (case-insensitive), as a string parameter.
fn choice(name: &str, v: &ParameterValue, choices: [&str; 2]) -> Result<bool, ParamError> {
    match v {
        ParameterValue::String(s) if s.trim().eq_ignore_ascii_case(choices[0]) => Ok(false),
        ParameterValue::String(s) if s.trim().eq_ignore_ascii_case(choices[1]) => Ok(true),
        ParameterValue::String(s) => Err(ParamError::Invalid {
            name: name.into(),
            reason: format!("{s:?} is not {} or {}", choices[0], choices[1]),
        }),
        other => Err(ParamError::WrongType {
            name: name.into(),
            expected: "a string",
            got: type_name(other),
        }),
    }
}

impl Params {
    /// The QoS of the endpoint on topic `name` (one of [`crate::graph::names`]).
    pub fn qos_of(&self, name: &str) -> TopicQos {
        self.qos_overrides
            .iter()
            .find(|o| o.name == name)
            .map(|o| o.qos.clone())
            .unwrap_or_default()
    }

    /// The name of the `qos_overrides` parameter for `policy` (one of [`QOS_POLICIES`]) of
    /// endpoint `o`.
    fn qos_parameter(o: &QosOverride, policy: &str) -> String {
        format!("qos_overrides.{}.{}.{policy}", o.topic, o.role)
    }

    /// The endpoint (index) and policy a `qos_overrides` parameter name sets, if it is one of
    /// this node's.
    fn qos_policy_of<'a>(&self, name: &'a str) -> Option<(usize, &'a str)> {
        let rest = name.strip_prefix("qos_overrides.")?;
        self.qos_overrides.iter().enumerate().find_map(|(i, o)| {
            rest.strip_prefix(o.topic.as_str())?
                .strip_prefix('.')?
                .strip_prefix(o.role)?
                .strip_prefix('.')
                .filter(|p| QOS_POLICIES.contains(p))
                .map(|p| (i, p))
        })
    }

    /// Every parameter name of this node: the table's, then the `qos_overrides` ones.
    pub fn names(&self) -> Vec<String> {
        names()
            .map(|n| n.to_string())
            .chain(
                self.qos_overrides
                    .iter()
                    .flat_map(|o| QOS_POLICIES.iter().map(move |p| Self::qos_parameter(o, p))),
            )
            .collect()
    }

    /// Whether `name` is one of this node's parameters.
    pub fn is_known(&self, name: &str) -> bool {
        spec(name).is_some() || self.qos_policy_of(name).is_some()
    }

    fn apply_qos(
        &mut self,
        name: &str,
        (index, policy): (usize, &str),
        value: &ParameterValue,
    ) -> Result<(), ParamError> {
        let Some(o) = self.qos_overrides.get_mut(index) else {
            return Err(ParamError::Unknown(name.into()));
        };
        let q = &mut o.qos;
        match policy {
            "reliability" => q.best_effort = choice(name, value, ["reliable", "best_effort"])?,
            "durability" => {
                q.transient_local = choice(name, value, ["volatile", "transient_local"])?
            }
            "history" => q.keep_all = choice(name, value, ["keep_last", "keep_all"])?,
            _ => q.depth = integer(name, value, 1, 10_000)?,
        }
        Ok(())
    }

    /// Sets parameter `name` to `value` after validating it; on error `self` is unchanged.
    pub fn apply(&mut self, name: &str, value: &ParameterValue) -> Result<(), ParamError> {
        if let Some(endpoint) = self.qos_policy_of(name) {
            return self.apply_qos(name, endpoint, value);
        }
        let spec = spec(name).ok_or_else(|| ParamError::Unknown(name.into()))?;
        spec.kind.check(name, value)?;
        let mut next = self.clone();
        (spec.set)(&mut next, value).map_err(|reason| ParamError::Invalid {
            name: name.into(),
            reason,
        })?;
        *self = next;
        Ok(())
    }

    /// Checks `value` for `name` without changing anything.
    pub fn validate(&self, name: &str, value: &ParameterValue) -> Result<(), ParamError> {
        self.clone().apply(name, value)
    }

    /// The value of `name` as a ROS parameter value (the type it is declared with).
    pub fn get(&self, name: &str) -> Option<ParameterValue> {
        if let Some((index, policy)) = self.qos_policy_of(name) {
            let q = &self.qos_overrides.get(index)?.qos;
            let pick =
                |b: bool, [a, z]: [&str; 2]| ParameterValue::String(if b { z } else { a }.into());
            return Some(match policy {
                "reliability" => pick(q.best_effort, ["reliable", "best_effort"]),
                "durability" => pick(q.transient_local, ["volatile", "transient_local"]),
                "history" => pick(q.keep_all, ["keep_last", "keep_all"]),
                _ => ParameterValue::Integer(q.depth),
            });
        }
        spec(name).map(|s| (s.get)(self))
    }

    /// All parameters as (name, value), to declare them on the node.
    pub fn to_declarations(&self) -> Vec<(String, ParameterValue)> {
        self.names()
            .into_iter()
            .filter_map(|n| self.get(&n).map(|v| (n, v)))
            .collect()
    }

    /// The parameters that differ from `before`, as `name: old → new` (for the log line of a
    /// change, rather than the whole set).
    pub fn changes_from(&self, before: &Params) -> Vec<String> {
        let old: std::collections::HashMap<String, ParameterValue> =
            before.to_declarations().into_iter().collect();
        self.to_declarations()
            .into_iter()
            .filter_map(|(name, new)| {
                let was = old.get(&name)?;
                (*was != new).then(|| format!("{name}: {} → {}", value_text(was), value_text(&new)))
            })
            .collect()
    }

    /// What `describe_parameters` (`ros2 param describe`) says about `name`.
    pub fn descriptor(&self, name: &str) -> Option<Descriptor> {
        if let Some((index, policy)) = self.qos_policy_of(name) {
            let o = self.qos_overrides.get(index)?;
            let (what, allowed, range) = match policy {
                "reliability" => ("reliability", "reliable or best_effort", Range::Unbounded),
                "durability" => (
                    "durability",
                    "volatile or transient_local",
                    Range::Unbounded,
                ),
                "history" => ("history", "keep_last or keep_all", Range::Unbounded),
                _ => ("keep_last depth", "1..10000", Range::Integer(1, 10_000)),
            };
            return Some(Descriptor {
                description: format!("QoS {what} of the {} on {}; start-up only", o.role, o.topic),
                constraints: allowed.into(),
                read_only: true,
                range,
            });
        }
        let spec = spec(name)?;
        Some(Descriptor {
            description: spec.description.into(),
            constraints: if spec.constraints.is_empty() {
                spec.kind.constraint()
            } else {
                spec.constraints.into()
            },
            read_only: false,
            range: spec.kind.range(),
        })
    }
}

/// A parameter's ROS descriptor (`rcl_interfaces/ParameterDescriptor`), without ROS types.
#[derive(Clone, Debug, PartialEq)]
pub struct Descriptor {
    /// What the parameter does, with its unit.
    pub description: String,
    /// Constraints a range cannot express ("> 0", the allowed strings), or empty.
    pub constraints: String,
    /// Set at start-up only (`-p`, `--params-file`).
    pub read_only: bool,
    /// Numeric range, bounds included.
    pub range: Range,
}

/// Numeric range of a [`Descriptor`] (bounds included, as in ROS).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Range {
    /// No range (or not numeric).
    Unbounded,
    /// Integer bounds.
    Integer(i64, i64),
    /// Floating-point bounds.
    Double(f64, f64),
}

/// What the command line asks for.
#[derive(Debug, PartialEq)]
pub enum Command {
    /// Run the node.
    Run(Box<Startup>),
    /// Print the usage text and exit.
    Help,
}

/// Everything the node starts with.
#[derive(Debug, PartialEq)]
pub struct Startup {
    /// Parameters after every `-p` and `--params-file`, in order.
    pub params: Params,
    /// Node name, namespace and remapping rules.
    pub identity: NodeIdentity,
    /// Console log filter from `--log-level`, if given.
    pub log_filter: Option<String>,
    /// Publish logs on /rosout (`--disable-rosout-logs` turns it off).
    pub rosout_logs: bool,
    /// The node's ROS logger name (`left.rod_ig_node`) and its threshold (`--log-level`,
    /// global or for this logger), applied to /rosout as to the console.
    pub logger: (String, crate::ros_args::LogLevel),
}

/// Usage text for `--help`: the parameters from the parameter table.
pub fn usage() -> String {
    let d = Params::default();
    let mut text = String::from(
        "rod_ig_node: ROS 2 node serving elastic-rod inverse geometry.\n\n\
         Usage: rod_ig_node [--ros-args [-r FROM:=TO]... [-p NAME:=VALUE]... [--params-file FILE]...\n\
         \x20                  [--log-level [LOGGER:=]LEVEL]... [--]]\n\n\
         ROS 2 arguments as rcl reads them: -r __ns:=/NS and -r __node:=NAME move and rename the\n\
         node, -r rod/target:=/arm/goal remaps a topic or service (names are relative: rod/...\n\
         in the node's namespace). Later settings override earlier ones. Parameters (default):\n",
    );
    for spec in &TABLE {
        let value = match (spec.get)(&d) {
            ParameterValue::String(s) => format!("{s:?}"),
            ParameterValue::Double(x) => format!("{x}"),
            ParameterValue::Integer(i) => format!("{i}"),
            ParameterValue::Boolean(b) => format!("{b}"),
            other => format!("{other:?}"),
        };
        let constraint = match spec.kind.constraint() {
            c if c.is_empty() => String::new(),
            c => format!(", {c}"),
        };
        text.push_str(&format!(
            "  {:<18}{}{constraint} ({value})\n",
            spec.name, spec.description
        ));
    }
    text.push_str(
        "  qos_overrides.TOPIC.ROLE.POLICY  start-up QoS, as rclcpp's: TOPIC /rod/target (ROLE\n\
         \x20   subscription) or /rod/path, /rod/solution, /rod/marker, /rod/plan_rods, /diagnostics,\n\
         \x20   /rod/base_wrench (ROLE publisher); POLICY reliability (reliable|best_effort), durability\n\
         \x20   (volatile|transient_local), history (keep_last|keep_all), depth (1..10000)\n\
         \x20   (reliable, volatile, keep_last, 10)\n",
    );
    text.push_str(
        "\nEnvironment: ROS_DOMAIN_ID (0..232), ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST or\n\
         ROS_LOCALHOST_ONLY=1 (loopback only), RUST_LOG (console log level).\n",
    );
    text
}

/// Parses a command-line value the way `ros2 run ... -p` does (YAML scalar rules, subset):
/// true/false, integers, floats, otherwise a string (quotes stripped).
pub fn parse_value(text: &str) -> ParameterValue {
    let t = text.trim();
    match serde_yaml::from_str::<serde_yaml::Value>(t) {
        Ok(v) => yaml_to_value(&v).unwrap_or_else(|| ParameterValue::String(t.to_string())),
        Err(_) => ParameterValue::String(t.to_string()),
    }
}

fn yaml_to_value(v: &serde_yaml::Value) -> Option<ParameterValue> {
    use serde_yaml::Value as Y;
    Some(match v {
        Y::Bool(b) => ParameterValue::Boolean(*b),
        Y::Number(n) => {
            if let Some(i) = n.as_i64() {
                ParameterValue::Integer(i)
            } else {
                ParameterValue::Double(n.as_f64()?)
            }
        }
        Y::String(s) => ParameterValue::String(s.clone()),
        Y::Null => ParameterValue::NotSet,
        // A list of numbers is a double array (rcl reads [0, -9.81, 0] so too).
        Y::Sequence(items) => ParameterValue::DoubleArray(
            items
                .iter()
                .map(|i| i.as_f64())
                .collect::<Option<Vec<f64>>>()?,
        ),
        _ => return None,
    })
}

/// Parses the command line (without the program name) into a [`Command`]: the node's
/// identity (default `rod_ig_node` in `/`, see [`crate::graph::NODE_NAME`]), then every
/// parameter source in order.
pub fn parse_args<I, S>(args: I) -> Result<Command, ParamError>
where
    I: IntoIterator<Item = S>,
    S: AsRef<str>,
{
    let ros = ros_args::parse(args).map_err(|e| ParamError::Args(e.to_string()))?;
    if ros.help {
        return Ok(Command::Help);
    }
    if let Some(extra) = ros.unparsed.first() {
        return Err(ParamError::Args(format!(
            "unexpected argument {extra:?} (see --help)"
        )));
    }
    let identity = ros
        .identity(crate::graph::NODE_NAME, "/")
        .map_err(|e| ParamError::Args(e.to_string()))?;
    let mut params = Params {
        qos_overrides: QosOverride::for_node(|n| identity.resolve(n))
            .map_err(|e| ParamError::Args(e.to_string()))?,
        ..Params::default()
    };
    let fqn = identity.fully_qualified_name();
    for source in &ros.params {
        match source {
            ParamSource::Value { node, name, value } => {
                if node
                    .as_deref()
                    .is_some_and(|n| n != identity.name && n != crate::graph::NODE_NAME)
                {
                    continue; // for another node
                }
                let name = name.trim();
                if !params.is_known(name) {
                    // rcl declares nothing for a name the node does not use: say so, go on.
                    log::warn!("-p {name}: not a parameter of this node, ignored");
                    continue;
                }
                params.apply(name, &parse_value(value))?;
            }
            ParamSource::File(path) => load_params_file_for(&mut params, path, &fqn)?,
        }
    }
    let logger = (
        identity.logger_name(),
        ros.level_of(&identity.logger_name()),
    );
    let log_filter = ros.log_filter(&identity.logger_name());
    Ok(Command::Run(Box::new(Startup {
        params,
        identity,
        log_filter,
        rosout_logs: ros.rosout_logs.unwrap_or(true),
        logger,
    })))
}

/// The default node's fully qualified name.
const DEFAULT_FQN: &str = "/rod_ig_node";

/// Applies a ROS 2 parameters file (`rod_ig_node: {ros__parameters: {...}}`; also
/// `/rod_ig_node` and the wildcard `/**`) to `params`. Unknown parameters are skipped with a
/// warning (a shared file may configure other nodes' parameters, e.g. `use_sim_time`, under
/// `/**`); invalid values of known ones are errors.
pub fn load_params_file(params: &mut Params, path: &Path) -> Result<(), ParamError> {
    load_params_file_for(params, path, DEFAULT_FQN)
}

/// [`load_params_file`] for the node whose fully qualified name is `fqn`.
fn load_params_file_for(params: &mut Params, path: &Path, fqn: &str) -> Result<(), ParamError> {
    let file_err = |reason: String| ParamError::File {
        path: path.to_path_buf(),
        reason,
    };
    let text = std::fs::read_to_string(path).map_err(|e| file_err(e.to_string()))?;
    apply_params_yaml_for(params, &text, fqn).map_err(|e| match e {
        ParamError::File { reason, .. } => file_err(reason),
        other => file_err(other.to_string()),
    })
}

/// Applies the text of a ROS 2 parameters file (see [`load_params_file`]).
pub fn apply_params_yaml(params: &mut Params, text: &str) -> Result<(), ParamError> {
    apply_params_yaml_for(params, text, DEFAULT_FQN)
}

fn apply_params_yaml_for(params: &mut Params, text: &str, fqn: &str) -> Result<(), ParamError> {
    let err = |reason: String| ParamError::File {
        path: PathBuf::new(),
        reason,
    };
    let doc: serde_yaml::Value = serde_yaml::from_str(text).map_err(|e| err(e.to_string()))?;
    if !doc.is_mapping() {
        return Err(err("top level must be a mapping of node names".into()));
    }
    let mut sections = Vec::new();
    node_sections("", &doc, &mut sections).map_err(err)?;
    let node = name_tokens(fqn);
    let mine: Vec<_> = sections
        .iter()
        .filter(|(key, _)| section_matches(&name_tokens(key), &node))
        .collect();
    if mine.is_empty() {
        let keys: Vec<&str> = sections.iter().map(|(k, _)| k.as_str()).collect();
        log::info!(
            "parameters file: no section for {fqn} (sections: {}): defaults kept",
            keys.join(", ")
        );
    }
    for (key, ros_params) in mine {
        // Nested mappings name parameters with dots, as rcl reads them
        // (`qos_overrides: {/rod/target: {subscription: {depth: 1}}}`).
        let mut flat = Vec::new();
        flatten_yaml("", ros_params, &mut flat).map_err(err)?;
        for (name, value) in flat {
            if !params.is_known(&name) {
                log::warn!(
                    "parameters file: ignoring unknown parameter '{name}' in section '{key}' \
                     (known: {})",
                    params.names().join(", ")
                );
                continue;
            }
            let value = yaml_to_value(value)
                .ok_or_else(|| err(format!("parameter '{name}': unsupported value {value:?}")))?;
            params.apply(&name, &value)?;
        }
    }
    Ok(())
}

/// Every `ros__parameters` mapping of a parameters file with the node key it sits under: keys
/// nest as rcl reads them (`/left:` → `rod_ig_node:` is `/left/rod_ig_node`).
fn node_sections<'a>(
    prefix: &str,
    value: &'a serde_yaml::Value,
    out: &mut Vec<(String, &'a serde_yaml::Value)>,
) -> Result<(), String> {
    let Some(map) = value.as_mapping() else {
        return Err(format!("'{prefix}' must be a mapping"));
    };
    for (k, v) in map {
        let k = k
            .as_str()
            .ok_or_else(|| format!("node names must be strings, got {k:?}"))?;
        if k == "ros__parameters" {
            if !v.is_mapping() {
                return Err(format!("'{prefix}.ros__parameters' must be a mapping"));
            }
            out.push((prefix.to_string(), v));
        } else {
            node_sections(&format!("{prefix}/{k}"), v, out)?;
        }
    }
    Ok(())
}

/// The tokens of a node name or key (`/left//rod_ig_node` → ["left", "rod_ig_node"]).
fn name_tokens(name: &str) -> Vec<&str> {
    name.split('/').filter(|t| !t.is_empty()).collect()
}

/// rcl's matching of a params-file key against a node's fully qualified name: token by token,
/// `*` matching one token and `**` any number (none included).
fn section_matches(key: &[&str], node: &[&str]) -> bool {
    match (key.first(), node.first()) {
        (None, None) => true,
        (Some(&"**"), _) => {
            section_matches(&key[1..], node)
                || (!node.is_empty() && section_matches(key, &node[1..]))
        }
        (Some(&k), Some(&n)) if k == "*" || k == n => section_matches(&key[1..], &node[1..]),
        _ => false,
    }
}

/// The leaves of a `ros__parameters` mapping, named by their dotted paths.
fn flatten_yaml<'a>(
    prefix: &str,
    value: &'a serde_yaml::Value,
    out: &mut Vec<(String, &'a serde_yaml::Value)>,
) -> Result<(), String> {
    match value.as_mapping() {
        Some(map) => {
            for (k, v) in map {
                let k = k
                    .as_str()
                    .ok_or_else(|| format!("parameter names must be strings, got {k:?}"))?;
                let name = if prefix.is_empty() {
                    k.to_string()
                } else {
                    format!("{prefix}.{k}")
                };
                flatten_yaml(&name, v, out)?;
            }
        }
        None => out.push((prefix.to_string(), value)),
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(args: &[&str]) -> Result<Params, ParamError> {
        match parse_args(args)? {
            Command::Run(s) => Ok(s.params),
            Command::Help => panic!("unexpected help"),
        }
    }

    #[test]
    fn a_change_is_logged_as_its_differences() {
        let before = Params::default();
        let mut after = before.clone();
        after
            .apply("deadline_ms", &ParameterValue::Double(100.0))
            .unwrap();
        after
            .apply(
                "gravity",
                &ParameterValue::DoubleArray(vec![0.0, -9.81, 0.0]),
            )
            .unwrap();
        let changes = after.changes_from(&before);
        assert_eq!(changes.len(), 2, "{changes:?}");
        assert!(
            changes.contains(&"deadline_ms: 250 → 100".to_string()),
            "{changes:?}"
        );
        assert!(
            changes
                .iter()
                .any(|c| c.starts_with("gravity: ") && c.ends_with("→ [0.0, -9.81, 0.0]")),
            "{changes:?}"
        );
        assert!(after.changes_from(&after).is_empty());
    }

    #[test]
    fn defaults() {
        let p = run(&[]).unwrap();
        assert_eq!(p, Params::default());
        assert_eq!(p.rod_length, 1.0);
        assert_eq!(p.path_samples, 100);
        assert_eq!(p.method, Method::Robust);
    }

    #[test]
    fn unknown_keys_in_a_params_file_are_skipped() {
        let mut p = Params::default();
        let yaml = "/**:\n  ros__parameters:\n    use_sim_time: false\n    rod_length: 0.7\n    \
                    some_other_node_param: [1, 2]\n";
        apply_params_yaml(&mut p, yaml).unwrap();
        assert_eq!(p.rod_length, 0.7);
        // A known parameter with a bad value is still an error.
        let bad = "rod_ig_node:\n  ros__parameters:\n    rod_length: -1.0\n";
        assert!(apply_params_yaml(&mut Params::default(), bad).is_err());
    }

    #[test]
    fn deadline_and_tolerance_limits() {
        let p = run(&["--ros-args", "-p", "deadline_ms:=20"]).unwrap();
        assert_eq!(p.deadline_ms, 20.0);
        assert_eq!(Params::default().deadline_ms, 250.0);
        for bad in [
            "deadline_ms:=0",
            "deadline_ms:=20000",
            "deadline_ms:=-1",
            "tolerance:=1e-20",
        ] {
            assert!(run(&["--ros-args", "-p", bad]).is_err(), "{bad}");
        }
    }

    #[test]
    fn command_line_parameters() {
        let p = run(&[
            "--ros-args",
            "-p",
            "rod_length:=0.5",
            "-p",
            "path_samples:=20",
            "--param",
            "method:=newton",
            "-p",
            "base_frame:=left_gripper",
            "-p",
            "bending_stiffness:=2",
            "-p",
            "publish_marker:=false",
            "-p",
            "solve_3d:=true",
        ])
        .unwrap();
        assert!(p.solve_3d);
        assert_eq!(p.rod_length, 0.5);
        assert_eq!(p.path_samples, 20);
        assert_eq!(p.method, Method::Newton);
        assert_eq!(p.base_frame, "left_gripper");
        assert_eq!(p.bending_stiffness, 2.0);
        assert!(!p.publish_marker);
    }

    #[test]
    fn bad_command_lines_are_rejected_with_a_reason() {
        let e = run(&["-p", "rod_length:=-1"]).unwrap_err();
        assert!(e.to_string().contains("rod_length"), "{e}");
        // A name the node does not have is skipped with a warning (rcl declares nothing).
        assert!(run(&["-p", "nope:=1"]).is_ok());
        assert!(matches!(
            run(&["-p", "rod_length"]),
            Err(ParamError::Args(_))
        ));
        assert!(matches!(run(&["-p"]), Err(ParamError::Args(_))));
        assert!(matches!(run(&["--frobnicate"]), Err(ParamError::Args(_))));
        assert!(matches!(
            run(&["-p", "path_samples:=1"]),
            Err(ParamError::Invalid { .. })
        ));
        assert!(matches!(
            run(&["-p", "path_samples:=2.5"]),
            Err(ParamError::WrongType { .. })
        ));
        assert!(matches!(
            run(&["-p", "method:=magic"]),
            Err(ParamError::Invalid { .. })
        ));
        assert!(matches!(
            run(&["-p", "rod_length:=.nan"]),
            Err(ParamError::Invalid { .. })
        ));
        assert_eq!(parse_args(["--help"]).unwrap(), Command::Help);
    }

    #[test]
    fn yaml_file() {
        let mut p = Params::default();
        apply_params_yaml(
            &mut p,
            "rod_ig_node:\n  ros__parameters:\n    rod_length: 2\n    tolerance: 1.0e-9\n    \
             max_iterations: 30\n    base_frame: world\n",
        )
        .unwrap();
        assert_eq!(p.rod_length, 2.0);
        assert_eq!(p.tolerance, 1e-9);
        assert_eq!(p.max_iterations, 30);
        assert_eq!(p.base_frame, "world");

        let mut q = Params::default();
        apply_params_yaml(&mut q, "/**:\n  ros__parameters:\n    path_samples: 7\n").unwrap();
        assert_eq!(q.path_samples, 7);

        let mut r = Params::default();
        // Only other nodes' sections (a launch file's shared YAML): the defaults, no error.
        assert!(apply_params_yaml(&mut r, "other_node:\n  ros__parameters: {}\n").is_ok());
        // Unknown keys are skipped with a warning (issue 10), not fatal.
        assert!(apply_params_yaml(&mut r, "rod_ig_node:\n  ros__parameters:\n    x: 1\n").is_ok());
        assert!(apply_params_yaml(&mut r, "[1, 2]").is_err());
        assert_eq!(r, Params::default());
    }

    #[test]
    fn shipped_params_file_loads() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("config/rod_ig_params.yaml");
        let mut p = Params::default();
        load_params_file(&mut p, &path).unwrap();
    }

    #[test]
    fn file_then_flag_order() {
        let dir = std::env::temp_dir().join(format!("rod_ig_params_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("p.yaml");
        std::fs::write(
            &f,
            "rod_ig_node:\n  ros__parameters:\n    rod_length: 3.0\n",
        )
        .unwrap();
        let fs = f.to_str().unwrap();
        assert_eq!(run(&["--params-file", fs]).unwrap().rod_length, 3.0);
        assert_eq!(
            run(&["--params-file", fs, "-p", "rod_length:=4.0"])
                .unwrap()
                .rod_length,
            4.0
        );
        assert_eq!(
            run(&["-p", "rod_length:=4.0", "--params-file", fs])
                .unwrap()
                .rod_length,
            3.0
        );
        assert!(matches!(
            run(&["--params-file", "/nonexistent/x.yaml"]),
            Err(ParamError::File { .. })
        ));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn run_time_validation_keeps_old_value() {
        let mut p = Params::default();
        assert!(p.apply("rod_length", &ParameterValue::Double(0.0)).is_err());
        assert!(p
            .apply("rod_length", &ParameterValue::Double(f64::INFINITY))
            .is_err());
        assert!(p
            .apply("rod_length", &ParameterValue::String("1".into()))
            .is_err());
        assert!(p
            .apply("tolerance", &ParameterValue::Double(-1e-3))
            .is_err());
        assert!(p
            .apply("max_iterations", &ParameterValue::Integer(0))
            .is_err());
        assert!(p
            .apply("bending_stiffness", &ParameterValue::Double(-2.0))
            .is_err());
        assert!(p
            .apply("publish_marker", &ParameterValue::Integer(1))
            .is_err());
        assert!(p
            .apply("solve_3d", &ParameterValue::String("yes".into()))
            .is_err());
        assert_eq!(p, Params::default());
        p.apply("rod_length", &ParameterValue::Double(0.7)).unwrap();
        assert_eq!(p.rod_length, 0.7);
        assert!(p
            .validate("path_samples", &ParameterValue::Integer(5))
            .is_ok());
        assert_eq!(p.path_samples, 100);
    }

    #[test]
    fn declarations_round_trip() {
        let p = Params::default();
        let decl = p.to_declarations();
        assert_eq!(
            decl.len(),
            names().count() + QOS_ENDPOINTS.len() * QOS_POLICIES.len()
        );
        let mut q = Params {
            rod_length: 9.0,
            ..Params::default()
        };
        for (n, v) in &decl {
            q.apply(n, v).unwrap();
        }
        assert_eq!(p, q);
    }

    #[test]
    fn every_table_row_is_consistent() {
        // Defaults pass their own checks, get returns them, every row has a descriptor.
        let d = Params::default();
        for spec in &TABLE {
            let v = spec.default.value();
            spec.kind.check(spec.name, &v).expect(spec.name);
            assert_eq!((spec.get)(&d), v, "{}", spec.name);
            let desc = d.descriptor(spec.name).expect(spec.name);
            assert!(!desc.description.is_empty() && !desc.read_only);
        }
        assert!(usage().contains("deadline_ms") && usage().contains("(0, 10000]"));
    }

    #[test]
    fn base_frame_must_be_a_tf_frame_id() {
        let mut p = Params::default();
        for good in ["base_link", "arm/base", "robot-1.base"] {
            p.apply("base_frame", &ParameterValue::String(good.into()))
                .expect(good);
            assert_eq!(p.base_frame, good);
        }
        for bad in ["", "bad frame!", "/world", "a//b", "a/"] {
            let e = p.apply("base_frame", &ParameterValue::String(bad.into()));
            assert!(
                matches!(e, Err(ParamError::Invalid { .. })),
                "{bad:?}: {e:?}"
            );
            assert_eq!(p.base_frame, "robot-1.base", "unchanged after {bad:?}");
        }
    }

    /// The sections rcl applies to a node (issue 20): wildcards, fully qualified names, nested
    /// namespaces, the renamed node; a file without one leaves the defaults; `-p` of a name
    /// the node does not have is skipped.
    #[test]
    fn params_file_sections_as_rcl_reads_them() {
        let dir =
            std::env::temp_dir().join(format!("rod_ig_params_sections_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let cases: [(&str, &[&str], Option<i64>); 9] = [
            (
                "/**:\n  ros__parameters:\n    path_samples: 11\n",
                &[],
                Some(11),
            ),
            (
                "/**/rod_ig_node:\n  ros__parameters:\n    path_samples: 12\n",
                &["-r", "__ns:=/left"],
                Some(12),
            ),
            (
                "/left/rod_ig_node:\n  ros__parameters:\n    path_samples: 13\n",
                &["-r", "__ns:=/left"],
                Some(13),
            ),
            (
                "/left:\n  rod_ig_node:\n    ros__parameters:\n      path_samples: 14\n",
                &["-r", "__ns:=/left"],
                Some(14),
            ),
            (
                "/left:\n  rod_ig_node:\n    ros__parameters:\n      path_samples: 15\n",
                &["-r", "__ns:=/right"],
                None,
            ),
            (
                "arm_rod:\n  ros__parameters:\n    path_samples: 16\n",
                &["-r", "__node:=arm_rod"],
                Some(16),
            ),
            (
                "/*/rod_ig_node:\n  ros__parameters:\n    path_samples: 17\n",
                &["-r", "__ns:=/a/b"],
                None,
            ),
            (
                "/**/rod_ig_node:\n  ros__parameters:\n    path_samples: 18\n",
                &["-r", "__ns:=/a/b"],
                Some(18),
            ),
            ("camera:\n  ros__parameters:\n    rate: 30\n", &[], None),
        ];
        for (k, (yaml, args, expected)) in cases.iter().enumerate() {
            let path = dir.join(format!("p{k}.yaml"));
            std::fs::write(&path, yaml).unwrap();
            let mut argv: Vec<&str> = vec!["--ros-args"];
            argv.extend_from_slice(args);
            let file = path.to_str().unwrap();
            argv.extend_from_slice(&["--params-file", file]);
            let p = run(&argv).unwrap_or_else(|e| panic!("{yaml:?} {args:?}: {e}"));
            let want = expected.unwrap_or(100) as usize;
            assert_eq!(p.path_samples, want, "{yaml:?} with {args:?}");
        }
        let p = run(&["--ros-args", "-p", "nosuch:=1", "-p", "path_samples:=5"]).unwrap();
        assert_eq!(p.path_samples, 5);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
