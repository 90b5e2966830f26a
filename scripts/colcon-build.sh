#!/usr/bin/env bash
# Builds this repository as a colcon workspace, as a ROS user's `colcon build` does: the
# interface package rod_ig_msgs (msg/, ament_cmake), the node package rod_ig (ros/rod_ig,
# ament_cargo via colcon-ros-cargo + cargo-ament-build) and the Rust crates (colcon-cargo).
# `ros2 run rod_ig rod_ig_node` then finds install/rod_ig/lib/rod_ig/rod_ig_node.
#
# On a machine with ROS 2 installed, the same is: clone into <ws>/src, run
# scripts/setup/patch-deps.sh once, `pip install colcon-ros-cargo cargo-ament-build` (or
# `cargo install cargo-ament-build`), then `colcon build` in <ws>. Here, without a system
# ROS, the venv of scripts/setup/setup-env.sh serves as the ROS prefix.
#
# Usage: scripts/colcon-build.sh [WORKSPACE]   (default: build/colcon-ws; the repository is
# linked in as WORKSPACE/src/rod-ig). Takes ~3 min on 2 cores (colcon builds the crates in
# its own target directory).
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
WS="${1:-$REPO/build/colcon-ws}"
VENV="${ROD_IG_VENV:-$REPO/.venv}"

bash "$REPO/scripts/setup/patch-deps.sh"
bash "$REPO/scripts/setup/setup-env.sh"
COLCON_PACKAGES=(colcon-core colcon-ros colcon-cmake colcon-cargo colcon-ros-cargo
                 colcon-recursive-crawl colcon-library-path colcon-package-selection
                 colcon-parallel-executor colcon-output colcon-package-information
                 cargo-ament-build)
if [ ! -x "$VENV/bin/colcon" ] || [ ! -x "$VENV/bin/cargo-ament-build" ]; then
    echo "[colcon-build] installing colcon, colcon-ros-cargo and cargo-ament-build into $VENV" >&2
    "$VENV/bin/python3" -m pip install --quiet --disable-pip-version-check "${COLCON_PACKAGES[@]}"
fi

mkdir -p "$WS/src"
ln -sfn "$REPO" "$WS/src/rod-ig"
cd "$WS"
export AMENT_PREFIX_PATH="$VENV${AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}"
export PATH="$VENV/bin:$PATH"
export LD_LIBRARY_PATH="$VENV/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
colcon build --event-handlers console_direct- \
    --cmake-args -DPython3_EXECUTABLE="$VENV/bin/python3" -DBUILD_TESTING=OFF -DCMAKE_BUILD_TYPE=Release
echo "[colcon-build] done: . $WS/install/setup.sh" >&2
