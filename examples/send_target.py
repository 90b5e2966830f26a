#!/usr/bin/env python3
"""Send one tip-gripper pose to rod_ig_node and print what comes back.

    source scripts/setup/env.sh                      # rclpy + rod_ig_msgs (after scripts/setup/setup-env.sh)
    python examples/send_target.py 0.5 0.2 1.0 # x (m), y (m), yaw (rad) in the base frame
"""
import math
import sys

import rclpy
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Path
from rod_ig_msgs.msg import RodSolution


def main() -> int:
    x, y, yaw = (float(v) for v in (sys.argv[1:4] if len(sys.argv) >= 4 else (0.5, 0.2, 1.0)))
    rclpy.init()
    node = rclpy.create_node("rod_ig_example_client")
    replies = {}
    node.create_subscription(RodSolution, "/rod/solution", lambda m: replies.setdefault("solution", m), 10)
    node.create_subscription(Path, "/rod/path", lambda m: replies.setdefault("path", m), 10)
    pub = node.create_publisher(PoseStamped, "/rod/target", 10)

    # Topics are volatile: wait until the node has matched our publisher (and we its outputs).
    deadline = node.get_clock().now().nanoseconds + 10_000_000_000
    while (pub.get_subscription_count() == 0 or node.count_publishers("/rod/solution") == 0) \
            and node.get_clock().now().nanoseconds < deadline:
        rclpy.spin_once(node, timeout_sec=0.1)

    target = PoseStamped()
    target.header.frame_id = "rod_base"
    target.header.stamp = node.get_clock().now().to_msg()
    target.pose.position.x, target.pose.position.y = x, y
    target.pose.orientation.z, target.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    # Discovery is asynchronous: the node may see our publisher before its writer has matched
    # our subscription, and a volatile answer sent then is lost. Resend each second until one
    # arrives (the node answers every target; a repeat is harmless).
    resend_ns = 1_000_000_000
    last_sent = 0
    while "solution" not in replies and node.get_clock().now().nanoseconds < deadline:
        now = node.get_clock().now().nanoseconds
        if now - last_sent >= resend_ns:
            pub.publish(target)
            last_sent = now
        rclpy.spin_once(node, timeout_sec=0.1)
    solution = replies.get("solution")
    if solution is None:
        print("no answer from rod_ig_node (is it running on this ROS_DOMAIN_ID?)")
        return 1
    if solution.success:
        print(f"solved: a = {[round(float(v), 6) for v in solution.a]}, stable = {solution.stable}, "
              f"{solution.iterations} iterations, position error {solution.position_error:.2e} m")
        # The Path follows the solution; give it a moment.
        while "path" not in replies and node.get_clock().now().nanoseconds < deadline:
            rclpy.spin_once(node, timeout_sec=0.1)
        if "path" in replies:
            tip = replies["path"].poses[-1].pose.position
            print(f"path: {len(replies['path'].poses)} poses, tip at ({tip.x:.4f}, {tip.y:.4f})")
    else:
        print(f"failed: {solution.message}")
    node.destroy_node()
    rclpy.shutdown()
    return 0 if solution.success else 2


if __name__ == "__main__":
    sys.exit(main())
