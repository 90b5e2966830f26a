//! The ROS 2 side: DDS context, topics, the service, parameters, and the tasks between them.
//! Names are relative (`rod/target`, ...) and resolved through the command line's
//! [`NodeIdentity`] (namespace, node name, remapping rules): started plainly they are
//! `/rod/...`.
//!
//! ```text
//!  /rod/target ──► subscriber task ──watch (latest wins)──► solver task ──► /rod/path
//!  /rod/solve  ──► service task ──mpsc + oneshot──────────►  (Processor)  ──► /rod/solution
//!  parameter services ──validator / set action──watch<Params>──►            ──► /rod/marker
//! ```
//!
//! A flood of targets cannot pile up: the subscriber task only overwrites the one slot of a
//! `tokio::sync::watch` channel, and the solver task always takes the newest target.

/// The enclosing function's name ([`function_of`]).
macro_rules! function_name {
    () => {{
        fn here() {}
        $crate::node::function_of(std::any::type_name_of_val(&here))
    }};
}

/// Logs through a [`Logger`] at a [`RosLevel`] with the call site's file, function and line.
macro_rules! node_log {
    ($logger:expr, $level:ident, $($arg:tt)+) => {
        $logger.log(
            RosLevel::$level,
            function_name!(),
            file!(),
            line!(),
            &format!($($arg)+),
        )
    };
}

use std::pin::pin;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use crate::solver::PlanarParams;
use futures::StreamExt;
use rod_ig_core::solver::{observe, Counters};
use ros2_client::dds::rustdds::DomainParticipantBuilder;
use ros2_client::log::LogLevel;
use ros2_client::qos::{Durability, History, WhenFull};
use ros2_client::{
    Context, Name, NodeLoggingHandle, NodeName, NodeOptions, ParameterValue, Publisher, QosProfile,
    ServiceMapping,
};
use thiserror::Error;
use tokio::sync::{mpsc, oneshot, watch};

use crate::diagnostics::SolveStats;
use crate::messages::{
    type_names, Marker, Path, PlanRodRequest, PlanRodResponse, PoseStamped, RodSolution,
    SolveRodRequest, SolveRodResponse, TfMessage, WrenchStamped,
};
use crate::params::{Params, Startup};
use crate::pipeline::{Outcome, Overrides, Processor};
use crate::ros_args::{LogLevel as RosLevel, NodeIdentity};
use crate::tf_buffer::TfBuffer;
use ros2_client::rosout::RosoutRaw;

pub use crate::graph::{names, NODE_NAME};

/// Errors that stop the node from starting.
#[derive(Debug, Error)]
pub enum NodeError {
    /// Bad environment variable.
    #[error("environment: {0}")]
    Environment(String),
    /// DDS / ROS entity creation failed.
    #[error("cannot create {what}: {reason}")]
    Create {
        /// Which entity.
        what: &'static str,
        /// Why.
        reason: String,
    },
}

fn create_err<E: std::fmt::Debug>(what: &'static str) -> impl FnOnce(E) -> NodeError {
    move |e| NodeError::Create {
        what,
        reason: format!("{e:?}"),
    }
}

/// How far the node looks for peers (`ROS_AUTOMATIC_DISCOVERY_RANGE`, as rcl reads it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DiscoveryRange {
    /// `OFF`: no automatic discovery at all (the node neither announces itself nor listens).
    Off,
    /// `LOCALHOST` (or the deprecated `ROS_LOCALHOST_ONLY=1`): this host only, over loopback.
    Localhost,
    /// `SUBNET`, `SYSTEM_DEFAULT` or unset: every network interface (rcl's default).
    Subnet,
}

/// Middleware settings read from the environment.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MiddlewareConfig {
    /// `ROS_DOMAIN_ID` (default 0).
    pub domain_id: u16,
    /// Loopback only: `ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST` or `ROS_LOCALHOST_ONLY=1`.
    pub localhost_only: bool,
    /// `ROS_AUTOMATIC_DISCOVERY_RANGE`.
    pub discovery: DiscoveryRange,
    /// Warnings to log once the logger runs: settings the node honours only in part
    /// (`ROS_STATIC_PEERS`, security under the Permissive strategy).
    pub warnings: Vec<String>,
}

impl MiddlewareConfig {
    /// Reads the configuration from environment variables (given as a lookup function so
    /// it can be tested).
    pub fn from_lookup(get: impl Fn(&str) -> Option<String>) -> Result<Self, NodeError> {
        let domain_id = match get("ROS_DOMAIN_ID").map(|s| s.trim().to_string()) {
            None => 0,
            Some(s) if s.is_empty() => 0,
            Some(s) => match s.parse::<u16>() {
                Ok(d) if d <= 232 => d,
                _ => {
                    return Err(NodeError::Environment(format!(
                        "ROS_DOMAIN_ID must be an integer in 0..=232, got {s:?}"
                    )))
                }
            },
        };
        let range = get("ROS_AUTOMATIC_DISCOVERY_RANGE").unwrap_or_default();
        let discovery = match range.trim().to_ascii_uppercase().as_str() {
            "OFF" => DiscoveryRange::Off,
            "LOCALHOST" => DiscoveryRange::Localhost,
            "SUBNET" | "SYSTEM_DEFAULT" => DiscoveryRange::Subnet,
            "" if get("ROS_LOCALHOST_ONLY").is_some_and(|v| v.trim() == "1") => {
                DiscoveryRange::Localhost
            }
            "" => DiscoveryRange::Subnet,
            other => {
                return Err(NodeError::Environment(format!(
                    "ROS_AUTOMATIC_DISCOVERY_RANGE must be OFF, LOCALHOST, SUBNET or \
                     SYSTEM_DEFAULT, got {other:?}"
                )))
            }
        };
        let mut warnings = Vec::new();
        let peers = get("ROS_STATIC_PEERS").unwrap_or_default();
        if !peers.trim().is_empty() {
            if discovery == DiscoveryRange::Off {
                return Err(NodeError::Environment(format!(
                    "ROS_STATIC_PEERS={peers:?} with ROS_AUTOMATIC_DISCOVERY_RANGE=OFF: this \
                     node's DDS (RustDDS) has no list of static peers, so it would reach no one"
                )));
            }
            warnings.push(format!(
                "ROS_STATIC_PEERS={peers:?} is ignored: this node's DDS (RustDDS) has no list of \
                 static peers; it discovers peers by ROS_AUTOMATIC_DISCOVERY_RANGE only"
            ));
        }
        if let Some(w) = security_check(&get)? {
            warnings.push(w);
        }
        Ok(Self {
            domain_id,
            localhost_only: discovery == DiscoveryRange::Localhost,
            discovery,
            warnings,
        })
    }

    /// From the process environment.
    pub fn from_env() -> Result<Self, NodeError> {
        Self::from_lookup(|k| std::env::var(k).ok())
    }
}

/// rcl's security settings: `ROS_SECURITY_ENABLE=true` with `ROS_SECURITY_STRATEGY=Enforce`
/// requires DDS security, which this node's DDS build does not carry, so it refuses to start
/// (as rcl does without a usable keystore) rather than run unsecured; under Permissive (or no
/// strategy) it runs unsecured and says so.
fn security_check(get: &impl Fn(&str) -> Option<String>) -> Result<Option<String>, NodeError> {
    if get("ROS_SECURITY_ENABLE").as_deref().map(str::trim) != Some("true") {
        return Ok(None);
    }
    let strategy = get("ROS_SECURITY_STRATEGY").unwrap_or_default();
    if strategy.trim() == "Enforce" {
        return Err(NodeError::Environment(
            "ROS_SECURITY_ENABLE=true with ROS_SECURITY_STRATEGY=Enforce: this node cannot run \
             DDS security (its DDS, RustDDS, is built without it), and Enforce forbids running \
             unsecured; unset ROS_SECURITY_ENABLE or use ROS_SECURITY_STRATEGY=Permissive"
                .into(),
        ));
    }
    Ok(Some(
        "ROS_SECURITY_ENABLE=true: running WITHOUT DDS security (strategy Permissive; this \
         node's DDS, RustDDS, is built without it)"
            .into(),
    ))
}

/// QoS of the topics and the service: reliable, volatile, keep last 10 (rclpy's
/// `create_publisher(T, topic, 10)`).
pub fn topic_qos() -> QosProfile {
    QosProfile::publisher_default()
        .reliability_reliable(WhenFull::DEFAULT)
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: 10 })
}

/// QoS of the outputs (path, solution, marker): as the service's. Not TRANSIENT_LOCAL:
/// RustDDS 0.15.1 hands a transient-local writer's history to *volatile* readers too (Fast
/// DDS does not), so a client that takes "the next solution" would get the previous one.
pub fn output_qos() -> QosProfile {
    topic_qos()
}

/// QoS of `/tf` (reliable, volatile, keep last 100) and `/tf_static` (transient local, so that
/// the transforms published before the node started reach it), as tf2's listener.
pub fn tf_qos(is_static: bool) -> QosProfile {
    QosProfile::publisher_default()
        .reliability_reliable(WhenFull::DEFAULT)
        .durability(if is_static {
            Durability::TransientLocal
        } else {
            Durability::Volatile
        })
        .history(History::KeepLast { depth: 100 })
}

/// QoS of an endpoint, from its `qos_overrides` parameters.
pub fn endpoint_qos(q: &crate::params::TopicQos) -> QosProfile {
    let base = QosProfile::publisher_default();
    let base = if q.best_effort {
        base.reliability_best_effort()
    } else {
        base.reliability_reliable(WhenFull::DEFAULT)
    };
    base.durability(if q.transient_local {
        Durability::TransientLocal
    } else {
        Durability::Volatile
    })
    .history(if q.keep_all {
        History::KeepAll
    } else {
        History::KeepLast {
            depth: usize::try_from(q.depth).unwrap_or(10),
        }
    })
}

/// A [`crate::params::Descriptor`] as ros2-client's.
fn ros_descriptor(
    name: &str,
    value: &ParameterValue,
    d: crate::params::Descriptor,
) -> ros2_client::parameters::ParameterDescriptor {
    use crate::params::Range;
    use ros2_client::parameters::NumericRange;
    ros2_client::parameters::ParameterDescriptor {
        name: name.to_string(),
        param_type: value.to_parameter_type(),
        description: d.description,
        additional_constraints: d.constraints,
        read_only: d.read_only,
        dynamic_typing: false,
        range: match d.range {
            Range::Unbounded => NumericRange::NotSpecified,
            Range::Integer(from_value, to_value) => NumericRange::IntegerRange {
                from_value,
                to_value,
                step: 0,
            },
            Range::Double(from_value, to_value) => NumericRange::FloatingPointRange {
                from_value,
                to_value,
                step: 0.0,
            },
        },
    }
}

/// Console (env_logger) plus /rosout logging, as rclcpp's loggers: named `<namespace>.<node>`
/// with dots, the `--log-level` threshold applied to /rosout too, the call site's file,
/// function and line in every record (the `node_log!` macro of this module).
#[derive(Clone)]
pub struct Logger {
    handle: Arc<NodeLoggingHandle>,
    name: Arc<str>,
    threshold: RosLevel,
}

impl Logger {
    /// The logger of `node` named `name`, publishing records at `threshold` or above.
    fn new(node: &ros2_client::Node, (name, threshold): &(String, RosLevel)) -> Self {
        Self {
            handle: Arc::new(node.logging_handle()),
            name: name.as_str().into(),
            threshold: *threshold,
        }
    }

    /// One record at `level` from `function` at `file`:`line`.
    pub fn log(&self, level: RosLevel, function: &str, file: &str, line: u32, msg: &str) {
        let (console, ros) = match level {
            RosLevel::Debug => (log::Level::Debug, LogLevel::Debug),
            RosLevel::Info => (log::Level::Info, LogLevel::Info),
            RosLevel::Warn => (log::Level::Warn, LogLevel::Warn),
            RosLevel::Error => (log::Level::Error, LogLevel::Error),
            RosLevel::Fatal => (log::Level::Error, LogLevel::Fatal),
        };
        log::log!(console, "{msg}");
        if level >= self.threshold {
            self.handle.rosout_raw(
                ros2_client::builtin_interfaces::Time::now(),
                ros,
                &self.name,
                msg,
                file,
                function,
                line,
            );
        }
    }
}

/// The name of a function from the type name of an item inside it (closures and async
/// blocks stripped): what rclcpp's macros take from `__FUNCTION__`.
pub fn function_of(path: &str) -> &str {
    let mut p = path.strip_suffix("::here").unwrap_or(path);
    while let Some(q) = p.strip_suffix("::{{closure}}") {
        p = q;
    }
    p.rsplit("::").next().unwrap_or(p)
}

/// Counters reported at shutdown and, with the solve record, on /diagnostics.
#[derive(Default)]
struct Stats {
    received: AtomicU64,
    solved: AtomicU64,
    failed: AtomicU64,
    service_calls: AtomicU64,
    solves: std::sync::Mutex<SolveStats>,
}

/// Period of the /diagnostics report (diagnostic_updater's default, 1 Hz).
const DIAGNOSTICS_PERIOD: std::time::Duration = std::time::Duration::from_secs(1);

/// A `rod/solve` request on its way to the solver thread, with the slot for its answer.
type SolveJob = (SolveRodRequest, oneshot::Sender<SolveRodResponse>);

/// A `rod/plan` request on its way to the planner thread, with the slot for its answer.
type PlanJob = (PlanRodRequest, oneshot::Sender<PlanRodResponse>);

/// The node's publishers.
struct Outputs {
    path: Publisher<Path>,
    solution: Publisher<RodSolution>,
    marker: Publisher<Marker>,
    /// Written by the planner thread.
    plan_rods: Arc<Publisher<Marker>>,
    /// The base wrench of each solution, when `bending_stiffness` is set.
    base_wrench: Publisher<WrenchStamped>,
    /// The tip wrench of each solution (tip frame), when `bending_stiffness` is set.
    tip_wrench: Publisher<WrenchStamped>,
    /// The frame id of the tip wrench: `tip_frame` when set, else [`DEFAULT_TIP_WRENCH_FRAME`].
    tip_frame: String,
    /// The resolved names, for the logs (remapped and namespaced as the graph shows them).
    names: Names,
}

/// The node's resolved topic and service names.
#[derive(Clone, Debug, Default)]
struct Names {
    target: String,
    path: String,
    solution: String,
    marker: String,
    plan_rods: String,
    base_wrench: String,
    tip_wrench: String,
    solve: String,
    plan: String,
}

impl Names {
    /// The names from the resolved topics (in their order of creation) and services.
    fn of(topics: &[String], [solve, plan]: [&String; 2]) -> Self {
        let topic = |i: usize| topics.get(i).cloned().unwrap_or_default();
        Names {
            target: topic(0),
            path: topic(1),
            solution: topic(2),
            marker: topic(3),
            plan_rods: topic(4),
            base_wrench: topic(6),
            tip_wrench: topic(7),
            solve: solve.clone(),
            plan: plan.clone(),
        }
    }
}

/// Creates the DDS context for `mw` (domain, loopback restriction).
fn create_context(mw: &MiddlewareConfig) -> Result<Context, NodeError> {
    let mut builder = DomainParticipantBuilder::new(mw.domain_id);
    match mw.discovery {
        DiscoveryRange::Localhost => {
            builder = builder.with_only_networks([std::net::Ipv4Addr::LOCALHOST]);
        }
        // No interface to announce on or listen from, and no loopback announcements.
        DiscoveryRange::Off => {
            builder = builder
                .with_only_networks(std::iter::empty::<std::net::IpAddr>())
                .same_host_loopback(false);
        }
        DiscoveryRange::Subnet => {}
    }
    let participant = builder.build().map_err(create_err("DDS participant"))?;
    Context::from_domain_participant(participant).map_err(create_err("ROS context"))
}

/// `identity.resolve_split(name)` as a ros2-client [`Name`].
fn resolved_name(identity: &NodeIdentity, name: &str) -> Result<(Name, String), NodeError> {
    let (ns, base) = identity.resolve_split(name).map_err(create_err("name"))?;
    let full = if ns == "/" {
        format!("/{base}")
    } else {
        format!("{ns}/{base}")
    };
    Ok((Name::new(&ns, &base).map_err(create_err("name"))?, full))
}

/// A target stamped zero is answered with the node's current ROS time (sim time when
/// `use_sim_time` is on, as rclcpp's `now()`); other stamps are kept.
fn stamp_if_zero(target: &mut PoseStamped, now: impl FnOnce() -> crate::messages::Time) {
    let t = &mut target.header.stamp;
    if t.sec == 0 && t.nanosec == 0 {
        *t = now();
    }
}

/// The node's current ROS time (sim time when `use_sim_time` is on).
fn ros_now(node: &ros2_client::Node) -> crate::messages::Time {
    let nanos = node.time_now().to_nanos();
    crate::messages::Time {
        sec: i32::try_from(nanos.div_euclid(1_000_000_000)).unwrap_or(i32::MAX),
        nanosec: nanos.rem_euclid(1_000_000_000) as u32,
    }
}

/// The node's options: /rosout, the parameter services, and a parameter store that validates
/// through `Params::validate`, applies through `Params::apply` and announces the new `Params`
/// to the solver thread; every parameter declared with its descriptor.
fn node_options(
    params: &Params,
    rosout_logs: bool,
    validator_rx: watch::Receiver<Params>,
    setter_tx: Arc<watch::Sender<Params>>,
) -> NodeOptions {
    let mut options = NodeOptions::new()
        .enable_rosout(rosout_logs)
        .start_parameter_services(true)
        .parameter_validator(Box::new(move |name: &str, value: &ParameterValue| {
            validator_rx
                .borrow()
                .validate(name, value)
                .map_err(|e| e.to_string())
        }))
        .parameter_set_action(Box::new(move |name: &str, value: &ParameterValue| {
            let mut result = Ok(());
            setter_tx.send_if_modified(|p| {
                let before = p.clone();
                result = p.apply(name, value).map_err(|e| e.to_string());
                *p != before
            });
            result
        }));
    for (name, value) in params.to_declarations() {
        if let Some(d) = params.descriptor(&name) {
            options = options.describe_parameter(ros_descriptor(&name, &value, d));
        }
        options = options.declare_parameter(&name, value);
    }
    options
}

/// Starts the solver thread: it builds the inverse-geometry atlas (the receiver fires when it
/// is built, with its number of seeds), then runs [`solver_loop`] on a runtime of its own.
#[allow(clippy::too_many_arguments)]
fn spawn_solver_thread(
    processor: Processor,
    links: SolverLinks,
    outputs: Outputs,
    stats: Arc<Stats>,
    log: Logger,
) -> Result<(std::thread::JoinHandle<()>, oneshot::Receiver<usize>), NodeError> {
    let (warm_tx, warm_rx) = oneshot::channel::<usize>();
    let thread = std::thread::Builder::new()
        .name("rod_ig_solver".into())
        .spawn(move || {
            let t0 = std::time::Instant::now();
            let seeds = rod_ig_core::planar::ig::warm_up();
            log::debug!("atlas of {seeds} stable rods built in {:?}", t0.elapsed());
            let _ = warm_tx.send(seeds);
            let rt = match tokio::runtime::Builder::new_current_thread()
                .enable_all()
                .build()
            {
                Ok(rt) => rt,
                Err(e) => {
                    node_log!(log, Error, "cannot start the solver thread's runtime: {e}");
                    return;
                }
            };
            rt.block_on(solver_loop(processor, links, outputs, stats, log));
        })
        .map_err(create_err("solver thread"))?;
    Ok((thread, warm_rx))
}

/// What the solver thread reads (parameters, targets, `rod/solve` calls) and tells (the rod
/// it holds, for `use_current` plans).
struct SolverLinks {
    params_rx: watch::Receiver<Params>,
    /// What `/tf` and `/tf_static` said ([`receive_tf`]).
    tf: Arc<SharedTf>,
    target_rx: watch::Receiver<Option<PoseStamped>>,
    job_rx: mpsc::Receiver<SolveJob>,
    held_tx: watch::Sender<Option<PlanarParams>>,
}

/// Starts the planner thread: `rod/plan` calls are answered there, so that a plan (up to its
/// deadline) never delays targets or `rod/solve` calls. It starts `use_current` plans from
/// the rod the solver thread holds.
fn spawn_planner_thread(
    params_rx: watch::Receiver<Params>,
    mut job_rx: mpsc::Receiver<PlanJob>,
    held_rx: watch::Receiver<Option<PlanarParams>>,
    plan_rods: Arc<Publisher<Marker>>,
    names: Names,
    log: Logger,
) -> Result<std::thread::JoinHandle<()>, NodeError> {
    std::thread::Builder::new()
        .name("rod_ig_planner".into())
        .spawn(move || {
            let mut processor = Processor::new(&params_rx.borrow());
            while let Some((request, reply)) = job_rx.blocking_recv() {
                let params = params_rx.borrow().clone();
                let held = *held_rx.borrow();
                let response = serve_plan(
                    &mut processor,
                    &request,
                    (&params, held),
                    (&plan_rods, &names),
                    &log,
                );
                let _ = reply.send(response); // the caller may have gone
            }
        })
        .map_err(create_err("planner thread"))
}

/// The start-up line: identity, domain, the main parameters and every resolved name.
fn ready_message(
    identity: &NodeIdentity,
    mw: &MiddlewareConfig,
    params: &Params,
    topics: &[String],
    services: &[&str],
) -> String {
    format!(
        "{} ready: domain {}{}, rod_length {} m, path_samples {}, method {}{}; \
         subscribed {}, publishing {}, services {}",
        identity.fully_qualified_name(),
        mw.domain_id,
        match mw.discovery {
            DiscoveryRange::Localhost => " (loopback only)",
            DiscoveryRange::Off => " (discovery off)",
            DiscoveryRange::Subnet => "",
        },
        params.rod_length,
        params.path_samples,
        params.method.as_str(),
        if params.use_sim_time {
            ", sim time (/clock)"
        } else {
            ""
        },
        topics.first().map_or("", String::as_str),
        topics.get(1..).map_or(String::new(), |t| t.join(" ")),
        services.join(" "),
    )
}

/// The node's topics and output publishers, created before the solver warms up.
struct Endpoints {
    target_topic: ros2_client::dds::rustdds::Topic,
    /// `/tf` and `/tf_static` (tf2_msgs/TFMessage).
    tf_topics: [ros2_client::dds::rustdds::Topic; 2],
    solve_name: Name,
    plan_name: Name,
    diagnostics: Publisher<crate::messages::DiagnosticArray>,
    /// Fully qualified names of the topics, then the services (for the start-up line).
    resolved: Vec<String>,
    services: [String; 2],
}

/// The tip wrench's frame id when `tip_frame` is not set: the rod's tip (x along its tangent
/// there), a frame the node does not broadcast (docs/node.md).
const DEFAULT_TIP_WRENCH_FRAME: &str = "rod_tip";

/// The frame id of `rod/tip_wrench`: the tip gripper's TF frame when the node follows one.
fn tip_wrench_frame(params: &Params) -> String {
    if params.tip_frame.is_empty() {
        DEFAULT_TIP_WRENCH_FRAME.to_string()
    } else {
        params.tip_frame.clone()
    }
}

/// Creates the topics and the output publishers (the inputs come after the warm-up).
fn create_endpoints(
    node: &mut ros2_client::Node,
    identity: &NodeIdentity,
    params: &Params,
) -> Result<(Endpoints, Outputs), NodeError> {
    let qos = topic_qos();
    let out_qos = |name| Some(endpoint_qos(&params.qos_of(name)));
    let mut resolved = Vec::new();
    let mut topic = |node: &mut ros2_client::Node, name: &str, ty| {
        let (n, full) = resolved_name(identity, name)?;
        resolved.push(full);
        node.create_topic(&n, ty, &qos).map_err(create_err("topic"))
    };
    let target_topic = topic(node, names::TARGET, type_names::pose_stamped())?;
    let path_topic = topic(node, names::PATH, type_names::path())?;
    let solution_topic = topic(node, names::SOLUTION, type_names::rod_solution())?;
    let marker_topic = topic(node, names::MARKER, type_names::marker())?;
    let plan_rods_topic = topic(node, names::PLAN_RODS, type_names::marker())?;
    let diagnostics_topic = topic(node, names::DIAGNOSTICS, type_names::diagnostic_array())?;
    let wrench_topic = topic(node, names::BASE_WRENCH, type_names::wrench_stamped())?;
    let tip_wrench_topic = topic(node, names::TIP_WRENCH, type_names::wrench_stamped())?;
    // Absolute, as tf2's: not under the node's namespace (remappable).
    let tf_topic = |name: &str| -> Result<_, NodeError> {
        let (n, _) = resolved_name(identity, name)?;
        node.create_topic(
            &n,
            type_names::tf_message(),
            &tf_qos(name == names::TF_STATIC),
        )
        .map_err(create_err("topic"))
    };
    let tf_topics = [tf_topic(names::TF)?, tf_topic(names::TF_STATIC)?];
    let (solve_name, solve_full) = resolved_name(identity, names::SOLVE)?;
    let (plan_name, plan_full) = resolved_name(identity, names::PLAN)?;
    let diagnostics = node
        .create_publisher(&diagnostics_topic, out_qos(names::DIAGNOSTICS))
        .map_err(create_err("/diagnostics publisher"))?;
    let outputs = Outputs {
        path: node
            .create_publisher(&path_topic, out_qos(names::PATH))
            .map_err(create_err("/rod/path publisher"))?,
        solution: node
            .create_publisher(&solution_topic, out_qos(names::SOLUTION))
            .map_err(create_err("/rod/solution publisher"))?,
        marker: node
            .create_publisher(&marker_topic, out_qos(names::MARKER))
            .map_err(create_err("/rod/marker publisher"))?,
        plan_rods: Arc::new(
            node.create_publisher(&plan_rods_topic, out_qos(names::PLAN_RODS))
                .map_err(create_err("/rod/plan_rods publisher"))?,
        ),
        base_wrench: node
            .create_publisher(&wrench_topic, out_qos(names::BASE_WRENCH))
            .map_err(create_err("/rod/base_wrench publisher"))?,
        tip_wrench: node
            .create_publisher(&tip_wrench_topic, out_qos(names::TIP_WRENCH))
            .map_err(create_err("/rod/tip_wrench publisher"))?,
        tip_frame: tip_wrench_frame(params),
        names: Names::of(&resolved, [&solve_full, &plan_full]),
    };
    let endpoints = Endpoints {
        target_topic,
        tf_topics,
        solve_name,
        plan_name,
        diagnostics,
        resolved,
        services: [solve_full, plan_full],
    };
    Ok((endpoints, outputs))
}

/// The node's inputs: the target subscription, the two services and TF.
struct Inputs {
    targets: ros2_client::Subscription<PoseStamped>,
    /// `/tf`, then `/tf_static`.
    tf: [ros2_client::Subscription<TfMessage>; 2],
    /// The resolved target topic (for the logs).
    target_name: String,
    solve: ros2_client::Server<SolveRodRequest, SolveRodResponse>,
    plan: ros2_client::Server<PlanRodRequest, PlanRodResponse>,
}

/// Creates the inputs, once the solver is warm: a client that sees the subscription or the
/// service can count on an answer at steady-state cost, instead of its first targets being
/// coalesced (latest wins) behind the warm-up.
fn create_inputs(
    node: &mut ros2_client::Node,
    endpoints: &Endpoints,
    params: &Params,
) -> Result<Inputs, NodeError> {
    let qos = topic_qos();
    let [tf, tf_static] = &endpoints.tf_topics;
    let mut tf_subscription = |topic, is_static| {
        node.create_subscription::<TfMessage>(topic, Some(tf_qos(is_static)))
            .map_err(create_err("/tf subscription"))
    };
    let tf = [
        tf_subscription(tf, false)?,
        tf_subscription(tf_static, true)?,
    ];
    Ok(Inputs {
        tf,
        target_name: endpoints.resolved[0].clone(),
        targets: node
            .create_subscription::<PoseStamped>(
                &endpoints.target_topic,
                Some(endpoint_qos(&params.qos_of(names::TARGET))),
            )
            .map_err(create_err("/rod/target subscription"))?,
        solve: node
            .create_server(
                ServiceMapping::Enhanced,
                &endpoints.solve_name,
                &type_names::solve_rod(),
                qos.clone(),
                qos.clone(),
            )
            .map_err(create_err("/rod/solve service"))?,
        plan: node
            .create_server(
                ServiceMapping::Enhanced,
                &endpoints.plan_name,
                &type_names::plan_rod(),
                qos.clone(),
                qos,
            )
            .map_err(create_err("/rod/plan service"))?,
    })
}

/// Spawns the node's tasks: the subscriber (newest target into the slot), the two services
/// (requests to the solver thread) and the diagnostics reporter.
#[allow(clippy::too_many_arguments)]
fn spawn_tasks(
    node: &Arc<ros2_client::Node>,
    inputs: Inputs,
    (tf, params_rx): (&Arc<SharedTf>, watch::Receiver<Params>),
    (diagnostics, diag_name): (Publisher<crate::messages::DiagnosticArray>, String),
    target_tx: watch::Sender<Option<PoseStamped>>,
    (solve_tx, plan_tx): (mpsc::Sender<SolveJob>, mpsc::Sender<PlanJob>),
    stats: &Arc<Stats>,
    log: &Logger,
) -> [tokio::task::JoinHandle<()>; 7] {
    let logger = || log.clone();
    let target_tx = Arc::new(target_tx);
    let [tf_dynamic, tf_static] = inputs.tf;
    let tf_tasks = [
        tokio::spawn(receive_tf(tf_dynamic, tf.clone(), false, logger())),
        tokio::spawn(receive_tf(tf_static, tf.clone(), true, logger())),
        tokio::spawn(follow_tip_frame(
            params_rx,
            tf.clone(),
            Arc::clone(&target_tx),
            Arc::clone(stats),
            logger(),
        )),
    ];
    let subscriber = tokio::spawn(receive_targets(
        inputs.targets,
        target_tx,
        Arc::clone(stats),
        logger(),
        Arc::clone(node),
        inputs.target_name,
    ));
    let reporter = tokio::spawn(report_diagnostics(
        diagnostics,
        Arc::clone(stats),
        Arc::clone(node),
        diag_name,
    ));
    let plan_clock = Arc::clone(node);
    let plan = tokio::spawn(serve_requests(
        inputs.plan,
        plan_tx,
        Arc::clone(stats),
        logger(),
        move |request: &mut PlanRodRequest| {
            stamp_if_zero(&mut request.goal, || ros_now(&plan_clock))
        },
    ));
    let solve_clock = Arc::clone(node);
    let solve = tokio::spawn(serve_requests(
        inputs.solve,
        solve_tx,
        Arc::clone(stats),
        logger(),
        move |request: &mut SolveRodRequest| {
            stamp_if_zero(&mut request.target, || ros_now(&solve_clock))
        },
    ));
    let [tf_task, tf_static_task, follow_task] = tf_tasks;
    [
        subscriber,
        solve,
        plan,
        reporter,
        tf_task,
        tf_static_task,
        follow_task,
    ]
}

/// Runs the node until SIGINT or SIGTERM.
pub async fn run(startup: Startup, mw: MiddlewareConfig) -> Result<(), NodeError> {
    // The signal handlers first: a SIGINT or SIGTERM during start-up (the atlas build takes
    // ~0.2 s) ends the node cleanly too, as rclcpp's does, instead of killing it.
    let mut signals = Signals::install();
    let running = tokio::select! {
        running = start(startup, mw) => running?,
        signal = signals.recv() => {
            log::info!("{signal} during start-up: exiting");
            return Ok(());
        }
    };
    let signal = signals.recv().await;
    let Running {
        logger,
        stats,
        tasks,
        threads,
        node,
        spin_task,
        params_tx,
    } = running;
    log_shutdown(&logger, signal, &stats);
    // The logger's /rosout writer goes before the node (and its participant).
    drop(logger);
    shut_down(tasks, threads, node, spin_task).await;
    drop(params_tx);
    Ok(())
}

/// The node once started: what shutting down stops.
struct Running {
    logger: Logger,
    stats: Arc<Stats>,
    tasks: [tokio::task::JoinHandle<()>; 7],
    threads: [std::thread::JoinHandle<()>; 2],
    node: Arc<ros2_client::Node>,
    spin_task: tokio::task::JoinHandle<()>,
    params_tx: Arc<watch::Sender<Params>>,
}

/// Starts the node: endpoints, worker threads (after the atlas is built), then the inputs.
async fn start(startup: Startup, mw: MiddlewareConfig) -> Result<Running, NodeError> {
    let Startup {
        params,
        identity,
        rosout_logs,
        logger: log_settings,
        ..
    } = startup;
    let context = create_context(&mw)?;

    // Parameters: the node's parameter store validates through `Params::validate` and
    // applies through `Params::apply`, then the solver task sees the new `Params`.
    let (params_tx, params_rx) = watch::channel(params.clone());
    let params_tx = Arc::new(params_tx);
    let options = node_options(
        &params,
        rosout_logs,
        params_rx.clone(),
        Arc::clone(&params_tx),
    );
    let mut node = create_node(&context, &identity, options)?;
    let logger = Logger::new(&node, &log_settings);
    let (endpoints, outputs) = create_endpoints(&mut node, &identity, &params)?;
    let spin_task = start_spinner(&mut node, &params)?;

    let stats = Arc::new(Stats::default());
    let workers = start_workers(&params, params_rx, outputs, &stats, &logger)?;
    let atlas_seeds = workers.warm.await.unwrap_or(0);
    log::debug!("solver warm: {atlas_seeds} atlas seeds");

    let inputs = create_inputs(&mut node, &endpoints, &params)?;
    let node = Arc::new(node);
    let tasks = spawn_tasks(
        &node,
        inputs,
        (&workers.tf, params_tx.subscribe()),
        (
            endpoints.diagnostics,
            format!("{}: inverse geometry", identity.fully_qualified_name()),
        ),
        workers.target_tx,
        workers.jobs,
        &stats,
        &logger,
    );
    let [solve_full, plan_full] = &endpoints.services;
    let ready = ready_message(
        &identity,
        &mw,
        &params,
        &endpoints.resolved,
        &[solve_full, plan_full],
    );
    node_log!(logger, Info, "{ready}");
    for warning in &mw.warnings {
        node_log!(logger, Warn, "{warning}");
    }
    Ok(Running {
        logger,
        stats,
        tasks,
        threads: workers.threads,
        node,
        spin_task,
        params_tx,
    })
}

/// The solver and planner threads, and the channels into them.
struct Workers {
    threads: [std::thread::JoinHandle<()>; 2],
    /// Fires when the solver's atlas is built (with its number of seeds).
    warm: oneshot::Receiver<usize>,
    /// The transform buffer the TF tasks fill and the solver thread reads.
    tf: Arc<SharedTf>,
    target_tx: watch::Sender<Option<PoseStamped>>,
    jobs: (mpsc::Sender<SolveJob>, mpsc::Sender<PlanJob>),
}

/// Starts the solver thread (it owns the Processor, and so the warm start: solving is
/// CPU-bound, up to the deadline per call, so it runs on a thread of its own, not on the
/// async runtime's workers that serve DDS; it builds the inverse-geometry atlas first, so
/// that the first target costs what later ones do) and the planner thread.
fn start_workers(
    params: &Params,
    params_rx: watch::Receiver<Params>,
    outputs: Outputs,
    stats: &Arc<Stats>,
    logger: &Logger,
) -> Result<Workers, NodeError> {
    let (target_tx, target_rx) = watch::channel::<Option<PoseStamped>>(None);
    let tf = Arc::new(SharedTf::new());
    let (solve_tx, solve_rx) = mpsc::channel::<SolveJob>(16);
    let (plan_tx, plan_rx) = mpsc::channel::<PlanJob>(16);
    let (held_tx, held_rx) = watch::channel::<Option<PlanarParams>>(None);
    let planner = spawn_planner_thread(
        params_rx.clone(),
        plan_rx,
        held_rx,
        Arc::clone(&outputs.plan_rods),
        outputs.names.clone(),
        logger.clone(),
    )?;
    let links = SolverLinks {
        params_rx,
        tf: Arc::clone(&tf),
        target_rx,
        job_rx: solve_rx,
        held_tx,
    };
    let (solver, warm) = spawn_solver_thread(
        Processor::new(params),
        links,
        outputs,
        Arc::clone(stats),
        logger.clone(),
    )?;
    Ok(Workers {
        threads: [solver, planner],
        warm,
        tf,
        target_tx,
        jobs: (solve_tx, plan_tx),
    })
}

/// The shutdown record: the signal and what the node did.
fn log_shutdown(logger: &Logger, signal: &str, stats: &Stats) {
    node_log!(
        logger,
        Info,
        "{signal}: shutting down after {} targets received, {} solved, {} failed, {} service calls",
        stats.received.load(Ordering::Relaxed),
        stats.solved.load(Ordering::Relaxed),
        stats.failed.load(Ordering::Relaxed),
        stats.service_calls.load(Ordering::Relaxed),
    );
}

/// Stops the tasks, lets the solver thread finish its solve in progress (bounded by its
/// deadline), then drops the node and waits for the spinner.
async fn shut_down(
    tasks: [tokio::task::JoinHandle<()>; 7],
    threads: [std::thread::JoinHandle<()>; 2],
    node: Arc<ros2_client::Node>,
    spin_task: tokio::task::JoinHandle<()>,
) {
    for task in tasks {
        task.abort();
        // Awaited so that the tasks' clones of the node are dropped before the node.
        let _ = task.await;
    }
    // With the subscriber and the service task gone, the solver loop's channels close and it
    // returns (after the solve in progress, bounded by its deadline).
    for thread in threads {
        let _ = tokio::task::spawn_blocking(move || thread.join()).await;
    }
    // Dropping the node tells the spinner to stop (stop_spinner() too, but then the drop
    // would log an error).
    drop(node);
    let _ = tokio::time::timeout(std::time::Duration::from_secs(2), spin_task).await;
}

/// The node, named and placed as `identity` says.
fn create_node(
    context: &Context,
    identity: &NodeIdentity,
    options: NodeOptions,
) -> Result<ros2_client::Node, NodeError> {
    let name =
        NodeName::new(&identity.namespace, &identity.name).map_err(create_err("node name"))?;
    context.new_node(name, options).map_err(create_err("node"))
}

/// Starts the node's spinner (parameter services, /rosout, the clock) on the runtime.
fn start_spinner(
    node: &mut ros2_client::Node,
    params: &Params,
) -> Result<tokio::task::JoinHandle<()>, NodeError> {
    let spinner = node.spinner().map_err(create_err("spinner"))?;
    if params.use_sim_time {
        // The declaration holds the start-up value; setting it again makes the parameter
        // store switch its clock (and announce it on /parameter_events).
        node.set_parameter("use_sim_time", ParameterValue::Boolean(true))
            .map_err(|e| NodeError::Create {
                what: "use_sim_time",
                reason: e,
            })?;
    }
    Ok(tokio::spawn(async move {
        if let Err(e) = spinner.spin().await {
            log::error!("spinner stopped: {e:?}");
        }
    }))
}

/// The subscriber task: every valid target replaces the one waiting in the slot (latest wins);
/// unstamped targets get the node's clock time.
async fn receive_targets(
    subscription: ros2_client::Subscription<PoseStamped>,
    target_tx: Arc<watch::Sender<Option<PoseStamped>>>,
    stats: Arc<Stats>,
    log: Logger,
    clock_node: Arc<ros2_client::Node>,
    topic: String,
) {
    let mut stream = pin!(subscription.async_stream());
    while let Some(item) = stream.next().await {
        match item {
            Ok((mut msg, _info)) => {
                stamp_if_zero(&mut msg, || ros_now(&clock_node));
                let t = &msg.header.stamp;
                node_log!(
                    log,
                    Debug,
                    "{topic}: received the target stamped {}.{:09}",
                    t.sec,
                    t.nanosec
                );
                stats.received.fetch_add(1, Ordering::Relaxed);
                target_tx.send_replace(Some(msg));
            }
            Err(e) => node_log!(log, Warn, "{topic}: dropped a bad message: {e:?}"),
        }
    }
}

/// Transforms kept per dynamic frame (tf2's default cache).
const TF_CACHE_SECONDS: f64 = 10.0;

/// The transforms `/tf` and `/tf_static` said, shared by the TF tasks and the solver thread.
struct SharedTf {
    transforms: std::sync::Mutex<TfBuffer>,
    /// Signalled after each TF message (one stored permit: no update is missed).
    updated: tokio::sync::Notify,
}

impl SharedTf {
    fn new() -> Self {
        Self {
            transforms: std::sync::Mutex::new(TfBuffer::new(TF_CACHE_SECONDS)),
            updated: tokio::sync::Notify::new(),
        }
    }
}
/// How often a target waiting for its transform looks again.
const TF_POLL: std::time::Duration = std::time::Duration::from_millis(5);

/// The `tip_frame` task: on each TF update (at most `tf_rate` times a second; a lookup
/// depends on nothing else, so none is wasted between updates), the tip gripper's frame in
/// `base_frame` at the latest time TF knows it; each new pose goes to the solver as a target on `rod/target` would (so the
/// rod follows its branch, and an out-of-plane pose is solved in 3-D or refused as a target
/// is). Stamped with the transform's time (a static chain: the system time when it changes).
async fn follow_tip_frame(
    mut params_rx: watch::Receiver<Params>,
    buffer: Arc<SharedTf>,
    target_tx: Arc<watch::Sender<Option<PoseStamped>>>,
    stats: Arc<Stats>,
    log: Logger,
) {
    let mut last: Option<(Option<i64>, nalgebra::Isometry3<f64>)> = None;
    let mut last_error = String::new();
    loop {
        let params = params_rx.borrow_and_update().clone();
        if params.tip_frame.is_empty() {
            last = None;
            if params_rx.changed().await.is_err() {
                break;
            }
            continue;
        }
        let looked_up = match buffer.transforms.lock() {
            Ok(b) => b.lookup_latest(&params.base_frame, &params.tip_frame),
            Err(_) => break,
        };
        match looked_up {
            // A new pose (the same pose at a later stamp is not a new target).
            Ok(now) if last.as_ref().map(|l| l.1) != Some(now.1) => {
                last_error.clear();
                let target = tip_target(&params.base_frame, now.0, &now.1);
                stats.received.fetch_add(1, Ordering::Relaxed);
                target_tx.send_replace(Some(target));
                last = Some(now);
            }
            Ok(_) => {}
            Err(e) => {
                let e = e.to_string();
                if e != last_error {
                    node_log!(log, Warn, "tip_frame {:?}: {e}", params.tip_frame);
                    last_error = e;
                }
            }
        }
        // At most tf_rate lookups a second, then the next TF update (or a parameter change,
        // which is looked at at once).
        let period = std::time::Duration::from_secs_f64(1.0 / params.tf_rate);
        tokio::select! {
            () = async {
                tokio::time::sleep(period).await;
                buffer.updated.notified().await;
            } => {}
            changed = params_rx.changed() => if changed.is_err() { break },
        }
    }
}

/// The tip frame's pose as a target in `base_frame`.
fn tip_target(base: &str, time: Option<i64>, pose: &nalgebra::Isometry3<f64>) -> PoseStamped {
    let nanos = time.unwrap_or_else(|| {
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| i64::try_from(d.as_nanos()).unwrap_or(i64::MAX))
    });
    let (t, q) = (&pose.translation.vector, pose.rotation.quaternion());
    PoseStamped {
        header: crate::messages::Header {
            stamp: crate::messages::Time {
                sec: i32::try_from(nanos.div_euclid(1_000_000_000)).unwrap_or(i32::MAX),
                nanosec: nanos.rem_euclid(1_000_000_000) as u32,
            },
            frame_id: base.to_string(),
        },
        pose: crate::messages::Pose {
            position: crate::messages::Point {
                x: t.x,
                y: t.y,
                z: t.z,
            },
            orientation: crate::messages::Quaternion {
                x: q.i,
                y: q.j,
                z: q.k,
                w: q.w,
            },
        },
    }
}

/// A TF task: every transform of `/tf` (or `/tf_static`) into the buffer; one that tf2 would
/// refuse (empty or '/'-led frame id, non-finite, not a rotation) is logged and skipped.
async fn receive_tf(
    subscription: ros2_client::Subscription<TfMessage>,
    buffer: Arc<SharedTf>,
    is_static: bool,
    log: Logger,
) {
    let topic = if is_static {
        names::TF_STATIC
    } else {
        names::TF
    };
    let mut stream = pin!(subscription.async_stream());
    while let Some(item) = stream.next().await {
        let msg = match item {
            Ok((msg, _info)) => msg,
            Err(e) => {
                node_log!(log, Warn, "{topic}: dropped a bad message: {e:?}");
                continue;
            }
        };
        {
            let Ok(mut b) = buffer.transforms.lock() else {
                break;
            };
            for t in &msg.transforms {
                if let Err(e) = b.insert(&crate::tf_buffer::from_message(t), is_static) {
                    log::debug!("{topic}: {e}");
                }
            }
        }
        buffer.updated.notify_one();
    }
}

/// Standard gravity (m/s²), the magnitude `world_frame` gives gravity.
const STANDARD_GRAVITY: f64 = 9.80665;

/// What TF answers to `f`, waited for up to `timeout` s (its last error once it passes).
async fn wait_for_tf<T>(
    buffer: &std::sync::Mutex<TfBuffer>,
    timeout: f64,
    f: impl Fn(&TfBuffer) -> Result<T, crate::tf_buffer::LookupError>,
) -> Result<T, crate::tf_buffer::LookupError> {
    let until = std::time::Instant::now() + std::time::Duration::from_secs_f64(timeout);
    loop {
        let looked_up = match buffer.lock() {
            Ok(b) => f(&b),
            Err(p) => f(&p.into_inner()),
        };
        match looked_up {
            Err(_) if std::time::Instant::now() < until => tokio::time::sleep(TF_POLL).await,
            done => return done,
        }
    }
}

/// Frames of targets taken as the base gripper's without TF (`use_tf` off), each warned
/// about once, so that a target stamped in `world` is not silently solved in the wrong frame.
#[derive(Default)]
struct UntransformedFrames {
    warned: std::collections::HashSet<String>,
}

impl UntransformedFrames {
    /// At most this many distinct frames are remembered (a flood of frame names stays bounded).
    const KEEP: usize = 64;

    /// Warns once per frame that a target in `frame` is taken as in `base_frame`.
    fn note(&mut self, frame: &str, params: &Params, log: &Logger) {
        if params.use_tf || frame.is_empty() || frame == params.base_frame {
            return;
        }
        if self.warned.len() < Self::KEEP && self.warned.insert(frame.to_string()) {
            node_log!(
                log,
                Warn,
                "targets in frame {frame:?} are taken as in the base gripper's frame {:?}: \
                 use_tf is off (set use_tf:=true to transform them through TF)",
                params.base_frame
            );
        }
    }
}

/// The target and the parameters to solve it with, through TF: the target in `base_frame`
/// when `use_tf` is on and it is stamped in another frame (its transform at its stamp), and
/// gravity from `world_frame` (−9.80665 m/s² along the world's z, in `base_frame` at the
/// target's stamp) when that is set and the rod has weight. Each waits up to `tf_timeout`.
async fn through_tf(
    target: &PoseStamped,
    params: &Params,
    buffer: &std::sync::Mutex<TfBuffer>,
) -> Result<(PoseStamped, Params), crate::convert::TargetError> {
    let refused =
        |frame: &str, e: crate::tf_buffer::LookupError| crate::convert::TargetError::Frame {
            frame: frame.to_string(),
            base: params.base_frame.clone(),
            timeout: params.tf_timeout,
            why: e.to_string(),
        };
    let frame = &target.header.frame_id;
    let target = if !params.use_tf || frame.is_empty() || *frame == params.base_frame {
        target.clone()
    } else {
        wait_for_tf(buffer, params.tf_timeout, |b| {
            crate::tf_buffer::pose_in_frame(b, &params.base_frame, target)
        })
        .await
        .map_err(|e| refused(frame, e))?
    };
    let world = &params.world_frame;
    if world.is_empty() || params.linear_density == 0.0 {
        return Ok((target, params.clone()));
    }
    let stamp = &target.header.stamp;
    let time = (stamp.sec != 0 || stamp.nanosec != 0)
        .then(|| i64::from(stamp.sec) * 1_000_000_000 + i64::from(stamp.nanosec));
    let world_in_base = wait_for_tf(buffer, params.tf_timeout, |b| {
        b.lookup(&params.base_frame, world, time)
    })
    .await
    .map_err(|e| refused(world, e))?;
    let g = world_in_base.rotation * nalgebra::Vector3::new(0.0, 0.0, -STANDARD_GRAVITY);
    let mut with_gravity = params.clone();
    with_gravity.gravity = [g.x, g.y, g.z];
    Ok((target, with_gravity))
}

/// The diagnostics task: one DiagnosticArray per [`DIAGNOSTICS_PERIOD`] from the solve record.
async fn report_diagnostics(
    publisher: Publisher<crate::messages::DiagnosticArray>,
    stats: Arc<Stats>,
    clock_node: Arc<ros2_client::Node>,
    name: String,
) {
    let mut tick = tokio::time::interval(DIAGNOSTICS_PERIOD);
    tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    tick.tick().await; // the first tick is immediate
    let mut last = tokio::time::Instant::now();
    loop {
        tick.tick().await;
        let now = tokio::time::Instant::now();
        let status = {
            let Ok(mut solves) = stats.solves.lock() else {
                break;
            };
            solves.report(
                &name,
                (now - last).as_secs_f64(),
                stats.received.load(Ordering::Relaxed),
                stats.service_calls.load(Ordering::Relaxed),
            )
        };
        last = now;
        let msg = crate::messages::DiagnosticArray {
            header: crate::messages::Header {
                stamp: ros_now(&clock_node),
                frame_id: String::new(),
            },
            status: vec![status],
        };
        if let Err(e) = publisher.publish(msg) {
            log::warn!("cannot publish /diagnostics: {e:?}");
        }
    }
}

/// A service task: each request (stamped by `prepare` when unstamped) goes to its worker
/// thread, and its answer goes back to the caller while the next request is taken, so a
/// large answer still being written queues nothing. The answers in flight are polled inside
/// this task, not spawned: aborting the task at shutdown drops them with the server, before
/// the node (a detached answer outlived the participant and RustDDS logged ERRORs).
async fn serve_requests<Req, Resp>(
    server: ros2_client::Server<Req, Resp>,
    job_tx: mpsc::Sender<(Req, oneshot::Sender<Resp>)>,
    stats: Arc<Stats>,
    log: Logger,
    prepare: impl Fn(&mut Req),
) where
    Req: ros2_client::Message + 'static,
    Resp: ros2_client::Message + Send + Sync + 'static,
    ros2_client::Server<Req, Resp>: Send + Sync,
{
    let mut replies = futures::stream::FuturesUnordered::new();
    let mut requests = pin!(server.receive_request_stream());
    loop {
        let item = tokio::select! {
            item = requests.next() => item,
            Some(()) = replies.next(), if !replies.is_empty() => continue,
        };
        let Some(item) = item else { break };
        let (id, mut request) = match item {
            Ok(r) => r,
            Err(e) => {
                node_log!(log, Warn, "service: dropped a bad request: {e:?}");
                continue;
            }
        };
        stats.service_calls.fetch_add(1, Ordering::Relaxed);
        prepare(&mut request);
        let (reply_tx, reply_rx) = oneshot::channel();
        if job_tx.send((request, reply_tx)).await.is_err() {
            break; // worker gone: shutting down
        }
        let (server, log) = (&server, &log);
        replies.push(async move {
            let Ok(response) = reply_rx.await else { return };
            if let Err(e) = server.async_send_response(id, response).await {
                node_log!(log, Warn, "service: cannot send the response: {e:?}");
            }
        });
    }
}

/// SIGINT and SIGTERM, listened to from the node's first instant.
struct Signals {
    interrupt: Option<tokio::signal::unix::Signal>,
    terminate: Option<tokio::signal::unix::Signal>,
}

impl Signals {
    /// Installs the handlers (a handler that cannot be installed is logged and skipped).
    fn install() -> Self {
        use tokio::signal::unix::{signal, SignalKind};
        let install = |kind, name| match signal(kind) {
            Ok(s) => Some(s),
            Err(e) => {
                log::warn!("cannot install a {name} handler: {e}");
                None
            }
        };
        Self {
            interrupt: install(SignalKind::interrupt(), "SIGINT"),
            terminate: install(SignalKind::terminate(), "SIGTERM"),
        }
    }

    /// Waits for either signal; returns its name.
    async fn recv(&mut self) -> &'static str {
        async fn next(s: &mut Option<tokio::signal::unix::Signal>) {
            match s {
                Some(s) => {
                    s.recv().await;
                }
                None => std::future::pending().await,
            }
        }
        tokio::select! {
            _ = next(&mut self.interrupt) => "SIGINT",
            _ = next(&mut self.terminate) => "SIGTERM",
        }
    }
}

/// Solves service requests (first) and the newest target, and publishes the results.
async fn solver_loop(
    mut processor: Processor,
    links: SolverLinks,
    outputs: Outputs,
    stats: Arc<Stats>,
    log: Logger,
) {
    let SolverLinks {
        mut params_rx,
        tf,
        mut target_rx,
        mut job_rx,
        held_tx,
    } = links;
    // The parameters as last logged: a change is logged as its differences.
    let mut logged_params = params_rx.borrow().clone();
    let mut untransformed = UntransformedFrames::default();
    loop {
        tokio::select! {
            biased;
            job = job_rx.recv() => {
                let Some((mut request, reply)) = job else { break };
                let params = params_rx.borrow_and_update().clone();
                untransformed.note(&request.target.header.frame_id, &params, &log);
                let response = match through_tf(&request.target, &params, &tf.transforms).await {
                    Ok((target, params)) => {
                        request.target = target;
                        serve_solve(&mut processor, &request, &params, &stats, &log, &outputs.names)
                    }
                    Err(e) => {
                        node_log!(log, Warn, "{}: {e}", outputs.names.solve);
                        let outcome = Processor::refused(&request.target, &params, e);
                        SolveRodResponse {
                            path: Path {
                                header: outcome.solution.header.clone(),
                                poses: Vec::new(),
                            },
                            solution: outcome.solution,
                        }
                    }
                };
                let _ = reply.send(response); // the caller may have gone
            }
            changed = target_rx.changed() => {
                if changed.is_err() {
                    break; // subscriber gone
                }
                let Some(target) = target_rx.borrow_and_update().clone() else { continue };
                if params_rx.has_changed().unwrap_or(false) {
                    let now = params_rx.borrow_and_update().clone();
                    let changes = now.changes_from(&logged_params);
                    if !changes.is_empty() {
                        node_log!(log, Info, "parameters changed: {}", changes.join(", "));
                    }
                    logged_params = now;
                }
                let params = params_rx.borrow().clone();
                let started = std::time::Instant::now();
                untransformed.note(&target.header.frame_id, &params, &log);
                let (target, params) = match through_tf(&target, &params, &tf.transforms).await {
                    Ok(resolved) => resolved,
                    Err(e) => {
                        let outcome = Processor::refused(&target, &params, e);
                        let work = Counters::default();
                        report(&log, &stats, &outputs.names.target, &outcome, &work, started.elapsed());
                        publish(&log, &outputs, outcome);
                        continue;
                    }
                };
                let (outcome, work) = observe(Counters::default(), || {
                    processor.process(&target, &params, &Overrides::default())
                });
                report(&log, &stats, &outputs.names.target, &outcome, &work, started.elapsed());
                publish(&log, &outputs, outcome);
            }
        }
        held_tx.send_replace(processor.held_rod());
    }
}

/// Answers one `/rod/plan` call (the planned rods also go out on `/rod/plan_rods`), starting
/// a `use_current` plan from `held`.
fn serve_plan(
    processor: &mut Processor,
    request: &PlanRodRequest,
    (params, held): (&Params, Option<PlanarParams>),
    (plan_rods, names): (&Publisher<Marker>, &Names),
    log: &Logger,
) -> PlanRodResponse {
    let started = std::time::Instant::now();
    let planned = processor.plan(request, params, held);
    let r = &planned.response;
    if r.success {
        log::debug!(
            "{}: {} rods in {:?}",
            names.plan,
            r.rods.len() / 3,
            started.elapsed()
        );
    } else {
        node_log!(log, Warn, "{}: no plan: {}", names.plan, r.reason);
    }
    if let Some(marker) = planned.marker {
        if let Err(e) = plan_rods.publish(marker) {
            node_log!(log, Error, "cannot publish {}: {e:?}", names.plan_rods);
        }
    }
    planned.response
}

/// Answers one `/rod/solve` call.
fn serve_solve(
    processor: &mut Processor,
    request: &SolveRodRequest,
    params: &Params,
    stats: &Stats,
    log: &Logger,
    names: &Names,
) -> SolveRodResponse {
    match Overrides::from_request(request) {
        Ok(overrides) => {
            let started = std::time::Instant::now();
            let (outcome, work) = observe(Counters::default(), || {
                if request.move_rod {
                    processor.process(&request.target, params, &overrides)
                } else {
                    processor.query(&request.target, params, &overrides)
                }
            });
            report(log, stats, &names.solve, &outcome, &work, started.elapsed());
            SolveRodResponse {
                path: outcome.path.unwrap_or_else(|| Path {
                    header: outcome.solution.header.clone(),
                    poses: Vec::new(),
                }),
                solution: outcome.solution,
            }
        }
        Err(reason) => {
            node_log!(log, Warn, "{}: bad request: {reason}", names.solve);
            let header = crate::convert::output_header(&request.target.header, params);
            SolveRodResponse {
                solution: crate::convert::failure_message(
                    format!("bad request: {reason}"),
                    None,
                    &header,
                    params,
                    0.0,
                ),
                path: Path {
                    header,
                    poses: Vec::new(),
                },
            }
        }
    }
}

fn report(
    log: &Logger,
    stats: &Stats,
    source: &str,
    outcome: &Outcome,
    work: &Counters,
    elapsed: std::time::Duration,
) {
    if let Ok(mut solves) = stats.solves.lock() {
        solves.record_work(work);
        solves.record(
            outcome.solution.success,
            outcome.failure,
            &outcome.solution.message,
            elapsed.as_secs_f64(),
        );
    }
    if outcome.solution.success {
        stats.solved.fetch_add(1, Ordering::Relaxed);
        node_log!(log, Debug, "{source}: {}", outcome.solution.message);
    } else {
        stats.failed.fetch_add(1, Ordering::Relaxed);
        node_log!(
            log,
            Warn,
            "{source}: no solution: {}",
            outcome.solution.message
        );
    }
}

fn publish(log: &Logger, outputs: &Outputs, outcome: Outcome) {
    // Path first: it is what latency-sensitive clients wait for.
    if let Some(path) = outcome.path {
        if let Err(e) = outputs.path.publish(path) {
            node_log!(log, Error, "cannot publish {}: {e:?}", outputs.names.path);
        }
    }
    // The base wrench for wrench displays and plotters, when it is known in newtons.
    if outcome.solution.success && outcome.solution.wrench_valid {
        let stamped = WrenchStamped {
            header: outcome.solution.header.clone(),
            wrench: outcome.solution.base_wrench,
        };
        if let Err(e) = outputs.base_wrench.publish(stamped) {
            node_log!(
                log,
                Error,
                "cannot publish {}: {e:?}",
                outputs.names.base_wrench
            );
        }
        let mut header = outcome.solution.header.clone();
        header.frame_id.clone_from(&outputs.tip_frame);
        let tip = WrenchStamped {
            header,
            wrench: outcome.solution.tip_wrench,
        };
        if let Err(e) = outputs.tip_wrench.publish(tip) {
            node_log!(
                log,
                Error,
                "cannot publish {}: {e:?}",
                outputs.names.tip_wrench
            );
        }
    }
    if let Err(e) = outputs.solution.publish(outcome.solution) {
        node_log!(
            log,
            Error,
            "cannot publish {}: {e:?}",
            outputs.names.solution
        );
    }
    if let Some(marker) = outcome.marker {
        if let Err(e) = outputs.marker.publish(marker) {
            node_log!(log, Error, "cannot publish {}: {e:?}", outputs.names.marker);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env<'a>(pairs: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
        move |k| {
            pairs
                .iter()
                .find(|(n, _)| *n == k)
                .map(|(_, v)| v.to_string())
        }
    }

    #[test]
    fn middleware_from_environment() {
        let c = MiddlewareConfig::from_lookup(env(&[])).unwrap();
        assert_eq!((c.domain_id, c.localhost_only), (0, false));
        assert_eq!(c.discovery, DiscoveryRange::Subnet);
        let c = MiddlewareConfig::from_lookup(env(&[
            ("ROS_DOMAIN_ID", "42"),
            ("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST"),
        ]))
        .unwrap();
        assert_eq!((c.domain_id, c.localhost_only), (42, true));
        let c = MiddlewareConfig::from_lookup(env(&[("ROS_LOCALHOST_ONLY", "1")])).unwrap();
        assert!(c.localhost_only);
        assert!(MiddlewareConfig::from_lookup(env(&[("ROS_DOMAIN_ID", "300")])).is_err());
        assert!(MiddlewareConfig::from_lookup(env(&[("ROS_DOMAIN_ID", "x")])).is_err());
        let off = [("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")];
        assert_eq!(
            MiddlewareConfig::from_lookup(env(&off)).unwrap().discovery,
            DiscoveryRange::Off
        );
        let bad = [("ROS_AUTOMATIC_DISCOVERY_RANGE", "GALAXY")];
        assert!(MiddlewareConfig::from_lookup(env(&bad)).is_err());
        let peers = [
            ("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF"),
            ("ROS_STATIC_PEERS", "10.0.0.2"),
        ];
        assert!(MiddlewareConfig::from_lookup(env(&peers)).is_err());
        let peers = [("ROS_STATIC_PEERS", "10.0.0.2")];
        assert_eq!(
            MiddlewareConfig::from_lookup(env(&peers))
                .unwrap()
                .warnings
                .len(),
            1
        );
    }

    #[test]
    fn security_enforce_refuses_and_permissive_warns() {
        let enforce = [
            ("ROS_SECURITY_ENABLE", "true"),
            ("ROS_SECURITY_STRATEGY", "Enforce"),
        ];
        let e = MiddlewareConfig::from_lookup(env(&enforce)).unwrap_err();
        assert!(e.to_string().contains("Enforce"), "{e}");
        let permissive = [
            ("ROS_SECURITY_ENABLE", "true"),
            ("ROS_SECURITY_STRATEGY", "Permissive"),
        ];
        let c = MiddlewareConfig::from_lookup(env(&permissive)).unwrap();
        assert!(c.warnings[0].contains("WITHOUT DDS security"));
        // rcl reads "true" only.
        let other = [
            ("ROS_SECURITY_ENABLE", "1"),
            ("ROS_SECURITY_STRATEGY", "Enforce"),
        ];
        assert!(MiddlewareConfig::from_lookup(env(&other))
            .unwrap()
            .warnings
            .is_empty());
    }

    #[test]
    fn function_names_for_rosout() {
        assert_eq!(
            function_of("rod_ig_node::node::serve_plan::here"),
            "serve_plan"
        );
        assert_eq!(
            function_of("rod_ig_node::node::receive_targets::{{closure}}::here"),
            "receive_targets"
        );
        fn probe() -> &'static str {
            function_name!()
        }
        assert_eq!(probe(), "probe");
    }
}
