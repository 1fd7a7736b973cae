"""The hexapod in a maze for the simulation bridge: stepped by joint-target trajectories.

The same simulation, scanner and episode rules as offline evolution
(:mod:`offline_evolution.maze_task.hexapod_episode`): the bridge publishes what this world
reads, the graph answers with one control period of joint targets, and :meth:`step` runs
the physics through them. With the same start pose, a lockstep run reproduces the offline
episode cycle by cycle.
"""

from __future__ import annotations

import math

import numpy as np

from evorbc_ros.config import config_dir
from evorbc_ros.robots.hexapod import HexapodGeometry
from evorbc_ros.sensors import SensorLayout
from sim_bridge.hexapod.physics import HexapodSim, PhysicsSettings
from sim_bridge.hexapod.scanner import Scanner
from sim_bridge.maze import Maze
from sim_bridge.world import EpisodeStatus

#: Body tilt (rad) at which the hexapod has fallen over: the episode ends there.
FALLEN_TILT = math.radians(90.0)

#: The laser the hexapod was evolved with (25 beams over [-90, 90] deg, 2 m).
DEFAULT_SENSORS = "sensors/hexapod.yaml"


class HexapodMazeWorld:
    """A hexapod in a maze, advanced one control period at a time."""

    def __init__(
        self,
        maze: Maze,
        start: tuple[float, float, float] | None = None,
        episode_time: float = 30.0,
        gui: bool = False,
        geometry: HexapodGeometry | None = None,
        physics: PhysicsSettings | None = None,
        sensors: str = DEFAULT_SENSORS,
    ) -> None:
        self.maze = maze
        self.geometry = geometry or HexapodGeometry()
        self.physics = physics or PhysicsSettings()
        self.episode_time = episode_time
        layout = SensorLayout.load(config_dir() / sensors)
        self.scanner = Scanner.from_layout(layout.rangefinders)
        self.sim = HexapodSim(self.geometry, self.physics, maze.boxes, gui=gui)
        self.sim.reset(*(maze.start_pose if start is None else start))
        self.steps_per_period = self.physics.steps(self.geometry.control_period)
        self.cycles = 0
        self.reached = self.fell = False
        self.initial_distance = self._distance()
        self.targets = self.sim.joint_states()[0]  # (18,) rad, held until commanded

    @property
    def dt(self) -> float:
        """Control period (s)."""
        return self.geometry.control_period

    @property
    def time(self) -> float:
        """Simulated seconds since the start (whole control periods)."""
        return self.cycles * self.dt

    @property
    def pose(self) -> tuple[float, float, float]:
        """``(x m, y m, heading rad)`` of the body in the maze frame."""
        x, y, heading, _ = self.sim.pose()
        return x, y, heading

    def _distance(self) -> float:
        x, y, _ = self.pose
        return math.hypot(x - self.maze.target[0], y - self.maze.target[1])

    def step(self, trajectory: np.ndarray | None) -> None:
        """Run one control period; physics step ``k`` tracks ``trajectory[k]``.

        Args:
            trajectory: ``(points, 18)`` joint targets (rad) one physics step apart; a
                shorter one holds its last point, ``None`` holds the last targets.

        """
        if trajectory is not None and len(trajectory):
            rows = np.asarray(trajectory, dtype=np.float64)[: self.steps_per_period]
        else:
            rows = self.targets[None, :]
        self.targets = rows[-1].copy()  # the servos hold the last target they tracked
        pad = self.steps_per_period - len(rows)
        rows = np.vstack([rows, np.repeat(rows[-1:], pad, axis=0)]) if pad > 0 else rows
        tilt, _ = self.sim.run(rows, max_tilt=FALLEN_TILT)
        self.cycles += 1
        if self._distance() <= self.maze.target_radius:
            self.reached = True
        if tilt > FALLEN_TILT:
            self.fell = True

    def scan(self) -> np.ndarray:
        """``(beams,)`` float32 laser ranges (m, +inf: no return)."""
        return self.scanner.scan(self.sim)

    def status(self) -> EpisodeStatus:
        """Time, distance to the target, and whether it was reached or the robot fell.

        Reaching the target counts first when both happen in one cycle, as offline; a
        fall ends the episode and eq. 5 scores where the robot lies.
        """
        return EpisodeStatus(
            self.time,
            self.reached,
            self._distance(),
            self.initial_distance,
            self.episode_time,
            fell=self.fell and not self.reached,
        )

    def close(self) -> None:
        """Release PyBullet."""
        self.sim.close()
