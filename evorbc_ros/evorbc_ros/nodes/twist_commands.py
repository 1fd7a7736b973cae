"""A differential-drive robot's onboard command interface: a body twist on ``cmd_vel``.

Named by the differential-drive registrations' ``commands`` field (docs/your-robot.md).
Publishes, reliable, on ``cmd_vel``: ``linear.x`` (m/s) and ``angular.z`` (rad/s), the
current primitive's genes scaled to the robot's limits, and a zero twist to stop. As
geometry_msgs/TwistStamped (frame ``base_link``, stamped with the node's clock) by default,
which is what ros2_control's diff_drive_controller takes from Jazzy on; with
``twist_stamped: false`` as geometry_msgs/Twist, what a TurtleBot3's base, older nav2 and
older stacks take.
"""

from __future__ import annotations

from geometry_msgs.msg import Twist, TwistStamped

from evorbc_ros.twist_executor import TwistCommand, TwistExecutor


class TwistCommands:
    """The current primitive as a body twist.

    Args:
        node: the ``primitive_executor`` node: its lifecycle publishers, clock and
            parameter ``twist_stamped``.
        robot: the robot's registration; its ``model`` is its
            :class:`~evorbc_ros.robots.diff_drive.DiffDriveGeometry`.
        inputs: sensor topics whose silence stops the robot.
        stale_timeout: s, inputs older than this stop the robot.

    """

    def __init__(self, node, robot, inputs: list[str], stale_timeout: float) -> None:
        self.node = node
        self.logic = TwistExecutor(robot.name, robot.model, inputs, stale_timeout)
        self.stamped = bool(node.get_parameter("twist_stamped").value)
        self.pub = node.lifecycle_publisher(TwistStamped if self.stamped else Twist, "cmd_vel")

    def publish(self, command: TwistCommand, halt: bool = False) -> None:
        """Send one command (a halt is a zero twist like any stop)."""
        twist = Twist()
        twist.linear.x = command.linear
        twist.angular.z = command.angular
        if not self.stamped:
            self.pub.publish(twist)
            return
        msg = TwistStamped(twist=twist)
        msg.header.stamp = self.node.get_clock().now().to_msg()
        msg.header.frame_id = "base_link"
        self.pub.publish(msg)
