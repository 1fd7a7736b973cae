"""A differential-drive robot's body twist: TwistStamped by default, Twist on request.

Jazzy's diff_drive_controller takes geometry_msgs/TwistStamped on ``cmd_vel``; a
TurtleBot3's own base and older stacks take geometry_msgs/Twist. The executor and the
simulation bridge speak the same one, set by ``twist_stamped`` (docs/design.md section 9).
"""

import pytest
from geometry_msgs.msg import Twist, TwistStamped

from evorbc_ros.nodes.common import vector_message
from evorbc_ros.nodes.primitive_executor import PrimitiveExecutorNode

BURGER = "turtlebot3-burger"


@pytest.mark.parametrize(("stamped", "kind"), [(True, TwistStamped), (False, Twist)])
def test_the_executor_publishes_the_twist_type_asked_for(ros, stamped, kind):
    ros.make(PrimitiveExecutorNode, sim_time=True, robot=BURGER, twist_stamped=stamped)
    ros.set_clock(1.0)  # standing still: no stale stop under load
    got = ros.listen(kind, "cmd_vel")
    prim, rf, gs = ros.executor_inputs()
    rf.publish(vector_message([0.0] * 6))
    gs.publish(vector_message([1, 0, 0, 0]))
    prim.publish(vector_message([1.0, 0.0]))  # full speed ahead, no turn
    assert ros.spin_until(lambda: got)
    twist = got[-1].twist if stamped else got[-1]
    assert twist.linear.x > 0.0 and twist.angular.z == 0.0
    if stamped:
        assert got[-1].header.frame_id == "base_link"


@pytest.mark.parametrize(("stamped", "kind"), [(True, TwistStamped), (False, Twist)])
def test_the_bridge_takes_the_same_type(ros, stamped, kind):
    from sim_bridge.bridge_node import SimBridgeNode

    node = ros.make(SimBridgeNode, robot=BURGER, maze="zigzag", twist_stamped=stamped)
    try:
        (sub,) = node.subs
        assert sub.msg_type is kind and sub.topic_name == "/cmd_vel"
    finally:
        node.world.close()
