"""One graph per ROS domain: a lockstep bridge stops when another graph shares its topics.

Two graphs in one domain answer each other's states, and each bridge steps with whichever
commands come first: the run leaves its offline episode and its arbitrator records extra
choices (two corridors runs started together in one domain recorded 2,978 and 2,925
choices for the episode's 938 cycles). The bridge runs here in-process, with this test
as the rest of its graph plus a second executor's publisher (docs/design.md section 9).
"""

import pytest
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Float64MultiArray

from evorbc_ros.nodes.common import vector_message
from sim_bridge.bridge_node import SharedGraphError, SimBridgeNode

COMMANDS = ("steering_position_controller/commands", "wheel_velocity_controller/commands")


def test_a_lockstep_bridge_stops_before_stepping_with_another_graphs_commands(ros):
    ros.helper.destroy_publisher(ros.clock_pub)  # the bridge is this graph's clock
    bridge = ros.make(SimBridgeNode, maze="gaps", episode_time=0.1, startup_timeout=10.0)
    try:
        ros.listen(LaserScan, "scan")
        ros.listen(Odometry, "odom")
        ours = [ros.publisher(Float64MultiArray, t) for t in (*COMMANDS, "evorbc/primitive")]
        theirs = ros.publisher(Float64MultiArray, COMMANDS[1])  # another graph's executor
        for pub in (*ours[:2], theirs):  # the bridge's own subscriptions
            ros.connected(pub)
        # The first state's answers are already queued: without the check, the bridge
        # would step with them.
        ours[0].publish(vector_message([0.0] * 4))
        theirs.publish(vector_message([100.0] * 4))
        with pytest.raises(SharedGraphError) as refused:
            bridge.run_lockstep()
        assert str(refused.value).startswith(
            "/wheel_velocity_controller/commands has 2 publishers: another graph runs in ROS domain"
        )
        assert bridge.world.status().time == 0.0 and len(bridge.trajectory) == 1  # no step
    finally:
        bridge.world.close()
