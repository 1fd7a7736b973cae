"""The robot-specific half of the simulation bridge: a 4WS robot, or a legged one.

A differential-drive robot's is :mod:`sim_bridge.diff_drive.bridge`. The legged adapters
are :class:`HexapodBridge` and, for any legged robot from a settings file,
:mod:`sim_bridge.legged.bridge`; both are :class:`TrajectoryBridge`. Each adapter
owns its simulated world, subscribes its command topics, fills the joint states and laser
scan, and steps the world with the commands of the cycle. The bridge node
(:mod:`sim_bridge.bridge_node`) runs the loop, clock, odometry and result the same way for
every robot, and finds a robot's adapter by its family (:mod:`sim_bridge.robots.adapters`;
docs/your-robot.md gives the adapter's interface).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray
from trajectory_msgs.msg import JointTrajectory

from evorbc_ros.nodes.common import RELIABLE, StartupError, robot_named
from evorbc_ros.robots.four_ws import WHEEL_NAMES
from evorbc_ros.robots.hexapod import JOINT_NAMES
from evorbc_ros.robots.registry import RobotError
from sim_bridge.hexapod.maze_world import HexapodMazeWorld
from sim_bridge.robots.adapters import bridge_class
from sim_bridge.world import LaserConfig, SimWorld

STEERING_JOINTS = [f"{w}_steering_joint" for w in WHEEL_NAMES]
WHEEL_JOINTS = [f"{w}_wheel_joint" for w in WHEEL_NAMES]


@dataclass(frozen=True)
class ScanGeometry:
    """What a LaserScan message says about the beams (rad, m)."""

    angle_min: float
    angle_max: float
    angle_increment: float
    range_min: float
    range_max: float


class KinematicBridge:
    """What the kinematic robots' adapters share: the laser, the scan and a planar pose."""

    def _laser(self, node) -> LaserConfig:
        """The simulated scanner from the node's parameters; sets :attr:`scan_geometry`."""
        laser = LaserConfig(beams=node.params["laser_beams"], range_max=node.params["laser_range"])
        self.scan_geometry = ScanGeometry(
            laser.angle_min,
            laser.angle_min + laser.increment * (laser.beams - 1),
            laser.increment,
            laser.range_min,
            laser.range_max,
        )
        return laser

    def scan(self) -> np.ndarray:
        """Laser ranges (m)."""
        return self.world.scan()

    def body_pose(self) -> tuple[tuple, tuple]:
        """Position (m) and orientation (xyzw) of ``base_link`` in ``odom``: planar."""
        x, y, h = self.world.pose
        return (x, y, 0.0), (0.0, 0.0, math.sin(0.5 * h), math.cos(0.5 * h))


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
        self.world = SimWorld(maze, robot, pose, episode_time, laser, gui)
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


class TrajectoryBridge:
    """A legged robot: a JointTrajectory of targets per control period, PyBullet dynamics.

    Subclasses give :meth:`make_world` (a :class:`~sim_bridge.legged.maze_world.LeggedMazeWorld`)
    and :attr:`joint_names` (the world's joints, in its command order).
    """

    command_keys = ("trajectory",)
    joint_names: tuple[str, ...] = ()

    def make_world(self, robot: str, maze, pose, episode_time: float, gui: bool):
        """The simulated robot in ``maze`` at ``pose`` (None: the maze's nominal start)."""
        raise NotImplementedError

    def __init__(self, node, robot: str, maze, pose, episode_time: float, gui: bool) -> None:
        self.node = node
        self.name = robot
        self.topic = "joint_trajectory_controller/joint_trajectory"
        self.world = self.make_world(robot, maze, pose, episode_time, gui)
        # The latest trajectory resampled at the physics steps, and the next step to run:
        # a trajectory longer than a period keeps the legs walking until the next arrives.
        self.trajectory: np.ndarray | None = None
        self.cursor = 0
        s = self.world.scanner
        self.scan_geometry = ScanGeometry(
            s.angle_min, s.angle_max, s.angle_increment, s.range_min, s.range_max
        )
        self.index = {name: k for k, name in enumerate(self.joint_names)}
        self.dt = self.world.physics.dt

    def subscribe(self, on_command) -> list:
        """The trajectory subscription; ``on_command("trajectory")`` once one is stored."""
        return [
            self.node.create_subscription(
                JointTrajectory, self.topic, lambda m: self._store(m, on_command), RELIABLE
            )
        ]

    def _store(self, msg: JointTrajectory, on_command) -> None:
        problem, rows = self._targets(msg)
        if problem:
            self.node.get_logger().warning(
                f"{self.topic}: {problem}; ignored", throttle_duration_sec=2.0
            )
            return
        # An empty trajectory is ROS's "stop and hold where you are": the servos keep their
        # last targets (what the executor sends when told to stop before any target).
        self.trajectory, self.cursor = (rows if len(rows) else None), 0
        on_command("trajectory")

    def _targets(self, msg: JointTrajectory) -> tuple[str, np.ndarray | None]:
        """``(problem, (steps, joints) targets)``: points resampled at the physics steps."""
        names, joints = list(msg.joint_names), self.joint_names
        n = len(joints)
        if sorted(names) != sorted(joints):
            return f"expected the {n} joints {', '.join(joints)}, got {names}", None
        if not msg.points:
            return "", np.empty((0, n))  # "stop and hold where you are"
        order = [names.index(j) for j in joints]
        times, rows = [], []
        for point in msg.points:
            q = np.asarray(point.positions, dtype=np.float64)
            if q.shape != (n,) or not np.all(np.isfinite(q)):
                return f"every point needs {n} finite positions", None
            rows.append(q[order])
            times.append(point.time_from_start.sec + 1e-9 * point.time_from_start.nanosec)
        times = np.asarray(times)
        if np.any(np.diff(times) <= 0):
            return "point times must increase", None
        # Zero-order hold: physics step k (at k * dt) tracks the last point due by then,
        # over the span of the trajectory (times in s from receipt), but never past the
        # episode: a point stamped hours ahead would otherwise allocate that many steps.
        steps = math.ceil(times[-1] / self.dt - 1e-6) + 1  # through the last point's step
        steps = min(steps, math.ceil(self.world.episode_time / self.dt) + 1)
        due = np.searchsorted(times, np.arange(steps) * self.dt + 1e-6, side="right") - 1
        return "", np.asarray(rows)[np.clip(due, 0, None)]

    def advance(self) -> None:
        """One control period along the latest trajectory (its last target held after it)."""
        rows = None
        if self.trajectory is not None and self.cursor < len(self.trajectory):
            rows = self.trajectory[self.cursor : self.cursor + self.world.steps_per_period]
            self.cursor += self.world.steps_per_period
        self.world.step(rows)

    def scan(self) -> np.ndarray:
        """Laser ranges (m), float32 as LaserScan carries them."""
        return self.world.scan()

    def twist(self) -> tuple[float, float]:
        """Forward speed (m/s) and yaw rate (rad/s) of the body, body frame."""
        _, _, (vx, vy, _), (_, _, wz) = self.world.sim.base_state()
        heading = self.world.pose[2]
        return vx * math.cos(heading) + vy * math.sin(heading), wz

    def body_pose(self) -> tuple[tuple, tuple]:
        """Position (m) and full 3D orientation (xyzw) of the body, as PyBullet has them.

        The radar node takes the yaw from this quaternion exactly as offline evolution
        takes it from PyBullet's, so the goal bearing is bit-identical.
        """
        pos, orn, _, _ = self.world.sim.base_state()
        return tuple(pos), tuple(orn)

    def joint_state(self, msg: JointState) -> None:
        """Fill the joints' names, angles (rad), velocities (rad/s) and torques (N m)."""
        q, v, tau = self.world.sim.joint_states()
        msg.name = list(self.joint_names)
        msg.position = q.tolist()
        msg.velocity = v.tolist()
        msg.effort = tau.tolist()


class HexapodBridge(TrajectoryBridge):
    """The hexapod: its 18 joints, the maze world of :mod:`sim_bridge.hexapod.maze_world`."""

    joint_names = JOINT_NAMES

    def make_world(self, robot: str, maze, pose, episode_time: float, gui: bool):
        """The hexapod in ``maze``."""
        return HexapodMazeWorld(maze, pose, episode_time, gui)


def bridge_robot_class(robot: str) -> type:
    """The bridge adapter class of ``robot``'s family (:mod:`sim_bridge.robots.adapters`).

    Raises:
        StartupError: an unknown robot (listing the known ones), or an adapter that cannot
            be imported.
    """
    try:
        return bridge_class(robot_named(robot))
    except RobotError as e:
        raise StartupError(str(e)) from None
