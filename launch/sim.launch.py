"""Bring up the simulated graph: sim_bridge and the four evorbc nodes.

    ros2 launch evorbc_ros sim.launch.py maze:=zigzag mode:=lockstep gui:=false

Arguments: maze, mode (lockstep|realtime), gui, arbitrator and repertoire (files; empty
for the shipped ones). Node parameters come from config/ros/*.yaml of the package.
The same graph starts without ROS 2's launch via ``evorbc-sim``.
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    """The graph of evorbc-sim as a launch description."""
    config = os.path.join(get_package_share_directory("evorbc_ros"), "config", "ros")
    nodes = os.path.join(config, "evorbc_nodes.yaml")
    bridge = os.path.join(config, "sim_bridge.yaml")
    arbitrator = LaunchConfiguration("arbitrator")
    sim_time = {"use_sim_time": True}
    return LaunchDescription(
        [
            DeclareLaunchArgument("maze", default_value="obstacle"),
            DeclareLaunchArgument("mode", default_value="lockstep"),
            DeclareLaunchArgument("gui", default_value="false"),
            DeclareLaunchArgument("arbitrator", default_value=""),
            DeclareLaunchArgument("repertoire", default_value=""),
            Node(
                package="sim_bridge",
                executable="sim_bridge",
                output="screen",
                parameters=[
                    bridge,
                    {
                        "maze": LaunchConfiguration("maze"),
                        "mode": LaunchConfiguration("mode"),
                        "gui": LaunchConfiguration("gui"),
                    },
                ],
            ),
            Node(
                package="evorbc_ros",
                executable="laser_sensor",
                output="screen",
                parameters=[nodes, sim_time, {"sensor_layout": arbitrator}],
            ),
            Node(
                package="evorbc_ros",
                executable="radar_sensor",
                output="screen",
                parameters=[nodes, sim_time, {"sensor_layout": arbitrator}],
            ),
            Node(
                package="evorbc_ros",
                executable="arbitrator",
                output="screen",
                parameters=[
                    nodes,
                    sim_time,
                    {"arbitrator": arbitrator, "repertoire": LaunchConfiguration("repertoire")},
                ],
            ),
            Node(
                package="evorbc_ros",
                executable="primitive_executor",
                output="screen",
                parameters=[nodes, sim_time],
            ),
        ]
    )
