"""A legged robot from settings as the search code sees it (see :mod:`sim_bridge.robots.base`)."""

from __future__ import annotations

import functools

import numpy as np

from evorbc_ros.robots.primitive import ParameterSpec
from sim_bridge.legged.evaluate import HEADING, PATH, TILT, X, Y
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.legged.pool import EvaluationPool
from sim_bridge.legged.settings import LeggedRobotSettings, load_robot_settings
from sim_bridge.robots.base import PrimitiveOutcome, control_steps


class LeggedRobot:
    """A legged robot in PyBullet, primitives evaluated on ``workers`` processes.

    Args:
        settings: the robot, or the path of its settings file.
        workers: processes that evaluate primitives (default: every core); results do
            not depend on it.

    """

    def __init__(self, settings: LeggedRobotSettings | str, workers: int | None = None) -> None:
        if not isinstance(settings, LeggedRobotSettings):
            settings = load_robot_settings(settings)
        self.settings = settings
        self.name = settings.name
        self.control_period = settings.control_period
        self.pool = EvaluationPool(functools.partial(LeggedSim, settings), workers)

    @property
    def parameter_specs(self) -> tuple[ParameterSpec, ...]:
        """The ``1 + 3 k`` parameters of eq. 11 (genes in [-1, 1])."""
        return self.settings.gait.parameter_specs()

    def max_reach(self, eval_time: float) -> float:
        """An upper bound (m) on any primitive's displacement after ``eval_time`` s."""
        return self.settings.speed_bound * eval_time

    def evaluate_primitives(self, genes: np.ndarray, eval_time: float) -> PrimitiveOutcome:
        """Execute ``(n, 1 + 3 k)`` primitives from rest for ``eval_time`` s (in parallel).

        Primitives that tilt past the discard tilt stop early; their outcome is where they
        were then, with ``max_tilt`` above the limit (the circular+tilt metric discards
        them).
        """
        genes = np.atleast_2d(np.asarray(genes, dtype=np.float64))
        n = self.settings.gait.n_parameters
        if genes.shape[1] != n:
            raise ValueError(f"{self.name} primitives have {n} parameters, got {genes.shape[1]}")
        control_steps(eval_time, self.control_period)
        rows = self.pool.evaluate(genes, eval_time, self.control_period, self.settings.discard_tilt)
        return PrimitiveOutcome(
            x=rows[:, X],
            y=rows[:, Y],
            heading=rows[:, HEADING],
            path=rows[:, PATH],
            max_tilt=rows[:, TILT],
        )

    def describe(self) -> dict:
        """Plain-data description of the simulated robot (recorded in repertoire files)."""
        return self.settings.describe()

    def close(self) -> None:
        """Stop the worker processes."""
        self.pool.close()


def simulated_robot(robot, workers: int | None = None) -> LeggedRobot:
    """A legged registration's simulated robot (the ``legged`` family's ``simulation``).

    Args:
        robot: the :class:`~evorbc_ros.robots.registry.Robot`; its ``model`` names the
            settings file (:class:`~evorbc_ros.robots.builtin.legged.LeggedModel`).
        workers: PyBullet worker processes (default: every core).

    """
    return LeggedRobot(str(robot.model.path()), workers=workers)
