"""``primitive_executor``: runs the current primitive on the 4WS robot's controllers.

Subscribes ``evorbc/primitive`` (genes) and, to know that the sensors are alive,
``evorbc/rangefinders`` and ``evorbc/goal_sectors``. Publishes, following ros2_control's
forward command controllers (std_msgs/Float64MultiArray, reliable):

* ``steering_position_controller/commands``: the four steering angles (rad; fl, fr, rl, rr)
* ``wheel_velocity_controller/commands``: the four wheel velocities (rad/s)

A command goes out at once for every new primitive and at least every 0.1 s (10 Hz). If
the primitive or a sensor input is older than ``stale_timeout`` (0.3 s) the executor
commands zero wheel speed, steering held, within one cycle, and resumes when they return.
"""

from __future__ import annotations

import sys

from rclpy.node import Node
from std_msgs.msg import Float64MultiArray

from evorbc_ros.executor import PrimitiveExecutor, WheelCommand
from evorbc_ros.laser import InputError
from evorbc_ros.nodes.common import (
    RELIABLE,
    StartupError,
    declare,
    finite_parameter,
    now_seconds,
    run_node,
    vector_message,
)
from evorbc_ros.robots.four_ws import ROBOT_TYPES, WHEEL_NAMES, FourWSGeometry


class PrimitiveExecutorNode(Node):
    """Publishes wheel commands at 10 Hz and stops the robot when inputs go stale."""

    def __init__(self, **kwargs) -> None:
        super().__init__("primitive_executor", **kwargs)
        robot = declare(self, "robot", "4ws-5", "robot type: 2ws-2, 2ws-3, 4ws-3 or 4ws-5")
        if robot not in ROBOT_TYPES:
            raise StartupError(
                f"parameter robot must be one of {', '.join(ROBOT_TYPES)}, got {robot!r}"
            )
        self.wheel_radius = finite_parameter(
            self, "wheel_radius", 0.02, "wheel radius (m), for wheel velocities", positive=True
        )
        self.period = finite_parameter(self, "period", 0.1, "command period (s)", positive=True)
        stale = finite_parameter(
            self, "stale_timeout", 0.3, "stop when an input is older than this (s)", positive=True
        )
        primitive_topic = declare(
            self, "primitive_topic", "evorbc/primitive", "primitive genes (Float64MultiArray)"
        )
        inputs = declare(
            self,
            "input_topics",
            ["evorbc/rangefinders", "evorbc/goal_sectors"],
            "sensor topics whose silence stops the robot",
        )
        steering_topic = declare(
            self,
            "steering_topic",
            "steering_position_controller/commands",
            "steering angles (Float64MultiArray, rad)",
        )
        wheel_topic = declare(
            self,
            "wheel_topic",
            "wheel_velocity_controller/commands",
            "wheel velocities (Float64MultiArray, rad/s)",
        )
        self.logic = PrimitiveExecutor(ROBOT_TYPES[robot], FourWSGeometry(), list(inputs), stale)
        self.primitive_topic = primitive_topic
        self.steering_pub = self.create_publisher(Float64MultiArray, steering_topic, RELIABLE)
        self.wheel_pub = self.create_publisher(Float64MultiArray, wheel_topic, RELIABLE)
        self.subs = [
            self.create_subscription(
                Float64MultiArray, primitive_topic, self.on_primitive, RELIABLE
            )
        ]
        self.subs += [
            self.create_subscription(
                Float64MultiArray, t, lambda msg, t=t: self.on_input(t), RELIABLE
            )
            for t in inputs
        ]
        self.last_publish = -float("inf")
        self.stopped_reason = ""
        self.timer = self.create_timer(self.period, self.on_timer)

    def on_primitive(self, msg: Float64MultiArray) -> None:
        """Run a new primitive at once."""
        now = now_seconds(self)
        try:
            self.logic.on_primitive(msg.data, now)
        except InputError as e:
            self.get_logger().warning(
                f"{self.primitive_topic}: skipped: {e}", throttle_duration_sec=2.0
            )
            return
        self.publish(self.logic.command(now), now)

    def on_input(self, topic: str) -> None:
        """Note a sensor input; if the robot was stopped for it, run again at once."""
        now = now_seconds(self)
        self.logic.on_input(topic, now)
        if self.stopped_reason:
            command = self.logic.command(now)
            if not command.stopped:
                self.publish(command, now)

    def on_timer(self) -> None:
        """Stop on stale inputs; otherwise keep commands flowing at least every period."""
        now = now_seconds(self)
        command = self.logic.command(now)
        if command.stopped or now - self.last_publish > 1.5 * self.period:
            self.publish(command, now)

    def publish(self, command: WheelCommand, now: float) -> None:
        """Send one command to both controllers."""
        if command.stopped and command.reason != self.stopped_reason:
            self.get_logger().warning(f"stopping the robot: {command.reason}")
        elif not command.stopped and self.stopped_reason:
            self.get_logger().info("inputs are back: running the primitive again")
        self.stopped_reason = command.reason if command.stopped else ""
        self.steering_pub.publish(
            vector_message(command.steering, [f"{w}_steering" for w in WHEEL_NAMES])
        )
        self.wheel_pub.publish(
            vector_message(
                command.wheel_velocities(self.wheel_radius), [f"{w}_wheel" for w in WHEEL_NAMES]
            )
        )
        self.last_publish = now


def main(argv=None) -> int:
    """Run the node."""
    return run_node(PrimitiveExecutorNode, argv)


if __name__ == "__main__":
    sys.exit(main())
