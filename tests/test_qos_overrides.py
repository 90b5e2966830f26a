"""QoS overrides for every publisher (issue 20, item 5), by rclcpp's parameter names
(`qos_overrides.<topic>.publisher.<policy>`): an RViz display or a late joiner that asks for
TRANSIENT_LOCAL gets the last path and solution once the node's publishers offer it, and a
VOLATILE subscriber still gets only what is published after it joined."""
import threading
import time

from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

import rodig_harness as h
from rodig_harness import PathMsg, RodSolution

LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)


def _late_subscriber(c, ty, topic, qos):
    got = []
    event = threading.Event()

    def on_msg(msg):
        got.append(msg)
        event.set()

    c.node.create_subscription(ty, topic, on_msg, qos)
    return got, event


def test_transient_local_outputs_reach_late_joiners(tmp_path):
    params = tmp_path / "latched.yaml"
    params.write_text(
        "rod_ig_node:\n  ros__parameters:\n    qos_overrides:\n"
        "      /rod/path:\n        publisher:\n          durability: transient_local\n"
        "          depth: 1\n"
        "      /rod/solution:\n        publisher:\n          durability: transient_local\n")
    domain = h.free_domain()
    node = h.NodeProcess(domain, ["--ros-args", "--params-file", str(params),
                                  "-p", "qos_overrides./rod/marker.publisher.reliability:=best_effort"])
    c = h.Client(domain)
    try:
        assert c.wait_connected(), node.log_text()[-2000:]
        seq = h.next_seq()
        c.pub.publish(c.make_target(0.6, 0.3, 0.5, seq))
        first = c.solution_for(seq)
        assert first is not None and first.success
        # Late joiners, after the solution went out.
        late = h.Client(domain, name="rod_ig_late_joiner", path_only=True)
        try:
            paths, path_event = _late_subscriber(late, PathMsg, "/rod/path", LATCHED)
            sols, sol_event = _late_subscriber(late, RodSolution, "/rod/solution", LATCHED)
            volatile, _ = _late_subscriber(late, RodSolution, "/rod/solution", h.topic_qos())
            assert path_event.wait(10.0), "a TRANSIENT_LOCAL subscriber got no path"
            assert sol_event.wait(10.0), "a TRANSIENT_LOCAL subscriber got no solution"
            assert paths[-1].header.stamp == first.header.stamp
            assert list(sols[-1].a) == list(first.a)
            time.sleep(1.0)
            assert volatile == [] or all(s.header.stamp != first.header.stamp for s in volatile), \
                "a VOLATILE subscriber was handed the solution published before it joined"
        finally:
            late.close()
        names = {
            "qos_overrides./rod/path.publisher.durability": "transient_local",
            "qos_overrides./rod/path.publisher.depth": 1,
            "qos_overrides./rod/solution.publisher.durability": "transient_local",
            "qos_overrides./rod/marker.publisher.reliability": "best_effort",
            "qos_overrides./rod/plan_rods.publisher.durability": "volatile",
            "qos_overrides./diagnostics.publisher.history": "keep_last",
        }
        assert c.get_params(*names) == names
    finally:
        h.stop_node_and_client(node, c)


def test_default_outputs_are_volatile_and_refuse_transient_local():
    """Without the override a TRANSIENT_LOCAL subscription is incompatible (as rclcpp's
    default publishers are): it gets nothing, not even new samples."""
    node, c = h.start_node_and_client(name="rod_ig_qos_default")
    try:
        paths, path_event = _late_subscriber(c, PathMsg, "/rod/path", LATCHED)
        time.sleep(1.0)
        seq = h.next_seq()
        c.pub.publish(c.make_target(0.6, 0.3, 0.5, seq))
        assert c.solution_for(seq) is not None
        assert not path_event.wait(1.5), "a TRANSIENT_LOCAL subscriber matched a VOLATILE publisher"
    finally:
        h.stop_node_and_client(node, c)
