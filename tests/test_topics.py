"""rod_ig_node over topics: /rod/target in; /rod/path, /rod/solution, /rod/marker, /rosout out."""
import math
import time

import pytest

import rodig_harness as h

POS_TOL = 1e-5  # m (solver tolerance 1e-6 on the unit rod, rod_length 1 m)
ANG_TOL = 1e-5  # rad

TARGETS = [  # (x, y, yaw) reachable, stable rods of the unit rod
    (0.6, 0.3, 0.5),
    (0.55, 0.35, 0.8),
    (0.5, 0.4, 1.1),
    (0.7, -0.2, -0.4),
    (0.3, 0.5, 1.8),
    (0.8, 0.0, 0.0),
]


def check_path(path, target, samples, frame):
    assert path is not None, "no /rod/path for the target"
    assert len(path.poses) == samples
    assert path.header.frame_id == frame
    first = path.poses[0].pose
    assert abs(first.position.x) < 1e-12 and abs(first.position.y) < 1e-12 and first.position.z == 0.0
    assert abs(h.quaternion_yaw(first.orientation)) < 1e-12
    last = path.poses[-1].pose
    tp = target.pose
    assert math.hypot(last.position.x - tp.position.x, last.position.y - tp.position.y) < POS_TOL
    assert h.angle_diff(h.quaternion_yaw(last.orientation), h.quaternion_yaw(tp.orientation)) < ANG_TOL
    # Consecutive samples 1/(samples-1) of the rod length apart at most (arc ≥ chord).
    step = 1.0 / (samples - 1)
    for a, b in zip(path.poses, path.poses[1:]):
        d = math.hypot(b.pose.position.x - a.pose.position.x, b.pose.position.y - a.pose.position.y)
        assert d <= step + 1e-9
    for p in path.poses:
        assert p.header.frame_id == frame and p.header.stamp == path.header.stamp


def test_path_reaches_each_target(node_and_client):
    _, c = node_and_client
    for x, y, yaw in TARGETS:
        s = h.next_seq()
        t = c.make_target(x, y, yaw, s)
        c.pub.publish(t)
        sol = c.solution_for(s)
        assert sol is not None, f"no /rod/solution for {(x, y, yaw)}"
        assert sol.success, sol.message
        check_path(c.path_for(s), t, 100, "base_gripper")


def test_warm_started_sweep(node_and_client):
    """A smooth sweep of targets, sent one after the other (each answered before the next)."""
    _, c = node_and_client
    for i in range(40):
        u = i / 39
        x, y, yaw = 0.75 - 0.3 * u, 0.1 + 0.35 * u, 0.2 + 1.2 * u
        s = h.next_seq()
        t = c.make_target(x, y, yaw, s)
        c.pub.publish(t)
        sol = c.solution_for(s)
        assert sol is not None and sol.success, (i, sol and sol.message)
        assert sol.iterations <= 10, "warm start should need few iterations"
        check_path(c.path_for(s), t, 100, "base_gripper")


def test_solution_fields(node_and_client):
    _, c = node_and_client
    s = h.next_seq()
    t = c.make_target(0.6, 0.3, 0.5, s)
    c.pub.publish(t)
    sol = c.solution_for(s)
    assert sol is not None and sol.success
    assert sol.header.frame_id == "base_gripper"
    assert (sol.header.stamp.sec, sol.header.stamp.nanosec) == (t.header.stamp.sec, t.header.stamp.nanosec)
    assert len(sol.a) == 3 and all(math.isfinite(v) for v in sol.a)
    assert sol.stable and sol.stability_margin > 0
    assert sol.position_error < POS_TOL and sol.orientation_error < ANG_TOL
    assert sol.residual < 1e-5
    assert sol.elastic_energy > 0
    assert math.isnan(sol.elastic_energy_joules) and not sol.wrench_valid  # no bending_stiffness
    assert sol.rod_length == 1.0
    assert 0 < sol.solve_time < 1.0
    assert abs(sol.tip.position.x - 0.6) < POS_TOL and abs(sol.tip.position.y - 0.3) < POS_TOL
    assert sol.message


def test_empty_frame_uses_base_frame(node_and_client):
    _, c = node_and_client
    s = h.next_seq()
    c.pub.publish(c.make_target(0.6, 0.3, 0.5, s, frame=""))
    sol = c.solution_for(s)
    assert sol is not None and sol.header.frame_id == "rod_base"
    assert c.path_for(s).header.frame_id == "rod_base"


def test_marker_line_strip(node_and_client):
    _, c = node_and_client
    s = h.next_seq()
    t = c.make_target(0.5, 0.4, 1.1, s)
    c.pub.publish(t)
    m = c.marker_for(s)
    assert m is not None
    assert m.type == m.LINE_STRIP and m.action == m.ADD
    assert len(m.points) == 100 and m.scale.x > 0 and m.color.a > 0
    assert m.header.frame_id == "base_gripper"
    assert abs(m.points[-1].x - 0.5) < POS_TOL and abs(m.points[-1].y - 0.4) < POS_TOL


BAD = [
    ("nan position", dict(x=float("nan"), y=0.1, yaw=0.0), "non-finite"),
    ("inf orientation", dict(x=0.5, y=0.1, yaw=0.0, q=(0.0, 0.0, float("inf"), 1.0)), "non-finite"),
    ("zero quaternion", dict(x=0.5, y=0.1, yaw=0.0, q=(0.0, 0.0, 0.0, 0.0)), "not a rotation"),
    ("out of reach", dict(x=0.9, y=0.9, yaw=0.0), "out of reach"),
    ("exactly at length", dict(x=1.0, y=0.0, yaw=0.0), "out of reach"),
    ("z off plane", dict(x=0.5, y=0.1, yaw=0.0, z=0.05), "not planar"),
    ("tilted", dict(x=0.5, y=0.1, yaw=0.0, q=(math.sin(0.1), 0.0, 0.0, math.cos(0.1))), "not about z"),
]


@pytest.mark.parametrize("name,kw,expected", BAD, ids=[b[0] for b in BAD])
def test_bad_target_answered_node_alive(node_and_client, name, kw, expected):
    node, c = node_and_client
    s = h.next_seq()
    c.pub.publish(c.make_target(seq=s, **kw))
    sol = c.solution_for(s)
    assert sol is not None, f"{name}: no answer"
    assert not sol.success
    assert expected in sol.message, sol.message
    # No path for a failed target (documented choice).
    time.sleep(0.1)
    assert c.path_for(s, timeout=0.2) is None
    # Still serving.
    assert node.alive()
    s2 = h.next_seq()
    t = c.make_target(0.6, 0.3, 0.5, s2)
    c.pub.publish(t)
    good = c.solution_for(s2)
    assert good is not None and good.success
    check_path(c.path_for(s2), t, 100, "base_gripper")


def test_rosout_reports_rejections(node_and_client):
    _, c = node_and_client
    s = h.next_seq()
    c.pub.publish(c.make_target(5.0, 0.0, 0.0, s))
    assert c.solution_for(s) is not None
    log = c.wait_for(lambda: next((m for m in c.logs if m.name.endswith("rod_ig_node")
                                   and "out of reach" in m.msg), None), timeout=5)
    assert log is not None, [m.msg for m in c.logs][-5:]
    assert log.level == 30  # WARN


def test_first_target_respects_max_iterations():
    """Issue 10: the first target (the tracker's cold start, which compares the stable solutions
    near the target) used to report 551-771 iterations, above max_iterations (100): its search
    now stops once max_iterations are spent and a solution is known."""
    domain = h.free_domain()
    node = h.NodeProcess(domain, [])
    c = h.Client(domain)
    try:
        assert c.wait_connected(), node.log_text()
        s = h.next_seq()
        c.pub.publish(c.make_target(0.5, 0.2, 1.0, s))
        sol = c.solution_for(s, timeout=20)
        assert sol is not None and sol.success, sol and sol.message
        assert sol.iterations <= 100, sol.iterations
    finally:
        c.close()
        assert node.stop() == 0


def test_rosout_as_rclcpp_writes_it():
    """Issue 20: the logger is `<namespace>.<node>` with dots, `--log-level debug` reaches
    /rosout too, messages name the remapped topics, and file, function and line are filled."""
    domain = h.free_domain()
    node = h.NodeProcess(domain, ["--ros-args", "-r", "__ns:=/left", "-r", "rod/target:=/arm/goal",
                                  "--log-level", "debug"])
    c = h.Client(domain, ns="/left", node_fqn="/left/rod_ig_node", target_topic="/arm/goal")
    try:
        assert c.wait_connected(), node.log_text()
        far, near = h.next_seq(), h.next_seq()
        c.pub.publish(c.make_target(5.0, 0.0, 0.0, far))
        assert c.solution_for(far) is not None
        c.pub.publish(c.make_target(0.5, 0.2, 1.0, near))
        assert c.solution_for(near) is not None
        warn = c.wait_for(lambda: next((m for m in c.logs if m.level == 30 and "out of reach" in m.msg),
                                       None), timeout=5)
        assert warn is not None, [m.msg for m in c.logs][-5:]
        assert warn.name == "left.rod_ig_node", warn.name
        assert "/arm/goal" in warn.msg, warn.msg
        assert warn.function not in ("", "<unknown_func>") and warn.line > 0, (warn.function, warn.line)
        assert warn.file.endswith(".rs"), warn.file
        debug = c.wait_for(lambda: next((m for m in c.logs if m.level == 10
                                         and m.name == "left.rod_ig_node"), None), timeout=5)
        assert debug is not None, "DEBUG records reach /rosout with --log-level debug"
        mine = [m.msg for m in c.logs if m.name == "left.rod_ig_node"]
        assert not any("/rod/target" in m for m in mine), mine
    finally:
        c.close()
        assert node.stop() == 0


def test_stdout_logs_can_be_disabled():
    """Issue 20: `--disable-stdout-logs` silences the console; /rosout still has the records."""
    domain = h.free_domain()
    node = h.NodeProcess(domain, ["--ros-args", "--disable-stdout-logs"])
    c = h.Client(domain)
    try:
        assert c.wait_connected(timeout=30)
        ready = c.wait_for(lambda: next((m for m in c.logs if "ready" in m.msg), None), timeout=10)
        # The ready line may predate the client's subscription; a later record proves /rosout.
        s = h.next_seq()
        c.pub.publish(c.make_target(5.0, 0.0, 0.0, s))
        assert c.solution_for(s) is not None
        warn = c.wait_for(lambda: next((m for m in c.logs if "out of reach" in m.msg), None), timeout=5)
        assert warn is not None or ready is not None
        assert "ready" not in node.log_text() and "out of reach" not in node.log_text(), node.log_text()
    finally:
        c.close()
        assert node.stop() == 0
