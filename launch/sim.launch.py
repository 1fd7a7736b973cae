"""Bring up the simulated graph: sim_bridge and the four evorbc nodes.

    ros2 launch evorbc_bringup sim.launch.py maze:=zigzag mode:=lockstep gui:=false
    ros2 launch evorbc_bringup sim.launch.py robot:=hexapod namespace:=robot1
    ros2 launch evorbc_bringup sim.launch.py --show-args

Which nodes run, with which parameters, for which robot, comes from
:mod:`sim_bridge.graph`, shared with ``evorbc-sim`` and tested without ``launch``; this
file only turns it into launch actions. The lifecycle nodes (arbitrator, executor) start
unconfigured and this file drives them: configure, then activate once configured. The
whole graph shuts down when the bridge exits (the episode is over), and the launch fails
(a non-zero status) when a node cannot start, fails to configure, or dies
(docs/design.md section 9).
"""

from launch import LaunchDescription
from launch.actions import (
    DeclareLaunchArgument,
    EmitEvent,
    OpaqueFunction,
    RegisterEventHandler,
    Shutdown,
)
from launch.events import matches_action
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import LifecycleNode, Node
from launch_ros.event_handlers import OnStateTransition
from launch_ros.events.lifecycle import ChangeState
from lifecycle_msgs.msg import Transition

from sim_bridge.graph import ARGUMENTS, exit_ends_graph, graph_from_arguments


class GraphFailed(RuntimeError):
    """A node of the graph was refused or died: ``ros2 launch`` ends with status 1."""


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
    """One launch_ros node per node of the graph, and the lifecycle nodes' transitions."""
    graph = graph_from_arguments(
        {a.name: LaunchConfiguration(a.name).perform(context) for a in ARGUMENTS}
    )
    actions = []
    for spec in graph.nodes:
        kind = LifecycleNode if spec.managed else Node
        params = {**spec.parameters, "autostart": False} if spec.managed else spec.parameters
        node = kind(
            package=spec.package,
            executable=spec.name,
            name=spec.name,
            namespace=graph.namespace,
            output="screen",
            parameters=[str(spec.param_file), params],
            on_exit=lambda event, context, spec=spec: _on_exit(spec, event.returncode, context),
        )
        actions.append(node)
        if spec.managed:
            actions += _drive(node, spec.name)
    return actions


def _drive(node, name):
    """Configure ``node`` now; activate it once configured; fail the launch if it cannot.

    The activation is handled once: after a later reconfigure by hand (``ros2 lifecycle``)
    the user activates the node. A failed configure, or an error in a transition (which
    ends in unconfigured through errorprocessing), fails the launch whenever it happens.
    """

    def change(transition):
        return EmitEvent(
            event=ChangeState(lifecycle_node_matcher=matches_action(node), transition_id=transition)
        )

    def refused(context):
        raise GraphFailed(f"{name} could not be configured or failed (its line above says why)")

    return [
        RegisterEventHandler(
            OnStateTransition(
                target_lifecycle_node=node,
                start_state="configuring",
                goal_state="inactive",
                entities=[change(Transition.TRANSITION_ACTIVATE)],
                handle_once=True,
            )
        ),
        *(
            RegisterEventHandler(
                OnStateTransition(
                    target_lifecycle_node=node,
                    start_state=start,
                    goal_state="unconfigured",
                    entities=[OpaqueFunction(function=refused)],
                )
            )
            for start in ("configuring", "errorprocessing")
        ),
        change(Transition.TRANSITION_CONFIGURE),
    ]


def _on_exit(spec, returncode, context):
    """Shut the graph down when this exit leaves it useless; fail if the node failed."""
    reason = exit_ends_graph(spec, returncode)
    if not reason or getattr(context, "is_shutdown", False):
        return None
    if returncode != 0:
        raise GraphFailed(reason)
    return [Shutdown(reason=reason)]
