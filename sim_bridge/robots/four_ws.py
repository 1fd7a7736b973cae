"""The simulated 4WS robot as the search code sees it (see :mod:`sim_bridge.robots.base`)."""

from __future__ import annotations

import numpy as np

from evorbc_ros.robots.four_ws import FourWSGeometry, FourWSType, robot_type
from evorbc_ros.robots.primitive import ParameterSpec
from sim_bridge.four_ws_motion import motion_limits, run_primitives
from sim_bridge.robots.base import PrimitiveOutcome, control_steps


class FourWSRobot:
    """A 4WS robot type driven by the compiled motion model."""

    def __init__(self, type_name: str, geometry: FourWSGeometry | None = None) -> None:
        self.type: FourWSType = robot_type(type_name)
        self.name = self.type.name
        self.geometry = geometry or FourWSGeometry()
        self.limits = motion_limits(self.geometry)
        self.control_period = self.geometry.control_period

    @property
    def parameter_specs(self) -> tuple[ParameterSpec, ...]:
        """Names, units and ranges of the locomotion parameters (genes in [-1, 1])."""
        return self.type.parameter_specs(self.geometry)

    def max_reach(self, eval_time: float) -> float:
        """Top speed times the evaluation time (m): no primitive can get further."""
        return self.geometry.max_speed * eval_time

    def evaluate_primitives(self, genes: np.ndarray, eval_time: float) -> PrimitiveOutcome:
        """Execute ``(n, n_parameters)`` primitives from rest for ``eval_time`` seconds."""
        genes = np.atleast_2d(np.asarray(genes, dtype=np.float64))
        if genes.shape[1] != self.type.n_parameters:
            raise ValueError(
                f"robot {self.name} primitives have {self.type.n_parameters} parameters, "
                f"got {genes.shape[1]}"
            )
        steps = control_steps(eval_time, self.geometry.control_period)
        commands = np.ascontiguousarray(self.type.commands(genes, self.geometry))
        out = run_primitives(commands, steps, self.limits)
        return PrimitiveOutcome(x=out[:, 0], y=out[:, 1], heading=out[:, 2], path=out[:, 3])


def simulated_robot(robot, workers: int | None = None) -> FourWSRobot:
    """A 4WS registration's simulated robot (its ``simulation`` factory).

    Args:
        robot: the :class:`~evorbc_ros.robots.registry.Robot`; its ``model`` is the type.
        workers: unused: the compiled model runs on numba's threads.

    """
    return FourWSRobot(robot.name)
