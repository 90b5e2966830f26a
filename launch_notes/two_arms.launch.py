"""Two-arm cell: one rod_ig_node per gripper pair, side by side on one ROS domain (for machines
with a full ROS 2 install and `ros2 launch`).

Each instance runs in its own namespace, so its topics, service and parameter services move
with it: /left/rod/target, /left/rod/path, /left/rod/solve, /left/rod_ig_node/set_parameters,
and the same under /right. The right arm's targets come from a planner topic of its own
(a remap), and both can follow a simulator's /clock. Each base gripper is its own frame
(left_rod_base, right_rod_base): the frame of the outputs, and with `use_tf:=true` the TF frame
that targets in any frame of the robot's tree are expressed in. Usage, from the repository root after
`scripts/run-node.sh --help` (or `scripts/patch-deps.sh && cargo build --release`):

    ros2 launch launch_notes/two_arms.launch.py
    ros2 launch launch_notes/two_arms.launch.py use_sim_time:=true

rod_ig_node is started with ExecuteProcess and the standard ROS arguments (`--ros-args -r
__ns:=... -r __node:=... -r from:=to -p name:=value --params-file FILE --log-level LEVEL`),
which it parses as rcl does. In a colcon workspace, `Node(package=..., namespace=...,
remappings=[...], parameters=[...])` passes exactly these arguments.
"""
import os

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess
from launch.substitutions import LaunchConfiguration

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)


def rod_node(namespace, node_bin, params_file, use_sim_time, extra=()):
    return ExecuteProcess(
        cmd=[node_bin, "--ros-args",
             "-r", f"__ns:=/{namespace}",
             "--params-file", params_file,
             "-p", ["use_sim_time:=", use_sim_time],
             *extra],
        name=f"{namespace}_rod_ig_node",
        output="screen",
        additional_env={"ROS_DISTRO": os.environ.get("ROS_DISTRO", "kilted")},
    )


def generate_launch_description():
    node_bin = LaunchConfiguration("node_bin")
    params_file = LaunchConfiguration("params_file")
    use_sim_time = LaunchConfiguration("use_sim_time")
    return LaunchDescription([
        DeclareLaunchArgument("node_bin", default_value=os.path.join(REPO, "target", "release", "rod_ig_node"),
                              description="path of the rod_ig_node binary"),
        DeclareLaunchArgument("params_file", default_value=os.path.join(REPO, "ros", "rod_ig", "config", "rod_ig_params.yaml"),
                              description="ROS 2 parameters file (its /** section serves both nodes)"),
        DeclareLaunchArgument("use_sim_time", default_value="false",
                              description="stamp zero-stamped targets with /clock time"),
        rod_node("left", node_bin, params_file, use_sim_time, extra=("-p", "base_frame:=left_rod_base")),
        # The right arm's planner publishes on /right_planner/goal: remap the relative name.
        rod_node("right", node_bin, params_file, use_sim_time,
                 extra=("-r", "rod/target:=/right_planner/goal", "-p", "rod_length:=0.8",
                        "-p", "base_frame:=right_rod_base")),
    ])
