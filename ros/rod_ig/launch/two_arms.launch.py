"""Two-arm cell: one rod_ig_node per gripper pair, side by side on one ROS domain:
`ros2 launch rod_ig two_arms.launch.py`.

Each instance runs in its own namespace, so its topics, services and parameter services move
with it: /left/rod/target, /left/rod/path, /left/rod/solve, /left/rod_ig_node/set_parameters,
and the same under /right. The right arm's targets come from a planner topic of its own (a
remap) and its rod is 0.8 m; each base gripper is its own TF frame (left_rod_base,
right_rod_base); both can follow a simulator's /clock (use_sim_time:=true).
"""
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare


def rod_node(namespace, overrides, remappings=()):
    return Node(
        package="rod_ig",
        executable="rod_ig_node",
        name="rod_ig_node",
        namespace=namespace,
        parameters=[LaunchConfiguration("params_file"),
                    {"use_sim_time": LaunchConfiguration("use_sim_time"), **overrides}],
        remappings=list(remappings),
        output="screen",
    )


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument(
            "params_file",
            default_value=PathJoinSubstitution([FindPackageShare("rod_ig"), "config", "rod_ig_params.yaml"]),
            description="ROS 2 parameters file (its /**/rod_ig_node section serves both nodes)"),
        DeclareLaunchArgument("use_sim_time", default_value="false",
                              description="stamp zero-stamped targets with /clock time"),
        # Each rod's base gripper is its own TF frame (the params file's use_tf: targets in
        # any frame of the robot's tree are expressed in it).
        rod_node("left", {"base_frame": "left_rod_base"}),
        # The right arm's planner publishes on /right_planner/goal: remap the relative name.
        rod_node("right", {"rod_length": 0.8, "base_frame": "right_rod_base"},
                 remappings=[("rod/target", "/right_planner/goal")]),
    ])
