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


def test_the_package_installs_its_launch_files_and_parameters(workspace):
    """`ros2 launch rod_ig rod_ig.launch.py` finds its files in share/rod_ig (issue 43, item 7).
    launch_ros has no wheel, so the launch files are checked by parsing them: each starts the
    node as a ROS package's executable, Node(package='rod_ig', executable='rod_ig_node'), and
    they are the repository's only launch files (issue 53, item 5: one source)."""
    import ast

    share = ws_share = workspace[0] / "install" / "rod_ig" / "share" / "rod_ig"
    for f in ("package.xml", "launch/rod_ig.launch.py", "launch/two_arms.launch.py",
              "config/rod_ig_params.yaml"):
        assert (ws_share / f).is_file(), f"{f} not installed in {share}"
    for launch in ("rod_ig.launch.py", "two_arms.launch.py"):
        tree = ast.parse((share / "launch" / launch).read_text())
        nodes = [c for c in ast.walk(tree)
                 if isinstance(c, ast.Call) and getattr(c.func, "id", "") == "Node"]
        assert nodes, f"{launch}: no launch_ros Node"
        started = set()
        for call in nodes:
            kw = {k.arg: k.value for k in call.keywords}
            started.add((ast.literal_eval(kw["package"]), ast.literal_eval(kw["executable"])))
        # The node, and RViz on request (rod_ig.launch.py's rviz:=true): nothing else.
        assert ("rod_ig", "rod_ig_node") in started, launch
        assert started <= {("rod_ig", "rod_ig_node"), ("rviz2", "rviz2")}, (launch, started)
        names = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
        assert "ExecuteProcess" not in names and "generate_launch_description" in {
            f.name for f in tree.body if isinstance(f, ast.FunctionDef)}, launch
    sources = []
    for root, dirs, files in os.walk(h.REPO):
        dirs[:] = [d for d in dirs if d not in {"target", "build", "install", ".git", ".venv"}]
        sources += [str(Path(root, f).relative_to(h.REPO)) for f in files if f.endswith(".launch.py")]
    sources.sort()
    assert sources == ["ros/rod_ig/launch/rod_ig.launch.py",
                       "ros/rod_ig/launch/two_arms.launch.py"], sources


def test_the_installed_parameters_apply_in_a_namespace_without_warnings(workspace):
    """The installed params file serves a namespaced node (as two_arms.launch.py starts it)
    with no WARN line: every key applies (before, its QoS keys named unresolved topics and
    drew three warnings per node)."""
    ws, _ = workspace
    exe = ws / "install" / "rod_ig" / "lib" / "rod_ig" / "rod_ig_node"
    params = ws / "install" / "rod_ig" / "share" / "rod_ig" / "config" / "rod_ig_params.yaml"
    os.environ["ROD_IG_RUN_BIN"] = str(exe)
    node = h.NodeProcess(h.free_domain(), ["--ros-args", "-r", "__ns:=/left",
                                           "--params-file", str(params)],
                         binary_name="rod_ig_run")
    try:
        assert node.wait_log("ready", 30), node.log_text()[-2000:]
        log = node.log_text()
        assert "/left/rod_ig_node" in log, log
        assert " WARN " not in log and "ERROR" not in log, log
    finally:
        assert node.stop() == 0
