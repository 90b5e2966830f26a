"""The /rod/solve service (rod_ig_msgs/srv/SolveRod)."""
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

import rodig_harness as h

POS_TOL = 1e-5
ANG_TOL = 1e-5
# A short path keeps the many-call tests fast (full-size replies: test_service_full_path).
SMALL = 8
LOOPBACK_PROFILE = h.REPO / "ros" / "rod_ig" / "config" / "fastdds_loopback_client.xml"


def check_response(r, target, samples):
    assert r is not None, "no response from /rod/solve"
    sol = r.solution
    assert sol.success, sol.message
    assert sol.position_error < POS_TOL and sol.orientation_error < ANG_TOL
    assert sol.header.stamp == target.header.stamp
    assert len(r.path.poses) == samples
    last = r.path.poses[-1].pose
    assert abs(last.position.x - target.pose.position.x) < POS_TOL
    assert abs(last.position.y - target.pose.position.y) < POS_TOL
    assert h.angle_diff(h.quaternion_yaw(last.orientation), h.quaternion_yaw(target.pose.orientation)) < ANG_TOL
    first = r.path.poses[0].pose
    assert abs(first.position.x) < 1e-12 and abs(first.position.y) < 1e-12


def test_service_solves(node_and_client):
    _, c = node_and_client
    for x, y, yaw in [(0.6, 0.3, 0.5), (0.5, 0.4, 1.1), (0.7, -0.2, -0.4)]:
        t = c.make_target(x, y, yaw, h.next_seq())
        check_response(c.solve(t, path_samples=SMALL), t, SMALL)


def test_service_answers_many_calls(node_and_client):
    _, c = node_and_client
    for i in range(50):
        u = i / 49
        t = c.make_target(0.7 - 0.2 * u, 0.1 + 0.3 * u, 0.3 + u, h.next_seq())
        check_response(c.solve(t, path_samples=SMALL), t, SMALL)


def test_service_one_off_options(node_and_client):
    _, c = node_and_client
    t = c.make_target(0.6, 0.3, 0.5, h.next_seq())
    warm = c.solve(t, path_samples=SMALL)
    check_response(warm, t, SMALL)
    # The paper's Newton from the solution found: converges at once.
    r = c.solve(t, path_samples=SMALL, method="newton", use_initial_guess=True,
                initial_guess=list(warm.solution.a), tolerance=1e-9, max_iterations=30)
    check_response(r, t, SMALL)
    assert r.solution.iterations <= 2
    assert max(abs(a - b) for a, b in zip(r.solution.a, warm.solution.a)) < 1e-5
    # Robust from its own start.
    check_response(c.solve(t, path_samples=SMALL, method="robust"), t, SMALL)


@pytest.mark.parametrize("fields,expected", [
    (dict(method="magic"), "unknown method"),
    (dict(tolerance=-1.0), "tolerance"),
    (dict(path_samples=1), "path_samples"),
    (dict(use_initial_guess=True, initial_guess=[float("nan"), 0.0, 0.0]), "initial_guess"),
], ids=["method", "tolerance", "path_samples", "initial_guess"])
def test_service_bad_request(node_and_client, fields, expected):
    _, c = node_and_client
    t = c.make_target(0.6, 0.3, 0.5, h.next_seq())
    r = c.solve(t, **fields)
    assert r is not None
    assert not r.solution.success and expected in r.solution.message, r.solution.message
    assert len(r.path.poses) == 0


@pytest.mark.parametrize("kw,expected", [
    (dict(x=2.0, y=0.0, yaw=0.0), "out of reach"),
    (dict(x=float("nan"), y=0.0, yaw=0.0), "non-finite"),
    (dict(x=0.5, y=0.0, yaw=0.0, z=0.3), "not planar"),
], ids=["far", "nan", "z"])
def test_service_bad_target(node_and_client, kw, expected):
    node, c = node_and_client
    t = c.make_target(seq=h.next_seq(), **kw)
    r = c.solve(t)
    assert r is not None
    assert not r.solution.success and expected in r.solution.message
    assert len(r.path.poses) == 0 and r.path.header.frame_id == "base_gripper"
    assert math.isnan(r.solution.position_error)
    assert node.alive()


@pytest.mark.parametrize("samples", [None, 1000, 10000], ids=["default", "1000", "10000"])
def test_service_full_path(node_and_client, samples):
    """A stock rclpy client (rmw_fastrtps_cpp, default profile) gets replies of every size:
    the default 100 poses (~9 kB), 1,000 and 10,000 poses (~0.9 MB, thousands of DATA_FRAG
    submessages). Before patches/rustdds-0.15.1-datafrag-inline-qos.patch every fragmented
    reply was malformed on the wire and the call hung."""
    _, c = node_and_client
    t = c.make_target(0.6, 0.3, 0.5, h.next_seq())
    kw = {} if samples is None else dict(path_samples=samples)
    check_response(c.solve(t, timeout=30.0, **kw), t, samples or 100)


def test_service_full_path_loopback_client():
    """A Fast DDS client that advertises only its loopback locator
    (ros/rod_ig/config/fastdds_loopback_client.xml, the workaround before the DATA_FRAG patch) gets
    the full-size response (100 poses, ~9 kB) too, as one unfragmented DATA. Runs the client in its own process, since
    Fast DDS reads the profile file once per process."""
    domain = h.free_domain()
    node = h.NodeProcess(domain)
    try:
        x, y, yaw, seq = 0.6, 0.3, 0.5, h.next_seq()
        env = dict(os.environ, FASTDDS_DEFAULT_PROFILES_FILE=str(LOOPBACK_PROFILE))
        out = subprocess.run([sys.executable, str(Path(__file__).resolve().parent / "solve_full_path_client.py"),
                              str(domain), str(x), str(y), str(yaw), str(seq)],
                             env=env, capture_output=True, text=True, timeout=60)
        assert out.returncode == 0, f"{out.stdout}\n{out.stderr[-3000:]}\nnode log:\n{node.log_text()[-2000:]}"
        r = json.loads(out.stdout.strip().splitlines()[-1])
    finally:
        code = node.stop()
    assert code == 0
    assert r["success"], r["message"]
    assert r["position_error"] < POS_TOL and r["orientation_error"] < ANG_TOL
    assert r["stamp"] == r["target_stamp"]
    poses = r["poses"]
    assert len(poses) == 100
    assert abs(poses[0][0]) < 1e-12 and abs(poses[0][1]) < 1e-12
    assert abs(poses[-1][0] - x) < POS_TOL and abs(poses[-1][1] - y) < POS_TOL
    assert h.angle_diff(poses[-1][2], yaw) < ANG_TOL


def test_a_query_leaves_the_held_rod_alone():
    """/rod/solve is a query unless move_rod: the rod the target stream holds is untouched
    (issue 43, item 3). The buckled rod at (0.8, 0, 0) snaps when its gripper turns to 1.5 rad;
    a query for that pose must not make the next stream target start from the snapped rod."""
    node, c = h.start_node_and_client()
    try:
        def stream(x, y, yaw):
            s = h.next_seq()
            c.pub.publish(c.make_target(x, y, yaw, s))
            sol = c.solution_for(s)
            assert sol.success, sol.message
            return sol
        held = stream(0.8, 0.0, 0.0)
        # Queries, one of which the held rod could only reach by snapping.
        for yaw in (1.5, -1.5, 0.7):
            r = c.solve(c.make_target(0.8, 0.0, yaw, h.next_seq()), path_samples=SMALL)
            assert r.solution.success, r.solution.message
        again = stream(0.8, 0.0, 0.0)
        assert again.event == "none"
        assert max(abs(p - q) for p, q in zip(again.a, held.a)) < 1e-6, (held.a, again.a)
        # With move_rod the call is a move: the stream goes on from the moved rod.
        moved = c.solve(c.make_target(0.8, 0.0, 0.3, h.next_seq()), path_samples=SMALL,
                        move_rod=True).solution
        assert moved.success and moved.event in ("none", "snap")
        after = stream(0.8, 0.0, 0.3)
        assert max(abs(p - q) for p, q in zip(after.a, moved.a)) < 1e-6
    finally:
        h.stop_node_and_client(node, c)
