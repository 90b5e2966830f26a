"""Issue 10, point 7: the repository is a colcon workspace's source. `scripts/colcon-build.sh`
runs `colcon build` (colcon-ros-cargo + cargo-ament-build for the node, ament_cmake for
rod_ig_msgs); the node is then where `ros2 run rod_ig rod_ig_node` looks (the ament index's
prefix of rod_ig, lib/rod_ig/), and it serves the README's example client, which imports the
colcon-built rod_ig_msgs."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

import rodig_harness as h

REPO = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def workspace(tmp_path_factory):
    ws = tmp_path_factory.mktemp("colcon-ws")
    build = subprocess.run(["bash", str(REPO / "scripts" / "colcon-build.sh"), str(ws)],
                           capture_output=True, text=True, timeout=1800)
    assert build.returncode == 0, build.stdout[-3000:] + build.stderr[-3000:]
    # The environment `. install/setup.sh` gives, as a ROS user's shell has it.
    env_dump = subprocess.run(["bash", "-c", f". '{ws}/install/setup.sh' && env -0"],
                              capture_output=True, check=True)
    env = dict(kv.split("=", 1) for kv in env_dump.stdout.decode().split("\0") if "=" in kv)
    return ws, env


def test_ros2_run_finds_the_node(workspace):
    ws, env = workspace
    lookup = subprocess.run(
        [sys.executable, "-c",
         "from ament_index_python.packages import get_package_prefix as p; import os;"
         "exe = os.path.join(p('rod_ig'), 'lib', 'rod_ig', 'rod_ig_node'); print(exe);"
         "assert os.access(exe, os.X_OK), exe;"
         "import rod_ig_msgs; print(rod_ig_msgs.__file__)"],
        env=env, capture_output=True, text=True, timeout=60)
    assert lookup.returncode == 0, lookup.stdout + lookup.stderr
    exe, msgs = lookup.stdout.split()
    assert exe == str(ws / "install" / "rod_ig" / "lib" / "rod_ig" / "rod_ig_node")
    assert msgs.startswith(str(ws / "install" / "rod_ig_msgs")), msgs


def test_installed_node_serves_the_example_client(workspace):
    ws, env = workspace
    domain = h.free_domain()
    exe = ws / "install" / "rod_ig" / "lib" / "rod_ig" / "rod_ig_node"
    os.environ["ROD_IG_RUN_BIN"] = str(exe)
    node = h.NodeProcess(domain, binary_name="rod_ig_run")
    try:
        assert node.wait_log("ready", 30), node.log_text()[-2000:]
        run = subprocess.run(
            [sys.executable, str(REPO / "examples" / "send_target.py"), "0.5", "0.2", "1.0"],
            env=dict(env, ROS_DOMAIN_ID=str(domain), ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST"),
            capture_output=True, text=True, timeout=60)
        assert run.returncode == 0 and "solved:" in run.stdout, run.stdout + run.stderr
    finally:
        assert node.stop() == 0
