"""The simulated hexapod as the search code sees it (see :mod:`sim_bridge.robots.base`)."""

from __future__ import annotations

import dataclasses
import json

import numpy as np

from evorbc_ros.robots.hexapod import HEXAPOD, HexapodGeometry
from sim_bridge.hexapod.physics import PhysicsSettings, hexapod_robot_settings
from sim_bridge.legged.robot import LeggedRobot

#: Tilt (rad) beyond which an evaluation stops: eq. 6 discards the primitive anyway.
DISCARD_TILT = np.radians(45.0)


def describe_simulation(geometry: HexapodGeometry, physics: PhysicsSettings) -> dict:
    """Plain-data description of a simulated hexapod: its geometry and physics settings.

    Repertoires, checkpoints and arbitrator files record it, so that a file made for
    another design (other servos, legs or physics rate) is refused rather than reused.
    """
    described = {"geometry": dataclasses.asdict(geometry), "physics": physics.as_dict()}
    return json.loads(json.dumps(described))  # as a file holds it: tuples become lists


class HexapodRobot(LeggedRobot):
    """The 18-joint hexapod in PyBullet, primitives evaluated on ``workers`` processes.

    The legged robot (:class:`~sim_bridge.legged.robot.LeggedRobot`) of
    :func:`~sim_bridge.hexapod.physics.hexapod_robot_settings`: 37 parameters of eq. 11,
    primitives tilting past 45 deg stop early (the circular+tilt metric discards them).
    Its files record the hexapod's geometry and physics, as they always did.
    """

    name = HEXAPOD

    def __init__(
        self,
        geometry: HexapodGeometry | None = None,
        physics: PhysicsSettings | None = None,
        workers: int | None = None,
    ) -> None:
        settings = hexapod_robot_settings(geometry, physics)
        self.geometry = geometry or HexapodGeometry()
        self.physics = physics or PhysicsSettings()
        super().__init__(settings, workers)

    def describe(self) -> dict:
        """Plain-data description of the simulated robot (recorded in repertoire files)."""
        return describe_simulation(self.geometry, self.physics)


def simulated_robot(robot, workers: int | None = None) -> HexapodRobot:
    """The hexapod registration's simulated robot (its family's ``simulation``).

    Args:
        robot: the :class:`~evorbc_ros.robots.registry.Robot`.
        workers: PyBullet worker processes (default: every core).

    """
    return HexapodRobot(workers=workers)
