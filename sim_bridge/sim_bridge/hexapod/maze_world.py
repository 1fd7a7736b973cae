"""The hexapod in a maze for the simulation bridge: the legged robot's maze world.

:class:`~sim_bridge.legged.maze_world.LeggedMazeWorld` with the hexapod's simulation
(:func:`~sim_bridge.hexapod.physics.hexapod_robot_settings`) and laser; offline evolution
runs the same episodes (:mod:`sim_bridge.legged.episode`).
"""

from __future__ import annotations

import math

from evorbc_ros.robots.hexapod import HexapodGeometry
from sim_bridge.hexapod.physics import PhysicsSettings, hexapod_robot_settings
from sim_bridge.legged.maze_world import LeggedMazeWorld
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.maze import Maze

#: Body tilt (rad) at which the hexapod has fallen over: the episode ends there.
FALLEN_TILT = math.radians(90.0)

#: The laser the hexapod was evolved with (25 beams over [-90, 90] deg, 2 m).
DEFAULT_SENSORS = "sensors/hexapod.yaml"


class HexapodMazeWorld(LeggedMazeWorld):
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
        self.geometry = geometry or HexapodGeometry()
        settings = hexapod_robot_settings(geometry, physics)

        def sim(walls, gui):
            return LeggedSim(settings, walls, gui=gui)

        super().__init__(maze, sim, sensors, start, episode_time, gui)
