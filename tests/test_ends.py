"""Pinned and free ends in the node (issue 52, item 1): the parameters base_condition and
tip_condition; RodSolution's appended base_condition, tip_condition and base_angle; a free tip
hangs from its base whatever the target; refusals name the parameter."""
import contextlib
import math

import pytest

import rodig_harness as h

# A 1 m cable of 50 g/m, EI = 0.0981 N m^2: w = 0.05 * 9.81 * 1^3 / 0.0981 = 5.
CABLE = ["-p", "rod_length:=1.0", "-p", "bending_stiffness:=0.0981", "-p", "linear_density:=0.05",
         "-p", "gravity:=[0.0, -9.81, 0.0]", "-p", "follow_branch:=false"]


@pytest.fixture(scope="module")
def cable():
    node, client = h.start_node_and_client(["--ros-args", *CABLE, "-p", "tip_condition:=pinned"])
    yield node, client
    h.stop_node_and_client(node, client)


@contextlib.contextmanager
def params_set(c, **values):
    """Sets node parameters for the body of a `with`, then restores the values they had."""
    before = c.get_params(*values)
    assert all(r.successful for r in c.set_params(**values))
    try:
        yield
    finally:
        assert all(r.successful for r in c.set_params(**before))


def solve_topic(c, x, y, yaw):
    s = h.next_seq()
    c.pub.publish(c.make_target(x, y, yaw, s))
    return c.solution_for(s, timeout=10.0), c.path_for(s, timeout=10.0)


def test_a_pinned_tip_holds_the_position_and_frees_the_angle(cable):
    _, c = cable
    assert c.get_params("base_condition", "tip_condition") == {
        "base_condition": "clamped", "tip_condition": "pinned"}
    # The target's yaw is ignored: two yaws, one rod.
    sol, path = solve_topic(c, 0.6, -0.2, 0.0)
    other, _ = solve_topic(c, 0.6, -0.2, 1.0)
    assert sol.success, sol.message
    assert (sol.base_condition, sol.tip_condition) == ("clamped", "pinned")
    assert sol.stable and sol.base_angle == 0.0
    assert sol.position_error < 1e-9 and math.isnan(sol.orientation_error)
    assert list(other.a) == pytest.approx(list(sol.a), abs=1e-9)
    assert abs(sol.tip_wrench.torque.z) < 1e-9  # no moment at a pin
    last = path.poses[-1].pose.position
    assert math.hypot(last.x - 0.6, last.y + 0.2) < 1e-9


def test_pinned_at_both_ends_the_cable_hangs_between_the_pins(cable):
    _, c = cable
    with params_set(c, base_condition="pinned"):
        sol, path = solve_topic(c, 0.8, 0.0, 0.0)
        assert sol.success, sol.message
        assert sol.a[0] == 0.0 and sol.base_angle < 0.0  # leaves the base pin downwards
        first = path.poses[1].pose.position
        assert first.y < 0.0
        # Symmetric: the tip leaves at minus the base angle (gravity normal to the chord).
        assert sol.tip.orientation.z == pytest.approx(math.sin(-sol.base_angle / 2), abs=1e-8)


def test_a_free_tip_hangs_from_its_base_whatever_the_target(cable):
    _, c = cable
    with params_set(c, tip_condition="free"):
        sol, path = solve_topic(c, 0.3, 0.3, 0.0)
        assert sol.success, sol.message
        assert sol.tip_condition == "free" and math.isnan(sol.position_error)
        # No force or moment at a free tip; the base carries the whole weight (w = 5).
        assert abs(sol.tip_wrench.force.x) < 1e-9 and abs(sol.tip_wrench.force.y) < 1e-9
        assert sol.a[2] == pytest.approx(-5.0, rel=1e-12)
        assert path.poses[-1].pose.position.y < -0.4  # the cantilever sags (w = 5: y(1) = -0.496)


def test_bad_conditions_are_refused_by_name(cable):
    _, c = cable
    results = c.set_params(tip_condition="hinged")
    assert not results[0].successful and "tip_condition" in results[0].reason
    results = c.set_params(base_condition="free")
    assert not results[0].successful and "base_condition" in results[0].reason
    # A pinned base with a free tip: each value is valid, the pair holds nothing; targets are
    # refused with the reason.
    with params_set(c, base_condition="pinned", tip_condition="free"):
        # A refused target has no path: wait for the solution alone.
        s = h.next_seq()
        c.pub.publish(c.make_target(0.5, 0.0, 0.0, s))
        sol = c.solution_for(s, timeout=10.0)
        assert not sol.success and "pendulum" in sol.message


def test_a_held_rod_follows_its_gripper(cable):
    """With held ends the next target moves the rod held along its branch (held::follow): with
    follow_branch the event is "none", the rod on target, its base angle a step away from the
    last one's; the first target after a change of ends is a fresh search."""
    _, c = cable
    with params_set(c, base_condition="pinned", follow_branch=True):
        first, _ = solve_topic(c, 0.8, 0.0, 0.0)
        assert first.success, first.message
        for i in range(1, 4):
            sol, path = solve_topic(c, 0.8 - 0.02 * i, 0.02 * i, 0.0)
            assert sol.success, sol.message
            assert sol.event == "none", sol.event
            assert sol.position_error < 1e-9 and sol.stable
            assert abs(sol.base_angle - first.base_angle) < 0.2
            last = path.poses[-1].pose.position
            assert math.hypot(last.x - (0.8 - 0.02 * i), last.y - 0.02 * i) < 1e-9


def test_off_the_plane_held_ends_take_the_3d_rod(cable):
    """A target off the plane with pinned or free ends: refused naming solve_3d by default;
    with solve_3d the 3-D rod held by the ends answers (RodSolution.spatial): a hook (pinned
    tip) on its position with no moment there, a cable between two hooks with no moment at
    either end, its path ending at the target."""
    _, c = cable
    s = h.next_seq()
    c.pub.publish(c.make_target(0.6, -0.2, 0.0, s, z=0.2))
    sol = c.solution_for(s, timeout=10.0)
    assert not sol.success and "solve_3d" in sol.message
    for base in ("clamped", "pinned"):
        with params_set(c, solve_3d=True, base_condition=base):
            s = h.next_seq()
            c.pub.publish(c.make_target(0.6, -0.2, 0.0, s, z=0.2))
            sol, path = c.solution_for(s, timeout=20.0), c.path_for(s, timeout=20.0)
            assert sol.success, sol.message
            assert sol.spatial and sol.stable
            assert (sol.base_condition, sol.tip_condition) == (base, "pinned")
            assert sol.position_error < 1e-9
            t = sol.tip_wrench.torque
            assert max(abs(t.x), abs(t.y), abs(t.z)) < 1e-9
            last = path.poses[-1].pose.position
            assert math.dist((last.x, last.y, last.z), (0.6, -0.2, 0.2)) < 1e-9
            if base == "pinned":
                assert list(sol.a_spatial[:3]) == [0.0, 0.0, 0.0]
