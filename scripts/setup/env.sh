# Source me (bash): puts the venv's rclpy and the built rod_ig_msgs on the paths.
# Needs scripts/setup/setup-env.sh to have run. Honours ROD_IG_VENV and ROD_IG_BUILD like it.
_rod_ig_repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
_rod_ig_venv="${ROD_IG_VENV:-$_rod_ig_repo/.venv}"
_rod_ig_prefix="${ROD_IG_BUILD:-$_rod_ig_repo/build}/rod_ig_msgs/install"
# tf2_msgs' TFMessage, built for the test clients (tests/interfaces/tf2_msgs).
_rod_ig_tf="${ROD_IG_BUILD:-$_rod_ig_repo/build}/tf2_msgs/install"
export VIRTUAL_ENV="$_rod_ig_venv"
export PATH="$_rod_ig_venv/bin:$PATH"
export PYTHONPATH="$_rod_ig_prefix/lib/python3.11/site-packages:$_rod_ig_tf/lib/python3.11/site-packages${PYTHONPATH:+:$PYTHONPATH}"
export LD_LIBRARY_PATH="$_rod_ig_prefix/lib:$_rod_ig_tf/lib:$_rod_ig_venv/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export AMENT_PREFIX_PATH="$_rod_ig_prefix:$_rod_ig_tf:$_rod_ig_venv${AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}"
export RMW_IMPLEMENTATION="${RMW_IMPLEMENTATION:-rmw_fastrtps_cpp}"
unset _rod_ig_repo _rod_ig_venv _rod_ig_prefix _rod_ig_tf
