"""Non-planar targets and the solve_3d parameter: rejected by default, answered by the 3-D solver
(RodSolution.spatial, a_spatial; a 3-D /rod/path) when solve_3d is true, at start-up
(`-p solve_3d:=true`) or set at run time."""
import math

import pytest

import rodig_harness as h

POS_TOL = 1e-5  # m (solver tolerance 1e-6 on the unit rod, rod_length 1 m)
SAMPLES = 100


def tilted_quaternion():
    """yaw 0.4 about z composed with 0.3 rad about (1, 1, 0)/sqrt(2): not a rotation about z."""
    s, c = math.sin(0.15) / math.sqrt(2.0), math.cos(0.15)
    sz, cz = math.sin(0.2), math.cos(0.2)
    return (cz * s - sz * s, cz * s + sz * s, sz * c, cz * c)


TARGET = dict(x=0.6, y=0.2, z=0.2, yaw=0.0, q=tilted_quaternion())


def start(args=None):
    return h.start_node_and_client(args, name="rod_ig_spatial_client")


def stop(node, client):
    h.stop_node_and_client(node, client)


@pytest.fixture(scope="module")
def node_3d():
    node, client = start(["--ros-args", "-p", "solve_3d:=true"])
    try:
        yield node, client
    finally:
        stop(node, client)


def quat_dot(a, b):
    return a.x * b[0] + a.y * b[1] + a.z * b[2] + a.w * b[3]


def check_3d_answer(c, seq, target):
    sol = c.solution_for(seq)
    assert sol is not None, "no /rod/solution"
    assert sol.success, sol.message
    assert sol.spatial and sol.stable and sol.stability_margin > 0
    assert len(sol.a_spatial) == 6 and any(v != 0.0 for v in sol.a_spatial)
    assert list(sol.a) == list(sol.a_spatial[2:5])
    assert sol.position_error < POS_TOL and sol.orientation_error < POS_TOL
    tp = target.pose.position
    q = (target.pose.orientation.x, target.pose.orientation.y, target.pose.orientation.z,
         target.pose.orientation.w)
    assert math.dist((sol.tip.position.x, sol.tip.position.y, sol.tip.position.z), (tp.x, tp.y, tp.z)) < POS_TOL
    path = c.path_for(seq)
    assert path is not None, "no /rod/path"
    assert len(path.poses) == SAMPLES
    first = path.poses[0].pose
    assert math.dist((first.position.x, first.position.y, first.position.z), (0, 0, 0)) < 1e-12
    assert abs(abs(first.orientation.w) - 1.0) < 1e-12
    last = path.poses[-1].pose
    assert math.dist((last.position.x, last.position.y, last.position.z), (tp.x, tp.y, tp.z)) < POS_TOL
    assert abs(abs(quat_dot(last.orientation, q)) - 1.0) < 1e-9
    # Consecutive samples at most 1/(samples - 1) of the rod length apart (arc >= chord).
    step = 1.0 / (SAMPLES - 1)
    for a, b in zip(path.poses, path.poses[1:]):
        pa, pb = a.pose.position, b.pose.position
        assert math.dist((pa.x, pa.y, pa.z), (pb.x, pb.y, pb.z)) <= step + 1e-9
    return sol


def test_non_planar_target_solved_in_3d(node_3d):
    _, c = node_3d
    s = h.next_seq()
    t = c.make_target(seq=s, **TARGET)
    c.pub.publish(t)
    check_3d_answer(c, s, t)
    m = c.marker_for(s)
    assert m is not None and len(m.points) == SAMPLES
    assert abs(m.points[-1].z - 0.2) < POS_TOL


def test_planar_target_still_planar_solver(node_3d):
    _, c = node_3d
    s = h.next_seq()
    c.pub.publish(c.make_target(0.6, 0.3, 0.5, s))
    sol = c.solution_for(s)
    assert sol is not None and sol.success, sol and sol.message
    assert not sol.spatial and list(sol.a_spatial) == [0.0] * 6


def test_service_answers_3d(node_3d):
    _, c = node_3d
    t = c.make_target(seq=h.next_seq(), **TARGET)
    # Few poses: large responses do not reach Fast DDS clients by default (see test_service.py).
    resp = c.solve(t, path_samples=10)
    assert resp is not None
    assert resp.solution.success and resp.solution.spatial, resp.solution.message
    assert len(resp.path.poses) == 10
    last = resp.path.poses[-1].pose.position
    assert math.dist((last.x, last.y, last.z), (0.6, 0.2, 0.2)) < POS_TOL


def test_out_of_reach_in_3d_rejected(node_3d):
    _, c = node_3d
    s = h.next_seq()
    c.pub.publish(c.make_target(seq=s, **dict(TARGET, z=0.9)))
    sol = c.solution_for(s)
    assert sol is not None and not sol.success and "out of reach" in sol.message


def test_run_time_switch(node_and_client):
    """Default node: rejected; after set_parameters solve_3d=true: solved; false again: rejected."""
    _, c = node_and_client
    assert c.get_params("solve_3d") == {"solve_3d": False}
    s = h.next_seq()
    c.pub.publish(c.make_target(seq=s, **TARGET))
    sol = c.solution_for(s)
    assert sol is not None and not sol.success and "not planar" in sol.message
    assert not sol.spatial
    res = c.set_params(solve_3d="yes")
    assert not res[0].successful and "solve_3d" in res[0].reason
    res = c.set_params(solve_3d=True)
    assert all(r.successful for r in res), [r.reason for r in res]
    assert c.get_params("solve_3d") == {"solve_3d": True}
    s = h.next_seq()
    t = c.make_target(seq=s, **TARGET)
    c.pub.publish(t)
    check_3d_answer(c, s, t)
    res = c.set_params(solve_3d=False)
    assert all(r.successful for r in res)
    s = h.next_seq()
    c.pub.publish(c.make_target(seq=s, **TARGET))
    sol = c.solution_for(s)
    assert sol is not None and not sol.success and "not planar" in sol.message
