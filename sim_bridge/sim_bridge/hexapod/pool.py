"""Hexapod primitive evaluations spread over worker processes: the legged robot's pool.

:mod:`sim_bridge.legged.pool` holds the code; the names stay importable from here.
"""

from __future__ import annotations

import functools

from evorbc_ros.robots.hexapod import HexapodGeometry
from sim_bridge.hexapod.physics import HexapodSim, PhysicsSettings
from sim_bridge.legged import pool as _legged
from sim_bridge.legged.pool import CHUNK, SpawnedWorkers, available_cores, ignore_sigint

__all__ = ["CHUNK", "EvaluationPool", "SpawnedWorkers", "available_cores", "ignore_sigint"]


class EvaluationPool(_legged.EvaluationPool):
    """Evaluates batches of hexapod primitives on ``workers`` processes (1: in this one)."""

    def __init__(
        self,
        geometry: HexapodGeometry,
        physics: PhysicsSettings,
        workers: int | None = None,
    ) -> None:
        self.geometry = geometry
        self.physics = physics
        super().__init__(functools.partial(HexapodSim, geometry, physics), workers)
