"""A differential-drive robot's onboard command interface: a body twist on ``cmd_vel``.

Named by the differential-drive registrations' ``commands`` field (docs/your-robot.md).
Publishes, reliable, ``cmd_vel_topic`` (geometry_msgs/Twist, default ``cmd_vel``):
``linear.x`` (m/s) and ``angular.z`` (rad/s), the current primitive's genes scaled to the
robot's limits, and a zero twist to stop. That is what a TurtleBot3's base, nav2 and
ros2_control's diff_drive_controller take (a controller that wants TwistStamped, as
diff_drive_controller does from Jazzy, takes it through a relay such as
``twist_stamper``).
"""

from __future__ import annotations

from geometry_msgs.msg import Twist

from evorbc_ros.nodes.common import RELIABLE, declare
from evorbc_ros.twist_executor import TwistCommand, TwistExecutor


class TwistCommands:
    """The current primitive as a body twist.

    Args:
        node: the ``primitive_executor`` node; it gets the parameter ``cmd_vel_topic``.
        robot: the robot's registration; its ``model`` is its
            :class:`~evorbc_ros.robots.diff_drive.DiffDriveGeometry`.
        inputs: sensor topics whose silence stops the robot.
        stale_timeout: s, inputs older than this stop the robot.

    """

    def __init__(self, node, robot, inputs: list[str], stale_timeout: float) -> None:
        self.logic = TwistExecutor(robot.name, robot.model, inputs, stale_timeout)
        topic = declare(node, "cmd_vel_topic", "cmd_vel", "body twist (Twist: m/s, rad/s)")
        self.pub = node.create_publisher(Twist, topic, RELIABLE)

    def publish(self, command: TwistCommand, halt: bool = False) -> None:
        """Send one command (a halt is a zero twist like any stop)."""
        msg = Twist()
        msg.linear.x = command.linear
        msg.angular.z = command.angular
        self.pub.publish(msg)
