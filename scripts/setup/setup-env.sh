#!/usr/bin/env bash
# Sets up what rod_ig_node's tests and Python clients need, without a system ROS install:
#   1. a Python venv with ROS 2 Kilted from PyPI wheels (rclpy on Fast DDS, message packages,
#      the cmake/rosidl tool chain);
#   2. the interface package rod_ig_msgs (msg/), built with cmake alone and installed to
#      build/rod_ig_msgs/install.
# Idempotent: each step is skipped when its inputs did not change (stamp files).
#
# Environment (all optional):
#   ROD_IG_VENV    venv directory            (default: <repo>/.venv)
#   ROD_IG_BUILD   build directory            (default: <repo>/build)
#   PYTHON         interpreter for the venv   (default: python3; CPython 3.11 needed by the wheels)
# Afterwards: `source scripts/setup/env.sh` puts rclpy and rod_ig_msgs on the paths.
set -euo pipefail

REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
VENV="${ROD_IG_VENV:-$REPO/.venv}"
BUILD="${ROD_IG_BUILD:-$REPO/build}"
PYTHON="${PYTHON:-python3}"

log() { printf '[setup-env] %s\n' "$*" >&2; }

# --- 0. Python headers (rosidl's Python type support compiles against Python.h) -------------
py_include="$("$PYTHON" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')"
if [ ! -f "$py_include/Python.h" ]; then
    if command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
        log "Python.h missing in $py_include: installing python3-dev and python3-venv"
        apt-get update -qq
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-dev python3-venv >/dev/null
    else
        log "ERROR: Python.h not found in $py_include; install your Python's development headers"
        exit 1
    fi
fi

# --- 1. venv with the ROS 2 wheels ---------------------------------------------------------
PACKAGES=(
    ros-kilted-rclpy ros-kilted-rmw-fastrtps-cpp
    ros-kilted-std-msgs ros-kilted-geometry-msgs ros-kilted-nav-msgs ros-kilted-std-srvs
    ros-kilted-rcl-interfaces ros-kilted-visualization-msgs ros-kilted-diagnostic-msgs ros-kilted-rosgraph-msgs
    ros-kilted-ament-cmake ros-kilted-rosidl-default-generators ros-kilted-ament-package
    ros-kilted-ament-cmake-include-directories ros-kilted-rosidl-core-generators
    ros-kilted-ament-cmake-ros-core catkin_pkg cmake pytest
)
want_stamp="$(printf '%s\n' "${PACKAGES[@]}" "$("$PYTHON" --version 2>&1)")"
stamp="$VENV/.rod-ig-packages"
if [ ! -x "$VENV/bin/python3" ] || [ "$(cat "$stamp" 2>/dev/null)" != "$want_stamp" ]; then
    log "creating venv $VENV and installing ROS 2 wheels (about a minute)"
    [ -x "$VENV/bin/python3" ] || "$PYTHON" -m venv "$VENV"
    "$VENV/bin/python3" -m pip install --quiet --disable-pip-version-check "${PACKAGES[@]}"
    printf '%s' "$want_stamp" > "$stamp"
else
    log "venv $VENV up to date"
fi

# The venv holds the wheels' share/*/package.xml: a colcon workspace must not take them for
# its own packages.
touch "$VENV/COLCON_IGNORE"

# --- 1b. a Jazzy client venv: the node serves Jazzy clients too (tests/test_distros.py) ------
JAZZY_VENV="${ROD_IG_JAZZY_VENV:-$REPO/build/jazzy-venv}"
JAZZY_PACKAGES=(ros-jazzy-rclpy ros-jazzy-rmw-fastrtps-cpp ros-jazzy-geometry-msgs ros-jazzy-nav-msgs)
jazzy_want="$(printf '%s\n' "${JAZZY_PACKAGES[@]}" "$("$PYTHON" --version 2>&1)")"
if [ ! -x "$JAZZY_VENV/bin/python3" ] || [ "$(cat "$JAZZY_VENV/.rod-ig-packages" 2>/dev/null)" != "$jazzy_want" ]; then
    log "creating the Jazzy client venv $JAZZY_VENV"
    [ -x "$JAZZY_VENV/bin/python3" ] || "$PYTHON" -m venv "$JAZZY_VENV"
    "$JAZZY_VENV/bin/python3" -m pip install --quiet --disable-pip-version-check "${JAZZY_PACKAGES[@]}"
    printf '%s' "$jazzy_want" > "$JAZZY_VENV/.rod-ig-packages"
fi
touch "$JAZZY_VENV/COLCON_IGNORE"

# The wheels' exported CMake files hard-code the wheel builder's Python and numpy include
# paths: point them at this venv's own.
venv_py_include="$("$VENV/bin/python3" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')"
venv_np_include="$("$VENV/bin/python3" -c 'import numpy; print(numpy.get_include())')"
{ grep -rlZ --include='*.cmake' '/opt/python/cp311-cp311' "$VENV/share" 2>/dev/null || true; } \
    | xargs -0 -r sed -i \
        -e "s#/opt/python/cp311-cp311/lib/python3.11/site-packages/numpy/_core/include#$venv_np_include#g" \
        -e "s#/opt/python/cp311-cp311/include/python3.11#$venv_py_include#g"

# --- 2. the interface packages: rod_ig_msgs (msg/), and tf2_msgs' TFMessage for the test clients
# build_interfaces NAME SRC: builds the package in SRC with cmake into $BUILD/NAME/install,
# unless it is there and its sources (and the venv) are unchanged.
build_interfaces() {
    local name=$1 src=$2
    local build="$BUILD/$name/build" prefix="$BUILD/$name/install"
    local hash
    hash="$(cat "$src/package.xml" "$src/CMakeLists.txt" "$src"/msg/*.msg \
        $(ls "$src"/srv/*.srv 2>/dev/null) "$stamp" | sha256sum | cut -d' ' -f1)"
    if [ "$(cat "$prefix/.rod-ig-msgs-hash" 2>/dev/null)" = "$hash" ] \
        && [ -d "$prefix/lib/python3.11/site-packages/$name" ]; then
        log "$name up to date in $prefix"
        return
    fi
    log "building $name into $prefix"
    rm -rf "$build" "$prefix"
    mkdir -p "$build"
    (
        export AMENT_PREFIX_PATH="$VENV"
        export PATH="$VENV/bin:$PATH"
        export LD_LIBRARY_PATH="$VENV/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
        "$VENV/bin/cmake" -S "$src" -B "$build" \
            -DCMAKE_PREFIX_PATH="$VENV" -DCMAKE_INSTALL_PREFIX="$prefix" \
            -DPython3_EXECUTABLE="$VENV/bin/python3" -DBUILD_TESTING=OFF \
            -DCMAKE_BUILD_TYPE=Release >"$BUILD/$name/cmake.log" 2>&1 \
        && "$VENV/bin/cmake" --build "$build" -j 2 >>"$BUILD/$name/cmake.log" 2>&1 \
        && "$VENV/bin/cmake" --install "$build" >>"$BUILD/$name/cmake.log" 2>&1
    ) || { log "ERROR: building $name failed; last lines of $BUILD/$name/cmake.log:";
           tail -n 30 "$BUILD/$name/cmake.log" >&2; exit 1; }
    printf '%s' "$hash" > "$prefix/.rod-ig-msgs-hash"
}
build_interfaces rod_ig_msgs "$REPO/msg"
build_interfaces tf2_msgs "$REPO/tests/interfaces/tf2_msgs"
log "done; use: source $REPO/scripts/env.sh"
