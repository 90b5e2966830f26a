"""Rods with weight in the node: the parameters linear_density, bending_stiffness and gravity
give the dimensionless weight w = rho*A*|g|*L^3/EI; RodSolution reports it with the total
energy; wrong or missing values refuse targets with a reason (issue 41)."""
import math

import pytest

import rodig_harness as h

# A 30 cm cable of 20 g/m, EI = 3.5e-4 N m^2: w = 0.02 * 9.81 * 0.3^3 / 3.5e-4 = 15.13...
CABLE = ["-p", "rod_length:=0.3", "-p", "bending_stiffness:=3.5e-4", "-p", "linear_density:=0.02",
         "-p", "gravity:=[0.0, -9.81, 0.0]"]
W = 0.02 * 9.81 * 0.3**3 / 3.5e-4


@pytest.fixture(scope="module")
def cable():
    node, client = h.start_node_and_client(["--ros-args", *CABLE])
    yield node, client
    h.stop_node_and_client(node, client)


def solve_topic(c, x, y, yaw):
    s = h.next_seq()
    c.pub.publish(c.make_target(x, y, yaw, s))
    return c.solution_for(s), c.path_for(s, timeout=2.0)


def test_a_heavy_cable_held_level_sags(cable):
    _, c = cable
    assert c.get_params("gravity", "linear_density") == {"gravity": [0.0, -9.81, 0.0],
                                                         "linear_density": 0.02}
    sol, path = solve_topic(c, 0.18, 0.0, 0.0)
    assert sol.success, sol.message
    assert sol.stable
    assert math.isclose(sol.weight, W, rel_tol=1e-12)
    assert sol.total_energy != sol.elastic_energy
    assert sol.position_error < 1e-6 * 0.3
    last = path.poses[-1].pose.position
    assert math.hypot(last.x - 0.18, last.y) < 1e-6
    # The base wrench in newtons is the normalised one times EI/L^2 (the weight's scale).
    assert math.isclose(sol.base_wrench.force.y, sol.a[2] * 3.5e-4 / 0.3**2, rel_tol=1e-12)


def test_rod_plan_plans_for_the_cable_with_weight(cable):
    """rod/plan with weight: a stable path of heavy rods, ending where the heavy rod's tip is
    the goal; gravity out of the rod's plane is refused with the reason."""
    _, c = cable
    start = [1.7939773444075664, -11.347913785723009, 2.39993152353178]
    gx, gy, gyaw = 0.2413 * 0.3, -0.7694 * 0.3, -1.5494
    resp = c.plan(start=start, goal=c.make_target(gx, gy, gyaw, h.next_seq()))
    assert resp is not None and resp.success, resp and resp.reason
    assert resp.min_margin >= 1e-3
    last = resp.gripper_path.poses[-1].pose
    assert math.hypot(last.position.x - gx, last.position.y - gy) < 1e-6
    assert list(resp.rods[:3]) == start
    # Gravity out of the plane: the planner is planar.
    assert all(r.successful for r in c.set_params(gravity=[0.0, -6.0, 7.0]))
    try:
        resp = c.plan(start=start, goal=c.make_target(gx, gy, gyaw, h.next_seq()))
        assert resp is not None and not resp.success and "plane" in resp.reason
    finally:
        assert all(r.successful for r in c.set_params(gravity=[0.0, -9.81, 0.0]))


def test_weight_changes_take_effect_and_bad_values_are_refused(cable):
    _, c = cable
    # Gravity along +x (the base gripper turned): another rod for the same target.
    assert all(r.successful for r in c.set_params(gravity=[9.81, 0.0, 0.0]))
    sol, _ = solve_topic(c, 0.18, 0.0, 0.0)
    assert sol.success, sol.message
    assert math.isclose(sol.weight, W, rel_tol=1e-12)
    # Gravity out of the rod's plane: refused with the reason.
    assert all(r.successful for r in c.set_params(gravity=[0.0, -6.0, 7.0]))
    sol, _ = solve_topic(c, 0.18, 0.0, 0.0)
    assert not sol.success and "plane" in sol.message and "solve_3d" in sol.message
    # No gravity, or no stiffness: refused, naming what is missing.
    assert all(r.successful for r in c.set_params(gravity=[0.0, 0.0, 0.0]))
    sol, _ = solve_topic(c, 0.18, 0.0, 0.0)
    assert not sol.success and "gravity" in sol.message
    (res,) = c.set_params(gravity=[0.0, 1.0])
    assert not res.successful and "gravity" in res.reason
    assert all(r.successful for r in c.set_params(gravity=[0.0, -9.81, 0.0], bending_stiffness=0.0))
    sol, _ = solve_topic(c, 0.18, 0.0, 0.0)
    assert not sol.success and "bending_stiffness" in sol.message
    # Back to the cable: solved again; linear_density 0 is the weightless rod (w = 0).
    assert all(r.successful for r in c.set_params(bending_stiffness=3.5e-4))
    sol, _ = solve_topic(c, 0.18, 0.0, 0.0)
    assert sol.success and math.isclose(sol.weight, W, rel_tol=1e-12)
    assert all(r.successful for r in c.set_params(linear_density=0.0))
    sol, _ = solve_topic(c, 0.18, 0.0, 0.0)
    assert sol.success and sol.weight == 0.0 and sol.total_energy == sol.elastic_energy


# A 1 m harness of 100 g/m with EI = 4.905e-4 N m^2: w = 0.1 * 9.81 * 1^3 / 4.905e-4 = 2,000
# (issue 51: solved by multiple shooting on node states above w = 200).
HARNESS = ["-p", "rod_length:=1.0", "-p", "bending_stiffness:=4.905e-4", "-p", "linear_density:=0.1",
           "-p", "gravity:=[0.0, -9.81, 0.0]", "-p", "deadline_ms:=5000.0"]


@pytest.fixture(scope="module")
def harness():
    node, client = h.start_node_and_client(["--ros-args", *HARNESS], name="rod_ig_harness_client")
    yield node, client
    h.stop_node_and_client(node, client)


def test_a_one_metre_harness_hangs_and_follows_the_gripper(harness):
    """w = 2,000 held level 0.8 m apart: the hanging, loop-free cable (each gripper holds half of
    the weight: a5 = -w/2; turns 0), its path below the grippers with the reference sag 0.2676 m; the
    next target starts from the rod just returned (its node states) and is solved too."""
    _, c = harness
    sol, path = solve_topic(c, 0.8, 0.0, 0.0)
    assert sol.success, sol.message
    assert sol.stable and math.isclose(sol.weight, 2000.0, rel_tol=1e-9)
    assert abs(sol.a[2] + 1000.0) < 1e-6
    assert sol.turns == 0  # loop-free (RodSolution.turns, appended)
    ys = [p.pose.position.y for p in path.poses]
    assert max(ys) <= 1e-9 and abs(-min(ys) - 0.2676) < 5e-3  # 100 path samples: the sag to 5 mm
    last = path.poses[-1].pose.position
    assert math.hypot(last.x - 0.8, last.y) < 1e-6
    sol, path = solve_topic(c, 0.75, 0.05, 0.1)
    assert sol.success, sol.message
    last = path.poses[-1].pose.position
    assert math.hypot(last.x - 0.75, last.y - 0.05) < 1e-6


@pytest.fixture(scope="module")
def cable_3d():
    node, client = h.start_node_and_client(["--ros-args", *CABLE, "-p", "solve_3d:=true"],
                                           name="rod_ig_weight_3d_client")
    yield node, client
    h.stop_node_and_client(node, client)


def tilted(yaw, tilt):
    """yaw about z, then `tilt` rad about x: a target out of the rod's plane."""
    cy, sy, ct, st = math.cos(yaw / 2), math.sin(yaw / 2), math.cos(tilt / 2), math.sin(tilt / 2)
    return (cy * st, sy * st, sy * ct, cy * ct)


def check_heavy_3d(c, s, x, y, z, w=W):
    sol = c.solution_for(s)
    assert sol is not None and sol.success, sol and sol.message
    assert sol.spatial and sol.stable
    assert math.isclose(sol.weight, w, rel_tol=1e-12)
    assert sol.total_energy != sol.elastic_energy
    last = c.path_for(s, timeout=2.0).poses[-1].pose.position
    assert math.dist((last.x, last.y, last.z), (x, y, z)) < 1e-6
    return sol


def test_the_3d_rod_with_weight_serves_non_planar_targets(cable_3d):
    """solve_3d with weight: the 3-D rod under gravity (spatial::HeavySpatial), not a refusal."""
    _, c = cable_3d
    s = h.next_seq()
    c.pub.publish(c.make_target(0.18, 0.06, 0.0, s, z=0.05, q=tilted(0.4, 0.3)))
    heavy = check_heavy_3d(c, s, 0.18, 0.06, 0.05)
    # The same target without weight is another rod: the weight was modelled.
    assert all(r.successful for r in c.set_params(linear_density=0.0))
    s = h.next_seq()
    c.pub.publish(c.make_target(0.18, 0.06, 0.0, s, z=0.05, q=tilted(0.4, 0.3)))
    light = c.solution_for(s)
    assert light.success and light.spatial and light.weight == 0.0, light.message
    assert max(abs(p - q) for p, q in zip(heavy.a_spatial, light.a_spatial)) > 1.0
    assert all(r.successful for r in c.set_params(linear_density=0.02))


def test_gravity_out_of_the_plane_is_the_3d_rods(cable_3d):
    """Gravity leaving the rod's plane (a tilted base gripper): with solve_3d even a planar
    target is the 3-D rod's, sagging out of the plane."""
    _, c = cable_3d
    assert all(r.successful for r in c.set_params(gravity=[0.0, -6.0, 7.0]))
    try:
        s = h.next_seq()
        c.pub.publish(c.make_target(0.18, 0.09, 0.5, s))
        # |g| = sqrt(6^2 + 7^2) m/s^2 here.
        check_heavy_3d(c, s, 0.18, 0.09, 0.0, w=W * math.hypot(6.0, 7.0) / 9.81)
        shape = c.path_for(s, timeout=2.0).poses
        assert max(abs(p.pose.position.z) for p in shape) > 1e-3  # out of the plane
    finally:
        assert all(r.successful for r in c.set_params(gravity=[0.0, -9.81, 0.0]))


@pytest.fixture(scope="module")
def harness_3d():
    node, client = h.start_node_and_client(["--ros-args", *HARNESS, "-p", "solve_3d:=true"],
                                           name="rod_ig_harness_3d_client")
    yield node, client
    h.stop_node_and_client(node, client)


def test_a_one_metre_harness_in_3d(harness_3d):
    """solve_3d at w = 2,000 (issue 51, item 5): targets out of the plane of the base and gravity
    are reached by the 3-D rod (multiple shooting from the nearest planar rod), stable, its path
    ending on the target; the level target stays the planar rod's (in-plane gravity)."""
    _, c = harness_3d
    sol, _ = solve_topic(c, 0.8, 0.0, 0.0)
    assert sol.success and sol.stable and not sol.spatial, sol.message
    for (x, y, z, q) in [(0.7, -0.1, 0.15, tilted(0.2, 0.3)), (0.8, 0.0, 0.05, tilted(0.0, 0.0))]:
        s = h.next_seq()
        c.pub.publish(c.make_target(x, y, 0.0, s, z=z, q=q))
        check_heavy_3d(c, s, x, y, z, w=2000.0)


def _yaw(pose):
    q = pose.orientation
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def test_rod_plan_moves_the_one_metre_harness_around_a_disc(harness):
    """rod/plan at w = 2,000 (issue 51, item 4) from the rod the node holds: the hanging cable is
    a start (the a-space planner refused it: its conjugate-point margin shrinks with w), the
    plan goes around a disc its straight path would cross, ends on the goal, its gripper steps
    are at most 0.1 m (+ 0.3 m/rad of turn) apart and its margin is the second variation's."""
    _, c = harness
    sol, _ = solve_topic(c, 0.8, 0.0, 0.0)
    assert sol.success, sol.message
    resp = c.plan(use_current=True, goal=c.make_target(0.6, 0.2, 0.3, h.next_seq()),
                  disc_x=[0.7], disc_y=[0.1], disc_radius=[0.05])
    assert resp is not None and resp.success, resp and resp.reason
    assert resp.min_margin >= 1e-3
    assert max(abs(u - v) for u, v in zip(resp.rods[:3], sol.a)) < 1e-9
    poses = [p.pose for p in resp.gripper_path.poses]
    assert len(poses) > 5  # a detour around the disc
    last = poses[-1]
    assert math.hypot(last.position.x - 0.6, last.position.y - 0.2) < 1e-6
    assert abs(_yaw(last) - 0.3) < 1e-6
    for p, q in zip(poses, poses[1:]):
        step = math.hypot(q.position.x - p.position.x, q.position.y - p.position.y)
        turn = abs(math.remainder(_yaw(q) - _yaw(p), math.tau))
        assert step + 0.3 * turn <= 0.1 + 1e-9
        # The gripper stays off the disc (its tip is a point of the rod).
        assert math.hypot(q.position.x - 0.7, q.position.y - 0.1) > 0.05
