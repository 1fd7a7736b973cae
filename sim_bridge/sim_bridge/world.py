"""The simulated world of the bridge: a kinematic robot in a maze, one control step at a time.

The robot moves by its family's compiled motion model, the one offline evolution steps
(:class:`~sim_bridge.four_ws.world.FourWSWorld`,
:class:`~sim_bridge.diff_drive.world.DiffDriveWorld`); wall contact and the laser's rays are
computed by PyBullet (:class:`sim_bridge.pybullet_world.PyBulletMaze`). The contact rule is
the offline one: if the footprint would overlap a wall after a step, the position stays
and the heading change is kept. The episode's status (:class:`EpisodeStatus`) is every
robot's, the legged ones' too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim_bridge.maze import Maze
from sim_bridge.pybullet_world import PyBulletMaze

#: Columns of a kinematic robot's state row that every motion model shares (m, m, rad;
#: :mod:`sim_bridge.four_ws.motion`, :mod:`sim_bridge.diff_drive.motion`).
X, Y, HEADING = 0, 1, 2


@dataclass(frozen=True)
class LaserConfig:
    """The simulated scanner at the body centre: evenly spaced beams, REP 103 angles."""

    beams: int = 360
    angle_min: float = -math.pi  # rad, body frame
    angle_max: float = math.pi  # rad; the last beam is one increment short of it
    range_max: float = 2.0  # m
    range_min: float = 0.0  # m

    @property
    def increment(self) -> float:
        """Angle between beams (rad)."""
        return (self.angle_max - self.angle_min) / self.beams

    def angles(self) -> np.ndarray:
        """Beam directions in the body frame (rad)."""
        return self.angle_min + self.increment * np.arange(self.beams)


@dataclass(frozen=True)
class EpisodeStatus:
    """Where an episode stands (eq. 5 fitness once it is over)."""

    time: float  # s simulated
    reached: bool
    distance: float  # m, robot centre to target
    initial_distance: float  # m
    episode_time: float  # s, T of eq. 5
    fell: bool = False  # the hexapod's body tilted past 90 deg: the episode ends there

    @property
    def done(self) -> bool:
        """Target reached, robot fallen over, or time up."""
        return self.reached or self.fell or self.time >= self.episode_time - 1e-9

    @property
    def fitness(self) -> float:
        """Eq. 5: 2 - t/T if reached, else 1 - d_final / d_initial."""
        if self.reached:
            return 2.0 - self.time / self.episode_time
        return 1.0 - self.distance / self.initial_distance if self.initial_distance > 0 else 0.0


class KinematicWorld:
    """A kinematic robot in a maze, stepped by its motion model's commands.

    A family's world gives the motion model (:meth:`_model`, :meth:`_move`,
    :meth:`_roll_wheels`): :class:`~sim_bridge.four_ws.world.FourWSWorld`,
    :class:`~sim_bridge.diff_drive.world.DiffDriveWorld`.

    Args:
        maze: the maze.
        robot: a registered robot of the world's family.
        start: ``(x m, y m, heading rad)``; None: the maze's start pose.
        episode_time: s, T of eq. 5.
        laser: the simulated scanner.
        gui: open PyBullet's GUI.
        geometry: replaces the robot's body (its family's geometry class).

    """

    def __init__(
        self,
        maze: Maze,
        robot: str,
        start=None,
        episode_time=120.0,
        laser: LaserConfig = LaserConfig(),
        gui: bool = False,
        geometry=None,
    ) -> None:
        self.maze = maze
        self._model(robot, geometry)
        self.laser = laser
        self.episode_time = episode_time
        self.physics = PyBulletMaze(maze, self.geometry.footprint_radius, gui=gui)
        self.state = np.zeros((1, self.state_size))
        self.state[0, :3] = maze.start_pose if start is None else start
        self.time = 0.0
        self.cycles = 0
        # rad, integrated rotation of each wheel (joint states)
        self.wheel_angle = np.zeros(self.n_wheels)
        tx, ty = maze.target
        self.initial_distance = math.hypot(self.state[0, X] - tx, self.state[0, Y] - ty)
        self.reached = False
        # A perturbation set's draw (docs/perturbations.md): a factor on the commanded wheel
        # speed, and a 4WS robot's damaged wheel ((3,) kind, wheel, level; None: intact)
        # with the key of its per-cycle draws.
        self.speed_gain = 1.0
        self.damage: np.ndarray | None = None
        self.damage_key = 0
        self.physics.show_pose(*self.pose)

    def _model(self, robot: str, geometry) -> None:
        """Set the robot's motion model: ``geometry``, ``limits``, ``state_size``, ``n_wheels``."""
        raise NotImplementedError

    def _move(self, command: np.ndarray) -> float:
        """One control step of the motion model, no walls; the distance moved (m)."""
        raise NotImplementedError

    def _roll_wheels(self, wheel_radius: float) -> None:
        """Integrate the wheels' rotation (rad) over the step (:attr:`wheel_angle`)."""
        raise NotImplementedError

    @property
    def dt(self) -> float:
        """Control period (s)."""
        return self.limits.dt

    @property
    def pose(self) -> tuple[float, float, float]:
        """``(x m, y m, heading rad)`` in the maze frame (heading not wrapped)."""
        return float(self.state[0, X]), float(self.state[0, Y]), float(self.state[0, HEADING])

    def step(self, command: np.ndarray, wheel_radius: float = 0.02) -> float:
        """Apply a command for one control period.

        The command is the motion model's (4WS: ``(speed m/s, fl, fr, rl, rr rad)``;
        differential drive: ``(v m/s, omega rad/s)``); ``wheel_radius`` (m) turns the
        motion into wheel rotation.

        Returns:
            Distance travelled (m); 0 if the wheels fought or a wall was in the way.
        """
        x0, y0 = self.state[0, X], self.state[0, Y]
        command = np.array(command, dtype=np.float64)
        if self.speed_gain != 1.0:  # as the episode kernel scales it (docs/design.md s. 21)
            command[0] *= self.speed_gain
            if len(command) == 2:
                command[1] *= self.speed_gain
        moved = self._move(command)
        if moved > 0.0 and not self.physics.footprint_clear(self.state[0, X], self.state[0, Y]):
            self.state[0, X], self.state[0, Y] = x0, y0
            moved = 0.0
        self._roll_wheels(wheel_radius)
        self.cycles += 1
        self.time = self.cycles * self.limits.dt
        tx, ty = self.maze.target
        if math.hypot(self.state[0, X] - tx, self.state[0, Y] - ty) <= self.maze.target_radius:
            self.reached = True
        self.physics.show_pose(*self.pose)
        return moved

    def scan(self) -> np.ndarray:
        """Laser ranges (m, +inf for no return) at the current pose."""
        x, y, h = self.pose
        return self.physics.ranges(x, y, h + self.laser.angles(), self.laser.range_max)

    def status(self) -> EpisodeStatus:
        """Time, distance to the target and whether it was reached."""
        tx, ty = self.maze.target
        d = math.hypot(self.state[0, X] - tx, self.state[0, Y] - ty)
        return EpisodeStatus(self.time, self.reached, d, self.initial_distance, self.episode_time)

    def close(self) -> None:
        """Release PyBullet."""
        self.physics.close()
