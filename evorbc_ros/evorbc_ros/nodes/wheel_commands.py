"""The 4WS robots' onboard command interface: two ros2_control forward command controllers.

Named by the 4WS registrations' ``commands`` field (docs/your-robot.md). Publishes, reliable,
``steering_position_controller/commands`` (std_msgs/Float64MultiArray: the four steering
angles, rad, fl, fr, rl, rr) and ``wheel_velocity_controller/commands`` (the four wheel
velocities, rad/s: the robot's one wheel speed over the executor's live ``wheel_radius``).
"""

from __future__ import annotations

from std_msgs.msg import Float64MultiArray

from evorbc_ros.executor import PrimitiveExecutor, WheelCommand
from evorbc_ros.nodes.common import vector_message
from evorbc_ros.robots.four_ws import WHEEL_NAMES


class WheelCommands:
    """Steering angles and wheel velocities for a 4WS robot's two controllers.

    Args:
        node: the ``primitive_executor`` node: its lifecycle publishers, and its
            ``wheel_radius`` (m, read at every command).
        robot: the robot's registration; its ``model`` is its ``FourWSType`` (gene
            layout and body).
        inputs: sensor topics whose silence stops the robot.
        stale_timeout: s, inputs older than this stop the robot.

    """

    def __init__(self, node, robot, inputs: list[str], stale_timeout: float) -> None:
        self.node = node
        self.logic = PrimitiveExecutor(robot.model, robot.model.body(), inputs, stale_timeout)
        self.steering_pub = node.lifecycle_publisher(
            Float64MultiArray, "steering_position_controller/commands"
        )
        self.wheel_pub = node.lifecycle_publisher(
            Float64MultiArray, "wheel_velocity_controller/commands"
        )

    def publish(self, command: WheelCommand, halt: bool = False) -> None:
        """Send one command (a halt is a zero-speed command like any stop)."""
        self.steering_pub.publish(
            vector_message(command.steering, [f"{w}_steering" for w in WHEEL_NAMES])
        )
        self.wheel_pub.publish(
            vector_message(
                command.wheel_velocities(self.node.wheel_radius),
                [f"{w}_wheel" for w in WHEEL_NAMES],
            )
        )
