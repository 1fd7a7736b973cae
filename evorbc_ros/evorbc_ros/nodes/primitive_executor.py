"""``primitive_executor``: runs the current primitive on the robot's controllers.

Subscribes ``evorbc/primitive`` (genes) and, to know that the sensors are alive,
``evorbc/rangefinders`` and ``evorbc/goal_sectors``. What it publishes is the robot's
command interface, named by its registration (:mod:`evorbc_ros.robots.registry`),
following ros2_control's command conventions (reliable):

* 4WS robots (:mod:`evorbc_ros.nodes.wheel_commands`), forward command controllers
  (std_msgs/Float64MultiArray): ``steering_position_controller/commands``, the four
  steering angles (rad; fl, fr, rl, rr), and ``wheel_velocity_controller/commands``, the
  four wheel velocities (rad/s).
* the hexapod (:mod:`evorbc_ros.nodes.trajectory_commands`), joint_trajectory_controller
  (trajectory_msgs/JointTrajectory): ``joint_trajectory_controller/joint_trajectory``,
  the 18 joints' targets (rad) for the next ``stale_timeout`` s, one point per physics
  step (``trajectory_rate``, 50 Hz), see :mod:`evorbc_ros.hexapod_executor`.
* legged robots from a settings file, such as the A1
  (:mod:`evorbc_ros.nodes.legged_commands`): the same, for the robot's joints, at its own
  physics rate (the A1: 12 joints, 100 Hz) unless ``trajectory_rate`` is set.

The node declares the parameters of both (topics, ``wheel_radius``, ``trajectory_rate``),
whichever robot it drives, so one parameter file serves every robot.

A command goes out at once for every new primitive, and again whenever 1.5 periods
(0.15 s) pass without one, so the controllers keep receiving 10 Hz commands. If
the primitive or a sensor input is older than ``stale_timeout`` (0.3 s) the executor
stops the robot within one cycle (4WS: zero wheel speed, steering held; hexapod: every
joint held at its last target), and resumes when they return.

Before the first message on ``evorbc/primitive`` nothing is published, so the executor
does not fight another node (teleop) on the same controllers; ``zero_before_first_primitive``
makes a 4WS executor send zero commands every period instead. A primitive labelled with
another robot's parameter names is refused and logged as an error. ``wheel_radius`` is
applied live (``ros2 param set``, validated); the other parameters are read-only.
"""

from __future__ import annotations

import sys

from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter
from std_msgs.msg import Float64MultiArray

from evorbc_ros.executor import NO_PRIMITIVE_REASON
from evorbc_ros.laser import InputError
from evorbc_ros.nodes.common import (
    RELIABLE,
    StartupError,
    declare,
    finite_parameter,
    finite_problem,
    logged_startup,
    now_seconds,
    robot_named,
    run_node,
)
from evorbc_ros.robots import registry
from evorbc_ros.robots.hexapod import SERVO_RATE
from evorbc_ros.robots.registry import DEFAULT_ROBOT, RobotError


class PrimitiveExecutorNode(Node):
    """Publishes commands at 10 Hz and stops the robot when inputs go stale."""

    def __init__(self, **kwargs) -> None:
        super().__init__("primitive_executor", **kwargs)
        with logged_startup(self):
            robot = declare(
                self, "robot", DEFAULT_ROBOT, "robot type (a registered robot, e.g. 4ws-5)"
            )
            spec = robot_named(robot)
            self.wheel_radius = finite_parameter(
                self,
                "wheel_radius",
                spec.node_default("wheel_radius", 0.02),
                "wheel radius (m), for wheel velocities; applied live",
                positive=True,
                live=True,
            )
            self.period = finite_parameter(self, "period", 0.1, "command period (s)", positive=True)
            stale = finite_parameter(
                self,
                "stale_timeout",
                0.3,
                "stop when an input is older than this (s)",
                positive=True,
            )
            self.zero_before_primitive = declare(
                self,
                "zero_before_first_primitive",
                False,
                "4WS: send zero commands every period until the first primitive arrives "
                "(false: send nothing, so another node may drive the robot)",
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
            declare(
                self,
                "steering_topic",
                "steering_position_controller/commands",
                "steering angles (Float64MultiArray, rad)",
            )
            declare(
                self,
                "wheel_topic",
                "wheel_velocity_controller/commands",
                "wheel velocities (Float64MultiArray, rad/s)",
            )
            declare(
                self,
                "trajectory_topic",
                "joint_trajectory_controller/joint_trajectory",
                "hexapod joint targets (JointTrajectory, rad)",
            )
            try:
                interface = spec.load("commands")
            except RobotError as e:
                raise StartupError(str(e)) from None
            # A joint-trajectory interface says its robot's own rate (a legged robot's
            # physics rate); the wheel interfaces do not use it.
            default_rate = getattr(interface, "default_rate", None)
            finite_parameter(
                self,
                "trajectory_rate",
                default_rate(spec) if default_rate else SERVO_RATE,
                "legged robots' trajectory points per second (default: the robot's physics rate)",
                positive=True,
            )
        self.robot = robot
        self.parameter_names = list(spec.parameter_names)
        self.primitive_topic = primitive_topic
        # The robot's own command interface: the executor logic and its publishers.
        self.commands = interface(self, spec, list(inputs), stale)
        self.logic = self.commands.logic
        self.subs = [
            self.create_subscription(
                Float64MultiArray, primitive_topic, self.on_primitive_message, RELIABLE
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
        self.primitive_seen = False  # nothing is published before the arbitrator speaks
        self.add_on_set_parameters_callback(self.on_set_parameters)
        self.timer = self.create_timer(self.period, self.on_timer)

    def on_set_parameters(self, params: list[Parameter]) -> SetParametersResult:
        """Apply a valid ``wheel_radius`` at once (the others are read-only)."""
        for p in params:
            if p.name == "wheel_radius":
                problem = finite_problem(p.name, p.value, positive=True)
                if problem:
                    return SetParametersResult(successful=False, reason=problem)
        for p in params:
            if p.name == "wheel_radius":
                self.wheel_radius = float(p.value)
        return SetParametersResult(successful=True)

    def on_primitive_message(self, msg: Float64MultiArray) -> None:
        """Refuse a primitive labelled for another robot; otherwise run it."""
        problem = primitive_mismatch(msg, self.robot, self.parameter_names)
        if problem:
            self.get_logger().error(
                f"{self.primitive_topic}: refused {problem}", throttle_duration_sec=2.0
            )
            return
        self.primitive_seen = True
        self.on_primitive(msg)

    def on_primitive(self, msg: Float64MultiArray) -> None:
        """Run a new primitive at once; an empty message stops the robot at once."""
        now = now_seconds(self)
        try:
            self.logic.on_primitive(msg.data, now)
        except InputError as e:
            self.get_logger().warning(
                f"{self.primitive_topic}: skipped: {e}", throttle_duration_sec=2.0
            )
            return
        command = self.logic.command(now)
        self.publish(command, now, halt=self.logic.halted)

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
        if not (self.primitive_seen or self.zero_before_primitive):
            return  # never commanded: leave the controllers to whoever drives them (teleop)
        now = now_seconds(self)
        command = self.logic.command(now)
        # A stop for stale inputs is repeated every tick. The arbitrator's own "no
        # primitive" stop was sent at once and is kept alive like a running primitive, so
        # in lockstep every command still answers one arbitrator decision.
        repeat = command.stopped and command.reason != NO_PRIMITIVE_REASON
        if repeat or now - self.last_publish > 1.5 * self.period:
            self.publish(command, now)

    def publish(self, command, now: float, halt: bool = False) -> None:
        """Send one command through the robot's command interface.

        Args:
            halt: the command answers the arbitrator's "no primitive".

        """
        if command.stopped and command.reason != self.stopped_reason:
            self.get_logger().warning(f"stopping the robot: {command.reason}")
        elif not command.stopped and self.stopped_reason:
            self.get_logger().info("inputs are back: running the primitive again")
        self.stopped_reason = command.reason if command.stopped else ""
        self.commands.publish(command, halt)
        self.last_publish = now


def primitive_mismatch(msg: Float64MultiArray, robot: str, names: list[str]) -> str:
    """Why a labelled primitive is not for ``robot`` ("" if it is, or carries no label).

    The arbitrator labels the genes with its repertoire's parameter names. Two robots can
    have as many genes and different meanings (2ws-3 and 4ws-3), so the count alone
    would not catch a controller for another robot.
    """
    label = msg.layout.dim[0].label if msg.layout.dim else ""
    got = label.split(",") if label else []
    if not got or not msg.data or got == names:
        return ""
    other = next((r.name for r in registry.robots() if list(r.parameter_names) == got), None)

    def listed(n: list[str]) -> str:
        return ", ".join(n) if len(n) <= 6 else f"{len(n)} parameters"

    return (
        f"{'a ' + other if other else 'a'} primitive ({listed(got)}): this executor drives "
        f"a {robot} ({listed(names)}); is the arbitrator for another robot?"
    )


def main(argv=None) -> int:
    """Run the node."""
    return run_node(PrimitiveExecutorNode, argv)


if __name__ == "__main__":
    sys.exit(main())
