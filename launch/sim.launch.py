"""Bring up the simulated graph: sim_bridge and the four evorbc nodes.

    ros2 launch evorbc_bringup sim.launch.py maze:=zigzag mode:=lockstep gui:=false
    ros2 launch evorbc_bringup sim.launch.py robot:=hexapod namespace:=robot1
    ros2 launch evorbc_bringup sim.launch.py --show-args

Which nodes run, with which parameters, for which robot, comes from
:mod:`sim_bridge.graph`, shared with ``evorbc-sim`` and tested without ``launch``; this
file only turns it into launch actions. The whole graph shuts down when the bridge exits
(the episode is over, or it could not start) and when any other node fails.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction, Shutdown
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from sim_bridge.graph import ARGUMENTS, exit_ends_graph, graph_from_arguments


def generate_launch_description():
    """The launch arguments, and the nodes once their values are known."""
    return LaunchDescription(
        [
            *(
                DeclareLaunchArgument(a.name, default_value=a.default, description=a.description)
                for a in ARGUMENTS
            ),
            OpaqueFunction(function=_nodes),
        ]
    )


def _nodes(context):
    """One launch_ros Node per node of the graph."""
    graph = graph_from_arguments(
        {a.name: LaunchConfiguration(a.name).perform(context) for a in ARGUMENTS}
    )
    return [
        Node(
            package=spec.package,
            executable=spec.name,
            name=spec.name,
            namespace=graph.namespace,
            output="screen",
            parameters=[str(spec.param_file), spec.parameters],
            on_exit=lambda event, _context, spec=spec: _on_exit(spec, event.returncode),
        )
        for spec in graph.nodes
    ]


def _on_exit(spec, returncode):
    """Shut the whole graph down if this exit leaves it useless."""
    reason = exit_ends_graph(spec, returncode)
    return [Shutdown(reason=reason)] if reason else None
