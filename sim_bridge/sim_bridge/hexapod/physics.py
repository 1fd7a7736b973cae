"""The hexapod in a PyBullet world: the generic legged simulation with the hexapod's URDF.

:class:`HexapodSim` is :class:`~sim_bridge.legged.physics.LeggedSim` built from a
:class:`~evorbc_ros.robots.hexapod.HexapodGeometry`: the URDF generated from it, its gait
(eq. 10-11 with ``C = 90 deg - B``), its servos (P controller on position, velocity and
torque limits enforced in code) and the physics settings. ``config/robots/hexapod.yaml``
describes the same robot as a settings file; tests keep both bit-identical to each other
and to the code that simulated the hexapod before the generic legged robot existed
(``tests/reference_hexapod.py``).
"""

from __future__ import annotations

import functools

import numpy as np

from evorbc_ros.config import config_dir
from evorbc_ros.robots.hexapod import HEXAPOD, HexapodGeometry, hexapod_gait
from sim_bridge.hexapod.urdf import hexapod_urdf
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.legged.settings import (
    LeggedRobotSettings,
    PhysicsSettings,
    ServoModel,
    load_robot_settings,
)


@functools.lru_cache(maxsize=8)
def hexapod_settings(
    geometry: HexapodGeometry | None = None, physics: PhysicsSettings | None = None
) -> LeggedRobotSettings:
    """The hexapod as a legged robot (:mod:`sim_bridge.legged.settings`)."""
    g = geometry or HexapodGeometry()
    return LeggedRobotSettings(
        name=HEXAPOD,
        gait=hexapod_gait(g),
        servo=ServoModel(g.position_gain, g.max_joint_velocity, tuple(g.joint_torques())),
        physics=physics or PhysicsSettings(),
        urdf_text=hexapod_urdf(g),
        base_link="base",
        foot_links=tuple(f"{leg}_tibia_link" for leg in ("lf", "lm", "lr", "rf", "rm", "rr")),
        control_period=g.control_period,
        spawn_height=g.standing_height + 0.001,
        footprint_radius=g.footprint_radius,
        self_collision=True,
    )


def hexapod_robot_settings(
    geometry: HexapodGeometry | None = None, physics: PhysicsSettings | None = None
) -> LeggedRobotSettings:
    """The hexapod the search and the maze task simulate.

    The default design is the robot of ``config/robots/hexapod.yaml`` (and
    ``hexapod.urdf``), as for any legged robot; another design (``geometry`` or
    ``physics`` given) is built in code (:func:`hexapod_settings`). A test keeps the two
    bit-identical for the default design.
    """
    if geometry is None and physics is None:
        return load_robot_settings(config_dir() / "robots" / f"{HEXAPOD}.yaml")
    return hexapod_settings(geometry, physics)


class HexapodSim(LeggedSim):
    """One hexapod (and optionally maze walls) in its own PyBullet client.

    Args:
        geometry: the robot.
        physics: rate, solver and friction.
        walls: ``(m, 6)`` wall boxes of :mod:`sim_bridge.geometry` (a maze), or None.
        gui: open PyBullet's GUI instead of running headless.
        rest_xy: where (m) the robot settles into its rest state: the origin without
            walls, otherwise a point 10 m beyond the walls so that it settles untouched.

    """

    def __init__(
        self,
        geometry: HexapodGeometry | None = None,
        physics: PhysicsSettings | None = None,
        walls: np.ndarray | None = None,
        gui: bool = False,
        rest_xy: tuple[float, float] | None = None,
    ) -> None:
        self.geometry = geometry or HexapodGeometry()
        super().__init__(hexapod_settings(self.geometry, physics), walls, gui, rest_xy)
