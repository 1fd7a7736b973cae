"""``primitive_executor``: runs the current primitive on the robot's controllers (lifecycle).

Subscribes ``evorbc/primitive`` (genes) and, to know that the sensors are alive, the
``watched_inputs`` (``evorbc/rangefinders`` and ``evorbc/goal_sectors``). What it publishes
is the robot's command interface, named by its registration
(:mod:`evorbc_ros.robots.registry`), following ros2_control's command conventions
(reliable):

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
* differential drive (:mod:`evorbc_ros.nodes.twist_commands`): ``cmd_vel``,
  geometry_msgs/TwistStamped (Twist with ``twist_stamped: false``).

A command goes out at once for every new primitive, and again whenever 1.5 periods
(0.15 s) pass without one, so the controllers keep receiving 10 Hz commands (not under a
lockstep simulation, ``lockstep: true``, where every command answers one primitive). If
the primitive or a sensor input is older than ``stale_timeout`` (0.3 s) the executor
stops the robot within one cycle (4WS: zero wheel speed, steering held; hexapod: every
joint held at its last target), and resumes when they return.

Before the first message on ``evorbc/primitive`` nothing is published, so the executor
does not fight another node (teleop) on the same controllers; ``zero_before_first_primitive``
makes a 4WS executor send zero commands every period instead. A primitive labelled with
another robot's parameter names is refused and logged as an error. ``wheel_radius`` is
applied live (``ros2 param set``, validated). Configure loads the robot and its command
interface; activate starts commanding (at once for a primitive that came meanwhile);
deactivate stops the robot (:mod:`evorbc_ros.nodes.managed`).
"""

from __future__ import annotations

import sys

from std_msgs.msg import Float64MultiArray

from evorbc_ros.executor import NO_PRIMITIVE_REASON
from evorbc_ros.health import ERROR, WARN, Health, Meter, report_input, report_skipped
from evorbc_ros.laser import InputError
from evorbc_ros.nodes.common import StartupError, now_seconds, robot_named, run_node
from evorbc_ros.nodes.managed import ManagedNode
from evorbc_ros.robots import registry
from evorbc_ros.robots.registry import RobotError

#: Why the robot stands after a deactivation.
DEACTIVATED = "the executor was deactivated"


class PrimitiveExecutorNode(ManagedNode):
    """Publishes commands at 10 Hz and stops the robot when inputs go stale."""

    NAME = "primitive_executor"

    def __init__(self, **kwargs) -> None:
        self.spec = None
        self.commands = None
        self.wheel_radius = 0.0
        self.primitive, self.sent, self.skipped, self.refused = Meter(), Meter(), Meter(), Meter()
        self.inputs: dict[str, Meter] = {}
        super().__init__(**kwargs)

    # -- lifecycle ----------------------------------------------------------------------

    def configure(self, p: dict) -> None:
        """The robot, its command interface (publishers), subscriptions and the timer."""
        self.spec = robot_named(p["robot"])
        self.diagnostics.hardware_id = self.spec.name
        self.apply_live("wheel_radius", p["wheel_radius"])
        self.period, self.stale_timeout = p["period"], p["stale_timeout"]
        self.zero_before_primitive = p["zero_before_first_primitive"]
        # Under a lockstep simulation the bridge steps the world once per set of commands:
        # a command of the executor's own would be taken for the next cycle's. Under load
        # the executor can handle a primitive before the same cycle's /clock, so by its
        # clock the primitive came a cycle early and the keep-alive fired a cycle later
        # (docs/design.md section 9, "Lockstep under load").
        self.lockstep = p["lockstep"]
        inputs = [f"evorbc/{name}" for name in p["watched_inputs"]]
        try:
            interface = self.spec.load("commands")
        except RobotError as e:
            raise StartupError(str(e)) from None
        self.commands = interface(self, self.spec, inputs, self.stale_timeout)
        self.logic = self.commands.logic
        self.parameter_names = list(self.spec.parameter_names)
        self.inputs = {t: Meter() for t in inputs}
        self.subscription(Float64MultiArray, "evorbc/primitive", self.on_primitive_message)
        for t in inputs:
            self.subscription(Float64MultiArray, t, lambda msg, t=t: self.on_input(t))
        self.last_publish = -float("inf")
        self.stopped_reason = ""
        self.primitive_seen = False  # nothing is published before the arbitrator speaks
        self.timer(self.period, self.on_timer)

    def activate(self) -> None:
        """Command the primitive that came while inactive, if any (or stop if it is old)."""
        if self.primitive_seen:
            now = now_seconds(self)
            self.publish(self.logic.command(now), now, halt=self.logic.halted)

    def deactivate(self) -> None:
        """Stop the robot (if the executor was commanding it) before the publishers stop."""
        if not (self.primitive_seen or self.zero_before_primitive):
            return  # never commanded: leave the controllers to whoever drives them
        now = now_seconds(self)
        self.logic.on_primitive([], now)  # the arbitrator's "stop now", until a new one
        command = self.logic.command(now)
        self.commands.publish(command, halt=True)
        self.get_logger().info(f"deactivated: robot stopped ({DEACTIVATED})")

    def release(self) -> None:
        """Drop the command interface, subscriptions and timer."""
        self.release_made()
        self.commands = None

    def apply_live(self, name: str, value) -> None:
        """``wheel_radius`` (m), 0 meaning the robot's own."""
        if name == "wheel_radius" and self.spec is not None:
            self.wheel_radius = value or self.spec.node_default("wheel_radius", 0.02)

    # -- callbacks ----------------------------------------------------------------------

    def on_primitive_message(self, msg: Float64MultiArray) -> None:
        """Refuse a primitive labelled for another robot; otherwise run it."""
        now = now_seconds(self)
        problem = primitive_mismatch(msg, self.spec.name, self.parameter_names)
        if problem:
            self.refused.tick(now)
            self.get_logger().error(
                f"evorbc/primitive: refused {problem}", throttle_duration_sec=2.0
            )
            return
        try:
            self.logic.on_primitive(msg.data, now)
        except InputError as e:
            self.skipped.tick(now)
            self.get_logger().warning(f"evorbc/primitive: skipped: {e}", throttle_duration_sec=2.0)
            return
        self.primitive.tick(now)
        self.primitive_seen = True
        if self.active:
            self.publish(self.logic.command(now), now, halt=self.logic.halted)

    def on_input(self, topic: str) -> None:
        """Note a sensor input; if the robot was stopped for it, run again at once."""
        now = now_seconds(self)
        self.inputs[topic].tick(now)
        self.logic.on_input(topic, now)
        if self.stopped_reason and self.active and not self.lockstep:
            command = self.logic.command(now)
            if not command.stopped:
                self.publish(command, now)

    def on_timer(self) -> None:
        """Stop on stale inputs; otherwise keep commands flowing at least every period."""
        if not self.active or not (self.primitive_seen or self.zero_before_primitive):
            return  # never commanded: leave the controllers to whoever drives them (teleop)
        if self.lockstep:
            return  # every command answers a primitive (configure says why)
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
        self.sent.tick(now)
        self.last_publish = now

    def report(self, h: Health, now: float) -> None:
        """Inputs, commands per second, why the robot stands, refused primitives."""
        report_input(h, "primitive", self.primitive, now, self.stale_timeout)
        for topic, meter in self.inputs.items():
            report_input(h, topic, meter, now, self.stale_timeout)
        report_skipped(h, "primitive", self.skipped, now)
        new_refused = self.refused.new_since_report()
        self.refused.rate(now)
        h.add("commands per second", self.sent.rate(now))
        h.add("refused primitives", self.refused.count)
        h.add("robot", f"stopped: {self.stopped_reason}" if self.stopped_reason else "running")
        if self.stopped_reason:
            h.worse(WARN, f"robot stopped: {self.stopped_reason}")
        if new_refused:
            h.worse(ERROR, f"{new_refused} primitive(s) for another robot refused")


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
