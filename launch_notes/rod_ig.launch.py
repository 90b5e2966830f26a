"""ROS 2 launch file for rod_ig_node (for machines with a full ROS 2 install and `ros2 launch`).

rod_ig_node is a plain Cargo binary, not an ament package, so this launches it with
ExecuteProcess rather than Node(package=...). Usage, from the repository root after
`cargo build --release`:

    ros2 launch launch_notes/rod_ig.launch.py
    ros2 launch launch_notes/rod_ig.launch.py params_file:=/path/to/params.yaml
    ros2 launch launch_notes/rod_ig.launch.py rviz:=true fixed_frame:=rod_base   # and RViz

Parameters come from the YAML file (the package's ros/rod_ig/config/rod_ig_params.yaml, the one parameters file, or your own);
change them at run time with `ros2 param set /rod_ig_node rod_length 0.8`.

The node reads ROS_DOMAIN_ID and ROS_AUTOMATIC_DISCOVERY_RANGE from the environment.
"""
import os

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)


def generate_launch_description():
    node_bin = LaunchConfiguration("node_bin")
    return LaunchDescription([
        DeclareLaunchArgument("node_bin", default_value=os.path.join(REPO, "target", "release", "rod_ig_node"),
                              description="path of the rod_ig_node binary"),
        DeclareLaunchArgument("params_file", default_value=os.path.join(REPO, "ros", "rod_ig", "config", "rod_ig_params.yaml"),
                              description="ROS 2 parameters file for rod_ig_node"),
        DeclareLaunchArgument("rviz", default_value="false", description="also start RViz"),
        DeclareLaunchArgument("fixed_frame", default_value="rod_base",
                              description="RViz fixed frame: the frame_id of your targets (or base_frame)"),
        ExecuteProcess(
            cmd=[node_bin, "--ros-args", "--params-file", LaunchConfiguration("params_file")],
            name="rod_ig_node",
            output="screen",
            additional_env={"ROS_DISTRO": os.environ.get("ROS_DISTRO", "kilted")},
        ),
        ExecuteProcess(
            cmd=["rviz2", "-f", LaunchConfiguration("fixed_frame")],
            name="rviz2",
            output="screen",
            condition=IfCondition(LaunchConfiguration("rviz")),
        ),
    ])
