"""The simulated hexapod as the search code sees it (see :mod:`sim_bridge.robots.base`)."""

from __future__ import annotations

import dataclasses
import json

import numpy as np

from evorbc_ros.robots.hexapod import (
    HEXAPOD,
    N_PARAMETERS,
    SPEED_BOUND,
    HexapodGeometry,
    parameter_specs,
)
from evorbc_ros.robots.primitive import ParameterSpec
from sim_bridge.hexapod.evaluate import HEADING, PATH, TILT, X, Y
from sim_bridge.hexapod.physics import PhysicsSettings
from sim_bridge.hexapod.pool import EvaluationPool
from sim_bridge.robots.base import PrimitiveOutcome, control_steps

#: Tilt (rad) beyond which an evaluation stops: eq. 6 discards the primitive anyway.
DISCARD_TILT = np.radians(45.0)


def describe_simulation(geometry: HexapodGeometry, physics: PhysicsSettings) -> dict:
    """Plain-data description of a simulated hexapod: its geometry and physics settings.

    Repertoires, checkpoints and arbitrator files record it, so that a file made for
    another design (other servos, legs or physics rate) is refused rather than reused.
    """
    described = {"geometry": dataclasses.asdict(geometry), "physics": physics.as_dict()}
    return json.loads(json.dumps(described))  # as a file holds it: tuples become lists


class HexapodRobot:
    """The 18-joint hexapod in PyBullet, primitives evaluated on ``workers`` processes."""

    name = HEXAPOD

    def __init__(
        self,
        geometry: HexapodGeometry | None = None,
        physics: PhysicsSettings | None = None,
        workers: int | None = None,
    ) -> None:
        self.geometry = geometry or HexapodGeometry()
        self.physics = physics or PhysicsSettings()
        self.control_period = self.geometry.control_period
        self.pool = EvaluationPool(self.geometry, self.physics, workers)

    @property
    def parameter_specs(self) -> tuple[ParameterSpec, ...]:
        """The 37 parameters of eq. 11 (genes in [-1, 1])."""
        return parameter_specs()

    def max_reach(self, eval_time: float) -> float:
        """An upper bound (m) on any primitive's displacement after ``eval_time`` s."""
        return SPEED_BOUND * eval_time

    def evaluate_primitives(self, genes: np.ndarray, eval_time: float) -> PrimitiveOutcome:
        """Execute ``(n, 37)`` primitives from rest for ``eval_time`` s (in parallel).

        Primitives that tilt past 45 deg stop early; their outcome is where they were
        then, with ``max_tilt`` above the limit (the circular+tilt metric discards them).
        """
        genes = np.atleast_2d(np.asarray(genes, dtype=np.float64))
        if genes.shape[1] != N_PARAMETERS:
            raise ValueError(
                f"hexapod primitives have {N_PARAMETERS} parameters, got {genes.shape[1]}"
            )
        control_steps(eval_time, self.control_period)
        rows = self.pool.evaluate(genes, eval_time, self.control_period, DISCARD_TILT)
        return PrimitiveOutcome(
            x=rows[:, X],
            y=rows[:, Y],
            heading=rows[:, HEADING],
            path=rows[:, PATH],
            max_tilt=rows[:, TILT],
        )

    def describe(self) -> dict:
        """Plain-data description of the simulated robot (recorded in repertoire files)."""
        return describe_simulation(self.geometry, self.physics)

    def close(self) -> None:
        """Stop the worker processes."""
        self.pool.close()


def simulated_robot(robot, workers: int | None = None) -> HexapodRobot:
    """The hexapod registration's simulated robot (its ``simulation`` factory).

    Args:
        robot: the :class:`~evorbc_ros.robots.registry.Robot`.
        workers: PyBullet worker processes (default: every core).

    """
    return HexapodRobot(workers=workers)
