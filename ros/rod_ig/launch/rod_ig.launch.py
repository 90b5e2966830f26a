"""rod_ig_node with its installed parameters file: `ros2 launch rod_ig rod_ig.launch.py`.

    ros2 launch rod_ig rod_ig.launch.py
    ros2 launch rod_ig rod_ig.launch.py namespace:=left params_file:=/path/to/my_params.yaml
    ros2 launch rod_ig rod_ig.launch.py use_sim_time:=true
    ros2 launch rod_ig rod_ig.launch.py rviz:=true fixed_frame:=rod_base   # and RViz

The parameters file's `/**/rod_ig_node` section applies in any namespace; change parameters at
run time with `ros2 param set /rod_ig_node rod_length 0.8`. The node reads ROS_DOMAIN_ID,
ROS_AUTOMATIC_DISCOVERY_RANGE and the security variables from the environment as rcl does.
"""
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument(
            "params_file",
            default_value=PathJoinSubstitution([FindPackageShare("rod_ig"), "config", "rod_ig_params.yaml"]),
            description="ROS 2 parameters file for rod_ig_node"),
        DeclareLaunchArgument("namespace", default_value="", description="namespace of the node"),
        DeclareLaunchArgument("use_sim_time", default_value="false",
                              description="stamp zero-stamped targets with /clock time"),
        Node(
            package="rod_ig",
            executable="rod_ig_node",
            name="rod_ig_node",
            namespace=LaunchConfiguration("namespace"),
            parameters=[LaunchConfiguration("params_file"),
                        {"use_sim_time": LaunchConfiguration("use_sim_time")}],
            output="screen",
        ),
        DeclareLaunchArgument("rviz", default_value="false", description="also start RViz"),
        DeclareLaunchArgument("fixed_frame", default_value="rod_base",
                              description="RViz fixed frame: the frame_id of your targets (or base_frame)"),
        Node(
            package="rviz2",
            executable="rviz2",
            arguments=["-f", LaunchConfiguration("fixed_frame")],
            condition=IfCondition(LaunchConfiguration("rviz")),
        ),
    ])
