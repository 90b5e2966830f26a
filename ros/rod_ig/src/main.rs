//! `rod_ig_node`: start-up (arguments, logging, runtime) of the ROS 2 node; see [`rod_ig_node::node`].

use std::process::ExitCode;

use rod_ig_node::node::{self, MiddlewareConfig};
use rod_ig_node::params::{self, Command};

/// Console log filter: info, with the DDS libraries' chatter kept down.
const DEFAULT_LOG_FILTER: &str =
    "info,rustdds=error,rustdds::network::udp_listener=off,ros2_client=warn";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    // The logger first (parsing a params file logs warnings), with `--log-level` winning over
    // RUST_LOG, as the ROS command line does over the environment.
    let mut logger = env_logger::Builder::from_env(
        env_logger::Env::default().default_filter_or(DEFAULT_LOG_FILTER),
    );
    let ros = rod_ig_node::ros_args::parse(&args).ok();
    let own_logger = ros
        .as_ref()
        .and_then(|a| a.identity(rod_ig_node::graph::NODE_NAME, "/").ok())
        .map_or_else(
            || rod_ig_node::graph::NODE_NAME.to_string(),
            |i| i.logger_name(),
        );
    if let Some(f) = ros.as_ref().and_then(|a| a.log_filter(&own_logger)) {
        logger.parse_filters(&f);
    }
    if ros.as_ref().and_then(|a| a.stdout_logs) == Some(false) {
        // `--disable-stdout-logs`: nothing on the console (rcl's switch).
        logger.parse_filters("off");
    }
    // Milliseconds: start-up and matching events are a few ms apart (ROS logs stamp finer).
    logger.format_timestamp_millis().init();
    let parsed = params::parse_args(&args);

    let startup = match parsed {
        Ok(Command::Run(s)) => *s,
        Ok(Command::Help) => {
            print!("{}", params::usage());
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            eprintln!("rod_ig_node: {e}\n\n{}", params::usage());
            return ExitCode::from(2);
        }
    };
    let mw = match MiddlewareConfig::from_env() {
        Ok(m) => m,
        Err(e) => {
            eprintln!("rod_ig_node: {e}");
            return ExitCode::from(2);
        }
    };
    let runtime = match tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
    {
        Ok(r) => r,
        Err(e) => {
            eprintln!("rod_ig_node: cannot start the async runtime: {e}");
            return ExitCode::FAILURE;
        }
    };
    match runtime.block_on(node::run(startup, mw)) {
        Ok(()) => {
            runtime.shutdown_timeout(std::time::Duration::from_secs(1));
            ExitCode::SUCCESS
        }
        Err(e) => {
            log::error!("rod_ig_node: {e}");
            ExitCode::FAILURE
        }
    }
}
