"""A Jazzy rclpy client (run with the Jazzy venv's python by tests/test_distros.py): sends
targets to /rod/target until /rod/path answers; prints how many answers came and exits 0 when
at least `want` did. Standard messages only (rod_ig_msgs is built for the Kilted venv)."""
import sys
import time

import rclpy
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Path
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy


def main() -> int:
    want = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    rclpy.init()
    node = rclpy.create_node("rod_ig_jazzy_client")
    qos = QoSProfile(reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE,
                     history=HistoryPolicy.KEEP_LAST, depth=10)
    pub = node.create_publisher(PoseStamped, "/rod/target", qos)
    paths = []
    node.create_subscription(Path, "/rod/path", lambda m: paths.append(len(m.poses)), qos)
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline and (pub.get_subscription_count() == 0
                                           or node.count_publishers("/rod/path") == 0):
        rclpy.spin_once(node, timeout_sec=0.05)
    sent = 0
    while time.monotonic() < deadline and len(paths) < want:
        msg = PoseStamped()
        msg.header.frame_id = "rod_base"
        msg.pose.position.x = 0.5 + 0.01 * (sent % 10)
        msg.pose.position.y = 0.2
        msg.pose.orientation.z = 0.4794255386
        msg.pose.orientation.w = 0.8775825619
        pub.publish(msg)
        sent += 1
        end = time.monotonic() + 0.2
        while time.monotonic() < end:
            rclpy.spin_once(node, timeout_sec=0.02)
    print(f"answers {len(paths)} poses {paths[:1]} rclpy {rclpy.__file__}", flush=True)
    node.destroy_node()
    rclpy.shutdown()
    return 0 if len(paths) >= want else 1


if __name__ == "__main__":
    sys.exit(main())
