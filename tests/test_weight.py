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
    assert not sol.success and "plane" in sol.message
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
