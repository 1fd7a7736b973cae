"""The maze task for the hexapod: the legged robots' task with the hexapod (parent side).

:class:`HexapodMazeTask` is :class:`~offline_evolution.maze_task.legged_task.LeggedMazeTask`
(episodes in PyBullet on worker processes, perturbed worlds, eq. 5 fitness) for the hexapod
that ``config/robots/hexapod.yaml`` (with ``hexapod.urdf``) describes, or for another
design given as a :class:`~evorbc_ros.robots.hexapod.HexapodGeometry` and physics
settings. Its files record the hexapod's geometry and physics, as they always did.
"""

from __future__ import annotations

from evorbc_ros.robots.hexapod import HexapodGeometry
from offline_evolution.maze_task.base import MazeTaskSettings
from offline_evolution.maze_task.legged_task import LeggedMazeTask
from sim_bridge.hexapod.physics import PhysicsSettings, hexapod_robot_settings
from sim_bridge.hexapod.robot import describe_simulation


class HexapodMazeTask(LeggedMazeTask):
    """The maze task for the hexapod (``config/tasks/maze-hexapod.yaml``).

    Args:
        settings: the maze task's settings (mazes, episode time, samples, sensors).
        workers: PyBullet worker processes (default: every core).
        geometry, physics: another hexapod design than the default (None: the hexapod of
            ``config/robots/hexapod.yaml``, which is the default design; a test keeps the
            two bit-identical).

    """

    def __init__(
        self,
        settings: MazeTaskSettings,
        workers: int | None = None,
        geometry: HexapodGeometry | None = None,
        physics: PhysicsSettings | None = None,
    ):
        robot = hexapod_robot_settings(geometry, physics)
        self.geometry = geometry or HexapodGeometry()
        self.physics = physics or PhysicsSettings()
        super().__init__(settings, robot, workers)

    def describe(self) -> dict:
        """The simulated robot (geometry and physics), as repertoire files record it."""
        return describe_simulation(self.geometry, self.physics)
