"""Parameters: run-time changes through /rod_ig_node/set_parameters (rcl_interfaces), start-up
flags and YAML files, bad command lines, clean shutdown on SIGINT."""
import math
import signal
import subprocess

import rodig_harness as h

POS_TOL = 1e-5


def solve_topic(c, x, y, yaw, frame="base_gripper"):
    s = h.next_seq()
    t = c.make_target(x, y, yaw, s, frame=frame)
    c.pub.publish(t)
    return t, c.solution_for(s), (c.path_for(s, timeout=2.0))


def test_get_defaults(node_and_client):
    _, c = node_and_client
    got = c.get_params("rod_length", "path_samples", "base_frame", "method", "tolerance",
                       "max_iterations", "bending_stiffness")
    assert got == {"rod_length": 1.0, "path_samples": 100, "base_frame": "rod_base", "method": "robust",
                   "tolerance": 1e-6, "max_iterations": 100, "bending_stiffness": 0.0}


def test_rod_length_and_samples_take_effect(node_and_client):
    _, c = node_and_client
    res = c.set_params(rod_length=2.0, path_samples=37)
    assert all(r.successful for r in res), [r.reason for r in res]
    assert c.get_params("rod_length", "path_samples") == {"rod_length": 2.0, "path_samples": 37}
    # (1.2, 0.6) is out of reach of a 1 m rod, fine for 2 m; same shape as (0.6, 0.3) on 1 m.
    t, sol, path = solve_topic(c, 1.2, 0.6, 0.5)
    assert sol.success, sol.message
    assert sol.rod_length == 2.0
    assert len(path.poses) == 37
    last = path.poses[-1].pose.position
    assert math.hypot(last.x - 1.2, last.y - 0.6) < 2 * POS_TOL
    res = c.set_params(rod_length=1.0, path_samples=100)
    assert all(r.successful for r in res)
    _, sol, path = solve_topic(c, 1.2, 0.6, 0.5)
    assert not sol.success and "out of reach" in sol.message


def test_bad_values_rejected_with_reason(node_and_client):
    _, c = node_and_client
    cases = [
        (dict(rod_length=-1.0), "rod_length"),
        (dict(rod_length=float("nan")), "rod_length"),
        (dict(path_samples=1), "path_samples"),
        (dict(tolerance=0.0), "tolerance"),
        (dict(max_iterations=0), "max_iterations"),
        (dict(method="magic"), "method"),
        (dict(bending_stiffness=-3.0), "bending_stiffness"),
        (dict(rod_length="long"), "rod_length"),   # wrong type
        (dict(no_such_parameter=1.0), "no_such_parameter"),
    ]
    for values, name in cases:
        (res,) = c.set_params(**values)
        assert not res.successful, values
        assert name in res.reason and res.reason, res.reason
    assert c.get_params("rod_length", "path_samples", "method") == {
        "rod_length": 1.0, "path_samples": 100, "method": "robust"}
    _, sol, path = solve_topic(c, 0.6, 0.3, 0.5)
    assert sol.success and len(path.poses) == 100


def test_base_frame_and_marker_switch(node_and_client):
    _, c = node_and_client
    assert all(r.successful for r in c.set_params(base_frame="world", publish_marker=False))
    s = h.next_seq()
    c.pub.publish(c.make_target(0.6, 0.3, 0.5, s, frame=""))
    assert c.solution_for(s).header.frame_id == "world"
    assert c.marker_for(s, timeout=0.5) is None
    assert all(r.successful for r in c.set_params(base_frame="rod_base", publish_marker=True))


def test_bending_stiffness_gives_physical_wrench(node_and_client):
    _, c = node_and_client
    assert all(r.successful for r in c.set_params(bending_stiffness=2.0, rod_length=0.5))
    _, sol, _ = solve_topic(c, 0.3, 0.15, 0.5)
    assert sol.success and sol.wrench_valid
    ei, length = 2.0, 0.5
    a3, a4, a5 = sol.a
    assert math.isclose(sol.base_wrench.force.x, a4 * ei / length**2, rel_tol=1e-12)
    assert math.isclose(sol.base_wrench.force.y, a5 * ei / length**2, rel_tol=1e-12)
    assert math.isclose(sol.base_wrench.torque.z, a3 * ei / length, rel_tol=1e-12)
    assert math.isclose(sol.elastic_energy_joules, sol.elastic_energy * ei / length, rel_tol=1e-12)
    # Same normalised shape as (0.6, 0.3, 0.5) on the unit rod: same a.
    assert all(r.successful for r in c.set_params(bending_stiffness=0.0, rod_length=1.0))
    _, sol1, _ = solve_topic(c, 0.6, 0.3, 0.5)
    assert max(abs(p - q) for p, q in zip(sol.a, sol1.a)) < 1e-4
    assert not sol1.wrench_valid and math.isnan(sol1.elastic_energy_joules)


def test_solver_method_switch(node_and_client):
    _, c = node_and_client
    assert all(r.successful for r in c.set_params(method="newton", tolerance=1e-9, max_iterations=50))
    for x, y, yaw in [(0.6, 0.3, 0.5), (0.62, 0.31, 0.55)]:
        _, sol, path = solve_topic(c, x, y, yaw)
        assert sol.success, sol.message
        assert sol.position_error < 1e-8
    assert all(r.successful for r in c.set_params(method="robust", tolerance=1e-6, max_iterations=100))


def test_startup_flags_and_params_file(tmp_path):
    yaml = tmp_path / "p.yaml"
    yaml.write_text("rod_ig_node:\n  ros__parameters:\n    rod_length: 3.0\n    path_samples: 12\n"
                    "    base_frame: from_file\n")
    domain = h.free_domain()
    node = h.NodeProcess(domain, ["--ros-args", "--params-file", str(yaml), "-p", "rod_length:=2.0"])
    c = h.Client(domain)
    try:
        assert c.wait_connected(), node.log_text()
        assert c.get_params("rod_length", "path_samples", "base_frame") == {
            "rod_length": 2.0, "path_samples": 12, "base_frame": "from_file"}
        _, sol, path = solve_topic(c, 1.2, 0.6, 0.5, frame="")
        assert sol.success and sol.header.frame_id == "from_file"
        assert len(path.poses) == 12
    finally:
        c.close()
        code = node.stop(signal.SIGINT)
    assert code == 0, node.log_path.read_text()
    assert "SIGINT: shutting down" in node.log_path.read_text()


def test_shipped_params_file_starts(tmp_path):
    domain = h.free_domain()
    node = h.NodeProcess(domain, ["--params-file", str(h.REPO / "ros" / "rod_ig" / "config" / "rod_ig_params.yaml")])
    try:
        assert node.wait_log("rod_ig_node ready", timeout=20), node.log_text()
    finally:
        assert node.stop() == 0


def test_bad_command_line_exits_with_reason():
    for args, expected in [(["-p", "rod_length:=-2"], "rod_length"),
                           (["--params-file", "/nonexistent.yaml"], "nonexistent"),
                           (["--bogus"], "unknown argument")]:
        r = subprocess.run([str(h.binary("rod_ig_node")), *args], capture_output=True, text=True, timeout=20)
        assert r.returncode == 2, (args, r.returncode)
        assert expected in r.stderr, r.stderr
    r = subprocess.run([str(h.binary("rod_ig_node")), "--help"], capture_output=True, text=True, timeout=20)
    assert r.returncode == 0 and "rod_length" in r.stdout


def test_bad_domain_id_exits_with_reason():
    import os
    env = dict(os.environ, ROS_DOMAIN_ID="999")
    r = subprocess.run([str(h.binary("rod_ig_node"))], capture_output=True, text=True, timeout=20, env=env)
    assert r.returncode == 2 and "ROS_DOMAIN_ID" in r.stderr


def test_deadline_parameter_bounds_a_solve(node_and_client):
    """Issue 9: every solve has a deadline; the node's `deadline_ms` sets it (default 250 ms),
    within (0, 10000]. A solve that runs out answers success = false with the reason."""
    _, c = node_and_client
    assert c.get_params("deadline_ms") == {"deadline_ms": 250.0}
    for bad in (0.0, 20000.0, -5.0):
        (res,) = c.set_params(deadline_ms=bad)
        assert not res.successful and "deadline_ms" in res.reason
    # 1 µs: the robust solver's start list alone takes longer.
    res = c.set_params(deadline_ms=0.001)
    assert all(r.successful for r in res), [r.reason for r in res]
    _, sol, _ = solve_topic(c, 0.95, 0.05, 0.02)
    assert not sol.success
    assert "deadline" in sol.message, sol.message
    res = c.set_params(deadline_ms=250.0)
    assert all(r.successful for r in res)
    _, sol, _ = solve_topic(c, 0.5, 0.2, 1.0)
    assert sol.success, sol.message


def test_params_file_with_unknown_keys_warns_and_starts(tmp_path):
    """Issue 10: a shared params file (other nodes' keys under /**, use_sim_time) must not stop
    the node; unknown keys are skipped with a warning naming them."""
    yaml = tmp_path / "shared.yaml"
    yaml.write_text("/**:\n  ros__parameters:\n    use_sim_time: false\n    camera_rate: 30.0\n"
                    "rod_ig_node:\n  ros__parameters:\n    path_samples: 9\n")
    domain = h.free_domain()
    node = h.NodeProcess(domain, ["--ros-args", "--params-file", str(yaml)])
    c = h.Client(domain)
    try:
        assert c.wait_connected(), node.log_text()
        assert c.get_params("path_samples") == {"path_samples": 9}
        log = node.log_text()
        assert "ignoring unknown parameter 'camera_rate'" in log, log
        # use_sim_time is a parameter of the node (rclcpp's built-in), so it is not ignored.
        assert "ignoring unknown parameter 'use_sim_time'" not in log, log
        assert c.get_params("use_sim_time") == {"use_sim_time": False}
    finally:
        c.close()
        assert node.stop() == 0


def test_params_file_sections_as_rcl_reads_them(tmp_path):
    """Issue 20: the sections rcl applies: `/**/rod_ig_node` and a nested namespace section
    reach the node in /left; a file with only other nodes' sections, and `-p` of a name the
    node does not have, leave it starting on its defaults (it used to exit with code 2)."""
    nested = tmp_path / "nested.yaml"
    nested.write_text("/**/rod_ig_node:\n  ros__parameters:\n    path_samples: 21\n"
                      "/left:\n  rod_ig_node:\n    ros__parameters:\n      rod_length: 0.8\n"
                      "/right:\n  rod_ig_node:\n    ros__parameters:\n      rod_length: 3.0\n")
    others = tmp_path / "others.yaml"
    others.write_text("camera:\n  ros__parameters:\n    rate: 30\n")
    domain = h.free_domain()
    node = h.NodeProcess(domain, ["--ros-args", "-r", "__ns:=/left", "--params-file", str(nested),
                                  "--params-file", str(others), "-p", "nosuch:=1"])
    c = h.Client(domain, ns="/left", node_fqn="/left/rod_ig_node")
    try:
        assert c.wait_connected(), node.log_text()
        assert c.get_params("path_samples", "rod_length") == {"path_samples": 21, "rod_length": 0.8}
        log = node.log_text()
        assert "-p nosuch: not a parameter of this node, ignored" in log, log
        assert "no section for /left/rod_ig_node" in log, log
    finally:
        c.close()
        assert node.stop() == 0


def test_base_frame_must_be_a_frame_id(node_and_client):
    """Issue 20: '' and 'bad frame!' were accepted and then published as frame ids."""
    _, c = node_and_client
    for bad in ["", "bad frame!", "/world"]:
        results = c.set_params(base_frame=bad)
        assert not results[0].successful, bad
        assert "frame id" in results[0].reason, results[0].reason
    assert c.get_params("base_frame") == {"base_frame": "rod_base"}


def test_base_wrench_is_published_as_wrench_stamped(node_and_client):
    """rod/base_wrench (geometry_msgs/WrenchStamped) carries each solution's base wrench when
    bending_stiffness is set, for plotters and wrench displays (issue 43, item 4)."""
    from geometry_msgs.msg import WrenchStamped
    _, c = node_and_client
    got = []
    sub = c.node.create_subscription(WrenchStamped, "/rod/base_wrench", got.append, h.topic_qos())
    try:
        assert all(r.successful for r in c.set_params(bending_stiffness=2.0, rod_length=0.5))
        t, sol, _ = solve_topic(c, 0.3, 0.15, 0.5)
        assert sol.success and sol.wrench_valid
        assert c.wait_for(lambda: any(w.header.stamp == t.header.stamp for w in got), timeout=5.0)
        w = next(w for w in got if w.header.stamp == t.header.stamp)
        assert w.header.frame_id == sol.header.frame_id
        assert w.wrench.force.x == sol.base_wrench.force.x
        assert w.wrench.force.y == sol.base_wrench.force.y
        assert w.wrench.torque.z == sol.base_wrench.torque.z
        # Without bending_stiffness the wrench is not known in newtons: nothing is published.
        assert all(r.successful for r in c.set_params(bending_stiffness=0.0, rod_length=1.0))
        t, sol, _ = solve_topic(c, 0.6, 0.3, 0.5)
        assert sol.success and not sol.wrench_valid
        assert not c.wait_for(lambda: any(w.header.stamp == t.header.stamp for w in got), timeout=0.5)
    finally:
        c.node.destroy_subscription(sub)


def test_tip_wrench_balances_the_base_wrench(node_and_client):
    """Issue 52, item 2: RodSolution.tip_wrench and rod/tip_wrench (WrenchStamped in the tip
    frame, "rod_tip" without tip_frame) carry what the rod exerts on the tip gripper. Without
    weight it balances the base wrench: rotated into the base frame the forces cancel, and the
    moments about the base sum to zero (the tip at x, y in metres)."""
    from geometry_msgs.msg import WrenchStamped
    _, c = node_and_client
    got = []
    sub = c.node.create_subscription(WrenchStamped, "/rod/tip_wrench", got.append, h.topic_qos())
    try:
        assert all(r.successful for r in c.set_params(bending_stiffness=2.0, rod_length=0.5))
        t, sol, _ = solve_topic(c, 0.3, 0.15, 0.5)
        assert sol.success and sol.wrench_valid
        q = sol.tip.orientation
        theta = 2.0 * math.atan2(q.z, q.w)
        tw, bw = sol.tip_wrench, sol.base_wrench
        fx = math.cos(theta) * tw.force.x - math.sin(theta) * tw.force.y
        fy = math.sin(theta) * tw.force.x + math.cos(theta) * tw.force.y
        assert abs(fx + bw.force.x) < 1e-6 * (1 + abs(bw.force.x)), (fx, bw.force.x)
        assert abs(fy + bw.force.y) < 1e-6 * (1 + abs(bw.force.y)), (fy, bw.force.y)
        x, y = sol.tip.position.x, sol.tip.position.y
        moment = bw.torque.z + tw.torque.z + x * fy - y * fx
        assert abs(moment) < 1e-6 * (1 + abs(bw.torque.z)), moment
        assert c.wait_for(lambda: any(w.header.stamp == t.header.stamp for w in got), timeout=5.0)
        w = next(w for w in got if w.header.stamp == t.header.stamp)
        assert w.header.frame_id == "rod_tip"
        assert w.wrench.torque.z == tw.torque.z and w.wrench.force.x == tw.force.x
    finally:
        assert all(r.successful for r in c.set_params(bending_stiffness=0.0, rod_length=1.0))
        c.node.destroy_subscription(sub)
