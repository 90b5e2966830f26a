#!/usr/bin/env bash
# Builds (if needed) and runs rod_ig_node with working defaults; extra arguments go to the node,
# e.g.   scripts/run-node.sh -p rod_length:=0.8 --params-file ros/rod_ig/config/rod_ig_params.yaml
#
# The node itself needs no Python or ROS install (pure Rust DDS). Environment honoured:
# ROS_DOMAIN_ID (default 0), ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST or ROS_LOCALHOST_ONLY=1
# (loopback only), RUST_LOG (console log filter). Stop with Ctrl-C (SIGINT) or SIGTERM.
# With ROD_IG_SETUP_CLIENT=1 it also prepares the rclpy venv and rod_ig_msgs for clients
# (scripts/setup/setup-env.sh; then `source scripts/setup/env.sh` in the client's shell).
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$REPO"
if [ "${ROD_IG_SETUP_CLIENT:-0}" = 1 ]; then
    bash "$REPO/scripts/setup/setup-env.sh"
fi
bash "$REPO/scripts/setup/patch-deps.sh"
cargo build --release --manifest-path "$REPO/ros/rod_ig/Cargo.toml" --bins >&2
BIN="${CARGO_TARGET_DIR:-$REPO/target}/release/rod_ig_node"
export ROS_DISTRO="${ROS_DISTRO:-kilted}"
export RUST_LOG="${RUST_LOG:-info,rustdds=error,rustdds::network::udp_listener=off,ros2_client=warn}"
exec "$BIN" "$@"
