"""The bridge adapter of a 4WS robot: steering angles and wheel velocities in.

A 4WS robot takes its wheel angles (rad) on ``steering_position_controller/commands`` and
its wheel velocities (rad/s) on ``wheel_velocity_controller/commands``, as ros2_control's
forward command controllers do; the bridge steps the 4WS motion model with them
(:class:`~sim_bridge.four_ws.world.FourWSWorld`). The adapter interface is in
docs/your-robot.md.
"""

from __future__ import annotations

import math

import numpy as np
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray

from evorbc_ros.nodes.common import RELIABLE, robot_named
from evorbc_ros.robots.four_ws import WHEEL_NAMES
from sim_bridge.bridge_robots import KinematicBridge
from sim_bridge.four_ws.world import FourWSWorld

STEERING_JOINTS = [f"{w}_steering_joint" for w in WHEEL_NAMES]
WHEEL_JOINTS = [f"{w}_wheel_joint" for w in WHEEL_NAMES]


class FourWSBridge(KinematicBridge):
    """A 4WS robot: steering angles and wheel velocities in, kinematic motion model."""

    #: Command topics the lockstep loop waits for each cycle (parameter names).
    command_keys = ("steering", "wheel")

    def __init__(self, node, robot: str, maze, pose, episode_time: float, gui: bool) -> None:
        self.node = node
        self.wheel_radius = node.params["wheel_radius"] or robot_named(robot).node_default(
            "wheel_radius", 0.02
        )
        laser = self._laser(node)
        self.topics = {
            "steering": "steering_position_controller/commands",
            "wheel": "wheel_velocity_controller/commands",
        }
        self.world = FourWSWorld(maze, robot, pose, episode_time, laser, gui)
        self.commands: dict[str, np.ndarray | None] = {"steering": None, "wheel": None}

    @property
    def name(self) -> str:
        """Robot type."""
        return self.world.type.name

    def subscribe(self, on_command) -> list:
        """Subscriptions calling ``on_command(key)`` after a valid command is stored."""
        return [
            self.node.create_subscription(
                Float64MultiArray, topic, lambda m, k=key: self._store(k, m, on_command), RELIABLE
            )
            for key, topic in self.topics.items()
        ]

    def _store(self, key: str, msg: Float64MultiArray, on_command) -> None:
        values = np.asarray(msg.data, dtype=np.float64)
        if values.shape != (4,) or not np.all(np.isfinite(values)):
            self.node.get_logger().warning(
                f"{self.topics[key]}: command must be 4 finite values, got {values.tolist()}; "
                "ignored",
                throttle_duration_sec=2.0,
            )
            return
        self.commands[key] = values
        on_command(key)

    def wheel_command(self) -> np.ndarray:
        """``(speed m/s, fl, fr, rl, rr rad)`` from the latest commands (stopped if none)."""
        steering = self.commands["steering"]
        wheel = self.commands["wheel"]
        if steering is None:
            steering = self.world.steering
        # fsum is exact for the executor's four equal wheel speeds, so the speed is
        # (v / r) x r, the round trip offline episodes apply (docs/design.md section 2).
        speed = 0.0 if wheel is None else math.fsum(wheel) / len(wheel) * self.wheel_radius
        return np.concatenate([[speed], steering])

    def advance(self) -> None:
        """One control period with the latest commands."""
        self.world.step(self.wheel_command(), self.wheel_radius)

    def twist(self) -> tuple[float, float]:
        """Forward speed (m/s) and yaw rate (rad/s) in the body frame."""
        return self.world.speed, 0.0

    def joint_state(self, msg: JointState) -> None:
        """Fill the joint names, positions and velocities."""
        msg.name = STEERING_JOINTS + WHEEL_JOINTS
        msg.position = [*self.world.steering.tolist(), *self.world.wheel_angle.tolist()]
        msg.velocity = [0.0] * 4 + [self.world.speed / self.wheel_radius] * 4
