"""The rod/plan service (rod_ig_msgs/srv/PlanRod): a stable gripper path from the rod held now
(or a given rod) to a goal pose around obstacles; the planned rods on rod/plan_rods; failures
with a reason. Every answer is re-checked here: the path ends at the goal, the rods are spaced
as promised, and the last rod's tip (from the planar closed form) is the goal."""
import math

from geometry_msgs.msg import Point32, Polygon
from visualization_msgs.msg import Marker

import rodig_harness as h


def start():
    node, client = h.start_node_and_client(name="rod_ig_plan_client")
    rods = []
    client.node.create_subscription(Marker, "/rod/plan_rods", rods.append, h.topic_qos())
    return node, client, rods


def stop(node, client):
    h.stop_node_and_client(node, client)


def goal(c, x, y, yaw):
    return c.make_target(x, y, yaw, h.next_seq())


def check_plan(resp, gx, gy, gyaw):
    assert resp is not None, "no answer"
    assert resp.success, resp.reason
    rods = [list(resp.rods[i:i + 3]) for i in range(0, len(resp.rods), 3)]
    poses = resp.gripper_path.poses
    assert len(rods) == len(poses) >= 2
    last = poses[-1].pose
    assert math.hypot(last.position.x - gx, last.position.y - gy) < 1e-5
    assert abs(h.angle_diff(h.quaternion_yaw(last.orientation), gyaw)) < 1e-5
    for a, b in zip(rods, rods[1:]):
        na = math.sqrt(sum(v * v for v in a))
        nb = math.sqrt(sum(v * v for v in b))
        assert math.dist(a, b) <= 0.1 * (1.0 + min(na, nb)) + 1e-9
    assert resp.min_margin >= 1e-3
    return rods


def test_plan_from_a_given_rod_and_from_the_current_one():
    node, c, drawn = start()
    try:
        resp = c.plan(start=[1.0, 2.0, -1.0], goal=goal(c, 0.3, 0.6, 2.5),
                      disc_x=[0.5], disc_y=[0.35], disc_radius=[0.1])
        rods = check_plan(resp, 0.3, 0.6, 2.5)
        assert rods[0] == [1.0, 2.0, -1.0]
        assert c.wait_for(lambda: drawn, timeout=5.0), "no rod/plan_rods marker"
        assert drawn[-1].type == Marker.LINE_LIST and len(drawn[-1].points) > 0
        # The rod held now: after a target on rod/target, plan from it.
        s = h.next_seq()
        c.pub.publish(c.make_target(0.6, 0.3, 0.5, s))
        sol = c.solution_for(s)
        assert sol is not None and sol.success
        resp = c.plan(use_current=True, goal=goal(c, 0.5, -0.4, -1.0))
        rods = check_plan(resp, 0.5, -0.4, -1.0)
        assert max(abs(u - v) for u, v in zip(rods[0], sol.a)) < 1e-9
        # A polygon the rod must go around.
        square = Polygon(points=[Point32(x=0.55, y=0.05, z=0.0), Point32(x=0.65, y=0.05, z=0.0),
                                 Point32(x=0.65, y=0.15, z=0.0), Point32(x=0.55, y=0.15, z=0.0)])
        resp = c.plan(start=[1.0, 2.0, -1.0], goal=goal(c, 0.3, 0.6, 2.5), polygons=[square])
        check_plan(resp, 0.3, 0.6, 2.5)
    finally:
        stop(node, c)


def test_plan_failures_say_why():
    node, c, _ = start()
    try:
        resp = c.plan(start=[1.0, 2.0, -1.0], goal=goal(c, 1.5, 0.0, 0.0))
        assert resp is not None and not resp.success and "out of reach" in resp.reason
        resp = c.plan(start=[0.0, 0.0, 0.0], goal=goal(c, 0.3, 0.6, 2.5))
        assert not resp.success and "not stable" in resp.reason
        resp = c.plan(start=[1.0, 2.0, -1.0], goal=goal(c, 0.3, 0.6, 2.5), disc_x=[0.5])
        assert not resp.success and "same length" in resp.reason
        resp = c.plan(use_current=True, goal=goal(c, 0.3, 0.6, 2.5))
        assert not resp.success and "no current rod" in resp.reason
        # The node still serves targets afterwards.
        s = h.next_seq()
        c.pub.publish(c.make_target(0.6, 0.3, 0.5, s))
        sol = c.solution_for(s)
        assert sol is not None and sol.success
    finally:
        stop(node, c)
