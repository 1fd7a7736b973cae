"""``primitive_executor``: runs the current primitive on the robot's controllers.

Subscribes ``evorbc/primitive`` (genes) and, to know that the sensors are alive,
``evorbc/rangefinders`` and ``evorbc/goal_sectors``. Publishes, following ros2_control's
command conventions (reliable):

* 4WS robots, forward command controllers (std_msgs/Float64MultiArray):
  ``steering_position_controller/commands``, the four steering angles (rad; fl, fr, rl,
  rr), and ``wheel_velocity_controller/commands``, the four wheel velocities (rad/s).
* the hexapod, joint_trajectory_controller (trajectory_msgs/JointTrajectory):
  ``joint_trajectory_controller/joint_trajectory``, the 18 joints' targets (rad) for the
  next ``stale_timeout`` s, one point per physics step (``trajectory_rate``, 50 Hz), see
  :mod:`evorbc_ros.hexapod_executor`.

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

from builtin_interfaces.msg import Duration
from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter
from std_msgs.msg import Float64MultiArray
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from evorbc_ros.executor import NO_PRIMITIVE_REASON, PrimitiveExecutor, WheelCommand
from evorbc_ros.hexapod_executor import HexapodExecutor, JointTargets
from evorbc_ros.laser import InputError
from evorbc_ros.nodes.common import (
    RELIABLE,
    ROBOTS,
    StartupError,
    declare,
    finite_parameter,
    finite_problem,
    logged_startup,
    now_seconds,
    run_node,
    vector_message,
)
from evorbc_ros.robots.four_ws import ROBOT_TYPES, WHEEL_NAMES, FourWSGeometry
from evorbc_ros.robots.hexapod import HEXAPOD, JOINT_NAMES, SERVO_RATE, parameter_specs


class PrimitiveExecutorNode(Node):
    """Publishes commands at 10 Hz and stops the robot when inputs go stale."""

    def __init__(self, **kwargs) -> None:
        super().__init__("primitive_executor", **kwargs)
        with logged_startup(self):
            robot = declare(self, "robot", "4ws-5", f"robot type: {', '.join(ROBOTS)}")
            if robot not in ROBOTS:
                raise StartupError(
                    f"parameter robot must be one of {', '.join(ROBOTS)}, got {robot!r}"
                )
            self.wheel_radius = finite_parameter(
                self,
                "wheel_radius",
                0.02,
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
            trajectory_topic = declare(
                self,
                "trajectory_topic",
                "joint_trajectory_controller/joint_trajectory",
                "hexapod joint targets (JointTrajectory, rad)",
            )
            rate = finite_parameter(
                self,
                "trajectory_rate",
                SERVO_RATE,
                "hexapod trajectory points per second (the simulation's physics rate)",
                positive=True,
            )
        self.robot = robot
        self.parameter_names = robot_parameter_names(robot)
        self.primitive_topic = primitive_topic
        if robot == HEXAPOD:
            self.logic = HexapodExecutor(list(inputs), stale, rate)
            self.trajectory_pub = self.create_publisher(JointTrajectory, trajectory_topic, RELIABLE)
        else:
            geometry = FourWSGeometry()
            self.logic = PrimitiveExecutor(ROBOT_TYPES[robot], geometry, list(inputs), stale)
            self.steering_pub = self.create_publisher(Float64MultiArray, steering_topic, RELIABLE)
            self.wheel_pub = self.create_publisher(Float64MultiArray, wheel_topic, RELIABLE)
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
        if self.logic.halted and isinstance(command, JointTargets) and not len(command.positions):
            # No target sent yet, so none to hold: an empty trajectory is ROS's "stop and
            # hold where you are" for a joint trajectory controller.
            self.trajectory_pub.publish(JointTrajectory(joint_names=list(JOINT_NAMES)))
        self.publish(command, now)

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

    def publish(self, command: WheelCommand | JointTargets, now: float) -> None:
        """Send one command to the robot's controllers."""
        if command.stopped and command.reason != self.stopped_reason:
            self.get_logger().warning(f"stopping the robot: {command.reason}")
        elif not command.stopped and self.stopped_reason:
            self.get_logger().info("inputs are back: running the primitive again")
        self.stopped_reason = command.reason if command.stopped else ""
        if isinstance(command, JointTargets):
            if len(command.positions):  # none before the first primitive: nothing to hold
                self.trajectory_pub.publish(trajectory_message(command))
        else:
            self.publish_wheels(command)
        self.last_publish = now

    def publish_wheels(self, command: WheelCommand) -> None:
        """Steering angles and wheel velocities for a 4WS robot's two controllers."""
        self.steering_pub.publish(
            vector_message(command.steering, [f"{w}_steering" for w in WHEEL_NAMES])
        )
        self.wheel_pub.publish(
            vector_message(
                command.wheel_velocities(self.wheel_radius), [f"{w}_wheel" for w in WHEEL_NAMES]
            )
        )


def robot_parameter_names(robot: str) -> list[str]:
    """The names of ``robot``'s primitive parameters, as the arbitrator labels its genes."""
    if robot == HEXAPOD:
        return [p.name for p in parameter_specs()]
    return list(ROBOT_TYPES[robot].parameter_names)


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
    other = next((r for r in ROBOTS if robot_parameter_names(r) == got), None)

    def listed(n: list[str]) -> str:
        return ", ".join(n) if len(n) <= 6 else f"{len(n)} parameters"

    return (
        f"{'a ' + other if other else 'a'} primitive ({listed(got)}): this executor drives "
        f"a {robot} ({listed(names)}); is the arbitrator for another robot?"
    )


def trajectory_message(command: JointTargets) -> JointTrajectory:
    """A JointTrajectory with point ``k`` at ``k * dt`` s (header stamp 0: start on receipt)."""
    msg = JointTrajectory()
    msg.joint_names = list(JOINT_NAMES)
    points = []
    for k, row in enumerate(command.positions):
        ns = round(k * command.dt * 1e9)
        points.append(
            JointTrajectoryPoint(
                positions=row.tolist(),
                time_from_start=Duration(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000),
            )
        )
    msg.points = points
    return msg


def main(argv=None) -> int:
    """Run the node."""
    return run_node(PrimitiveExecutorNode, argv)


if __name__ == "__main__":
    sys.exit(main())
