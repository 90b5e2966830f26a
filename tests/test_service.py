"""The /rod/solve service (rod_ig_msgs/srv/SolveRod)."""
import math

import pytest

import rodig_harness as h

POS_TOL = 1e-5
ANG_TOL = 1e-5
# Responses must fit one UDP datagram for Fast DDS clients (see launch_notes/README.md, known
# gaps): ask for a short path.
SMALL = 8


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


@pytest.mark.xfail(reason="known gap: responses larger than one UDP datagram (~1.4 kB, more than "
                          "~10 path poses) are fragmented by RustDDS and not delivered to Fast DDS "
                          "service clients", strict=False)
def test_service_full_path(node_and_client):
    _, c = node_and_client
    t = c.make_target(0.6, 0.3, 0.5, h.next_seq())
    check_response(c.solve(t, timeout=3.0), t, 100)
