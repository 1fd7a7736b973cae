"""Bring up the simulated graph: sim_bridge and the four evorbc nodes.

    ros2 launch evorbc_ros sim.launch.py maze:=zigzag mode:=lockstep gui:=false
    ros2 launch evorbc_ros sim.launch.py robot:=hexapod arbitrator:=ARB.json repertoire:=REP.json

Arguments: robot (4ws-5 or another 4WS type, or hexapod), maze (default: obstacle, or
hexapod for the hexapod), mode (lockstep|realtime), gui, arbitrator and repertoire
(files; empty for the shipped ones, which exist for 4ws-5 and the hexapod). Node parameters
come from config/ros/*.yaml of the package; the hexapod's episode is 30 s.
The same graph starts without ROS 2's launch via ``evorbc-sim``.
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    """The graph of evorbc-sim as a launch description."""
    return LaunchDescription(
        [
            DeclareLaunchArgument("robot", default_value="4ws-5"),
            DeclareLaunchArgument("maze", default_value=""),
            DeclareLaunchArgument("mode", default_value="lockstep"),
            DeclareLaunchArgument("gui", default_value="false"),
            DeclareLaunchArgument("arbitrator", default_value=""),
            DeclareLaunchArgument("repertoire", default_value=""),
            OpaqueFunction(function=_nodes),
        ]
    )


def _nodes(context):
    """The five nodes, with the robot's defaults filled in."""
    config = os.path.join(get_package_share_directory("evorbc_ros"), "config", "ros")
    nodes = os.path.join(config, "evorbc_nodes.yaml")
    bridge = os.path.join(config, "sim_bridge.yaml")
    arbitrator = LaunchConfiguration("arbitrator")
    sim_time = {"use_sim_time": True}
    robot = LaunchConfiguration("robot").perform(context)
    hexapod = robot == "hexapod"
    maze = LaunchConfiguration("maze").perform(context) or ("hexapod" if hexapod else "obstacle")
    robot_params = {"robot": robot}
    if hexapod:
        robot_params["episode_time"] = 30.0
        if not arbitrator.perform(context):
            from evorbc_ros.defaults import default_arbitrator  # the installed package's data

            arbitrator = str(default_arbitrator("hexapod"))
    return [
        Node(
            package="sim_bridge",
            executable="sim_bridge",
            output="screen",
            parameters=[
                bridge,
                {
                    **robot_params,
                    "maze": maze,
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
            parameters=[nodes, sim_time, {"robot": robot}],
        ),
    ]
