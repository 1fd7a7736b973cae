"""The bridge adapter of a differential-drive robot: body twists on ``cmd_vel`` in.

A differential-drive base takes a body twist on ``cmd_vel``: geometry_msgs/TwistStamped
(ros2_control's diff_drive_controller from Jazzy on) or, with ``twist_stamped: false``,
geometry_msgs/Twist (a TurtleBot3's base, older stacks), as the executor publishes it
(:mod:`evorbc_ros.nodes.twist_commands`) with the same parameter. The twist, as received,
is the command of the compiled motion model, so a lockstep episode equals the offline one
bit for bit (docs/design.md section 19). The adapter interface is in docs/your-robot.md.
"""

from __future__ import annotations

import math

import numpy as np
from geometry_msgs.msg import Twist, TwistStamped
from sensor_msgs.msg import JointState

from evorbc_ros.nodes.common import RELIABLE, robot_named
from evorbc_ros.robots.diff_drive import WHEEL_JOINTS
from sim_bridge.bridge_robots import KinematicBridge
from sim_bridge.diff_drive.world import DiffDriveWorld


class DiffDriveBridge(KinematicBridge):
    """A differential-drive robot: a body twist in, kinematic motion model."""

    #: The command the lockstep loop waits for each cycle.
    command_keys = ("cmd_vel",)

    def __init__(self, node, robot: str, maze, pose, episode_time: float, gui: bool) -> None:
        self.node = node
        self.robot_name = robot
        laser = self._laser(node)
        self.topic = "cmd_vel"
        self.stamped = node.params["twist_stamped"]
        self.world = DiffDriveWorld(maze, robot, pose, episode_time, laser, gui)
        self.wheel_radius = robot_named(robot).model.wheel_radius  # m, for joint states
        self.command = np.zeros(2)  # (v m/s, omega rad/s): stand still until told

    @property
    def name(self) -> str:
        """The robot's name."""
        return self.robot_name

    def subscribe(self, on_command) -> list:
        """The twist subscription; ``on_command("cmd_vel")`` after a valid twist is stored."""
        kind = TwistStamped if self.stamped else Twist
        return [
            self.node.create_subscription(
                kind, self.topic, lambda m: self._store(m, on_command), RELIABLE
            )
        ]

    def _store(self, msg: Twist | TwistStamped, on_command) -> None:
        twist = msg.twist if self.stamped else msg
        values = (twist.linear.x, twist.angular.z)
        if not all(math.isfinite(v) for v in values):
            self.node.get_logger().warning(
                f"{self.topic}: twist must be finite, got linear.x {values[0]}, angular.z "
                f"{values[1]}; ignored",
                throttle_duration_sec=2.0,
            )
            return
        # A differential-drive base cannot move sideways, roll or pitch: like
        # diff_drive_controller it reads linear.x and angular.z only.
        self.command = np.array(values, dtype=np.float64)
        on_command("cmd_vel")

    def advance(self) -> None:
        """One control period with the latest twist."""
        self.world.step(self.command, self.wheel_radius)

    def twist(self) -> tuple[float, float]:
        """Forward speed (m/s) and yaw rate (rad/s) in the body frame."""
        v, omega = self.world.twist
        return float(v), float(omega)

    def joint_state(self, msg: JointState) -> None:
        """Fill the two wheels' names, angles (rad) and velocities (rad/s)."""
        msg.name = list(WHEEL_JOINTS)
        msg.position = self.world.wheel_angle.tolist()
        msg.velocity = [w / self.wheel_radius for w in self.world.wheel_speeds]
