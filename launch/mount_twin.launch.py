"""Launch mount_twin_node with a params file (default: the bundled config/params.yaml).

ros2 launch mount_twin mount_twin.launch.py params_file:=/path/params.yaml use_sim_time:=true
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from launch import LaunchDescription


def generate_launch_description() -> LaunchDescription:
    """The node, its params file and sim time for bag play (the input topic is the params
    file's input.topic: no remap needed)."""
    share = get_package_share_directory("mount_twin")
    return LaunchDescription(
        [
            DeclareLaunchArgument(
                "params_file", default_value=os.path.join(share, "config", "params.yaml")
            ),
            DeclareLaunchArgument("use_sim_time", default_value="false"),
            Node(
                package="mount_twin",
                executable="mount_twin_node",
                name="mount_twin",
                output="screen",
                parameters=[
                    LaunchConfiguration("params_file"),
                    {"use_sim_time": LaunchConfiguration("use_sim_time")},
                ],
            ),
        ]
    )
