"""A legged robot in a maze for the simulation bridge: stepped by joint-target trajectories.

The same simulation, scanner and episode rules as offline evolution
(:mod:`sim_bridge.legged.episode`): the bridge publishes what this world
reads, the graph answers with one control period of joint targets, and :meth:`step` runs
the physics through them. With the same start pose, a lockstep run reproduces the offline
episode cycle by cycle.
"""

from __future__ import annotations

import math

import numpy as np

from evorbc_ros.config import config_dir
from evorbc_ros.sensors import SensorLayout
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.legged.scanner import Scanner
from sim_bridge.maze import Maze
from sim_bridge.world import EpisodeStatus


class LeggedMazeWorld:
    """A legged robot in a maze, advanced one control period at a time.

    Args:
        maze: the maze.
        sim: builds the robot's simulation from the maze's wall boxes and ``gui``
            (``lambda walls, gui: LeggedSim(settings, walls, gui)``).
        sensors: the laser's settings file, relative to ``config/``.
        start: ``(x, y, heading)`` (m, rad), or None for the maze's nominal start.
        episode_time: s.
        gui: open PyBullet's GUI.

    """

    def __init__(
        self,
        maze: Maze,
        sim,
        sensors: str,
        start: tuple[float, float, float] | None = None,
        episode_time: float = 30.0,
        gui: bool = False,
    ) -> None:
        self.maze = maze
        self.episode_time = episode_time
        layout = SensorLayout.load(config_dir() / sensors)
        self.scanner = Scanner.from_layout(layout.rangefinders)
        self.sim: LeggedSim = sim(maze.boxes, gui)
        self.settings = self.sim.settings
        self.physics = self.sim.physics
        self.fallen_tilt = self.settings.fallen_tilt
        self.sim.reset(*(maze.start_pose if start is None else start))
        self.steps_per_period = self.physics.steps(self.settings.control_period)
        self.cycles = 0
        self.reached = self.fell = False
        self.initial_distance = self._distance()
        self.targets = self.sim.joint_states()[0]  # (joints,) rad, held until commanded

    @property
    def dt(self) -> float:
        """Control period (s)."""
        return self.settings.control_period

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
            trajectory: ``(points, joints)`` joint targets (rad) one physics step apart; a
                shorter one holds its last point, ``None`` holds the last targets.

        """
        if trajectory is not None and len(trajectory):
            rows = np.asarray(trajectory, dtype=np.float64)[: self.steps_per_period]
        else:
            rows = self.targets[None, :]
        self.targets = rows[-1].copy()  # the servos hold the last target they tracked
        pad = self.steps_per_period - len(rows)
        rows = np.vstack([rows, np.repeat(rows[-1:], pad, axis=0)]) if pad > 0 else rows
        tilt, _ = self.sim.run(rows, max_tilt=self.fallen_tilt)
        self.cycles += 1
        if self._distance() <= self.maze.target_radius:
            self.reached = True
        if tilt > self.fallen_tilt:
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
