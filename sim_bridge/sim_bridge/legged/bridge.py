"""The simulation bridge's adapter for a legged robot: joint trajectories in, PyBullet dynamics.

:class:`TrajectoryBridge` is every legged robot's adapter (JointTrajectory commands
resampled at the physics steps, zero-order hold, LaserScan, Odometry and JointState);
:class:`LeggedBridge` runs it over the maze world of the robot its registration's settings
file describes, with the laser of its registration's sensor layout (the ``legged``
family's ``bridge``), and :class:`~sim_bridge.hexapod.bridge.HexapodBridge` over the
hexapod's.
"""

from __future__ import annotations

import contextlib
import math

import numpy as np
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory

from evorbc_ros.nodes.common import RELIABLE
from evorbc_ros.robots import registry
from sim_bridge.bridge_robots import ScanGeometry
from sim_bridge.legged.maze_world import LeggedMazeWorld
from sim_bridge.legged.perturbed import perturbed_sim
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.legged.settings import load_robot_settings
from sim_bridge.perturbation import WorldDraw


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

    def perturb(self, draw: WorldDraw) -> tuple[str, ...]:
        """Apply row 0 of a perturbation set's ``draw`` for the run; the quantities applied.

        The robot's dynamics: friction, mass, payload, servos and damage
        (:func:`~sim_bridge.legged.perturbed.perturbed_sim`, left in force until the
        world closes); the rest of a set is the offline episodes' alone.
        """
        stack = contextlib.ExitStack()
        stack.enter_context(perturbed_sim(self.world.sim, draw.row(0)))
        close = self.world.close

        def put_back_and_close() -> None:
            stack.close()  # while PyBullet is still connected
            close()

        self.world.close = put_back_and_close
        applied = ("friction", "body_mass", "payload", "servo_strength", "servo_speed")
        if draw.damage is not None and draw.damage.spec.family == "legged":
            applied += (draw.damage.spec.kind,)
        return applied

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


class LeggedBridge(TrajectoryBridge):
    """A legged robot from settings, stepped by joint-target trajectories."""

    def make_world(self, robot: str, maze, pose, episode_time: float, gui: bool):
        """The robot of ``robot``'s settings file in ``maze``, with its laser."""
        spec = registry.lookup(robot)
        settings = load_robot_settings(spec.model.path())
        self.joint_names = settings.gait.joint_names

        def sim(walls, gui):
            return LeggedSim(settings, walls, gui=gui)

        return LeggedMazeWorld(maze, sim, str(spec.sensors_file()), pose, episode_time, gui)
