"""The simulated differential-drive robot as the search code sees it.

See :mod:`sim_bridge.robots.base`.
"""

from __future__ import annotations

import numpy as np

from evorbc_ros.robots.diff_drive import DiffDriveGeometry
from evorbc_ros.robots.primitive import ParameterSpec
from sim_bridge.diff_drive.motion import diff_limits
from sim_bridge.kinematics import run_model_primitives
from sim_bridge.robots.base import PrimitiveOutcome, control_steps


class DiffDriveRobot:
    """A differential-drive robot driven by the compiled motion model.

    Args:
        name: the robot's name.
        geometry: its body and limits.

    """

    def __init__(self, name: str, geometry: DiffDriveGeometry) -> None:
        self.name = name
        self.geometry = geometry
        self.limits = diff_limits(geometry)
        self.control_period = geometry.control_period
        self.footprint_radius = geometry.footprint_radius
        #: A standard controller's outputs are the genes: one per command entry.
        self.gene_matrix = np.eye(2)
        self.command_scale = geometry.command_scale
        self.speed_wheel_radius = 0.0  # a twist reaches the bridge as it is: no round trip

    @property
    def parameter_specs(self) -> tuple[ParameterSpec, ...]:
        """Linear (m/s) and angular (rad/s) speed, genes in [-1, 1]."""
        return self.geometry.parameter_specs()

    def commands(self, genes: np.ndarray) -> np.ndarray:
        """``(n, 2)`` body twists (v m/s, omega rad/s) of ``(n, 2)`` genes."""
        return self.geometry.commands(genes)

    def max_reach(self, eval_time: float) -> float:
        """Top speed times the evaluation time (m): no primitive can get further."""
        return self.geometry.max_speed * eval_time

    def evaluate_primitives(self, genes: np.ndarray, eval_time: float) -> PrimitiveOutcome:
        """Execute ``(n, 2)`` primitives from rest for ``eval_time`` seconds."""
        genes = np.atleast_2d(np.asarray(genes, dtype=np.float64))
        if genes.shape[1] != 2:
            raise ValueError(
                f"robot {self.name} primitives have 2 parameters, got {genes.shape[1]}"
            )
        steps = control_steps(eval_time, self.control_period)
        out = run_model_primitives(np.ascontiguousarray(self.commands(genes)), steps, self.limits)
        return PrimitiveOutcome(x=out[:, 0], y=out[:, 1], heading=out[:, 2], path=out[:, 3])

    def describe(self) -> dict:
        """Its design as files record it: the kinematics and the geometry (SI units)."""
        return {"kinematics": "diff_drive", "geometry": self.geometry.as_dict()}


def simulated_robot(robot, workers: int | None = None) -> DiffDriveRobot:
    """A differential-drive registration's simulated robot (its family's ``simulation``).

    Args:
        robot: the registration; its ``model`` is its :class:`DiffDriveGeometry`.
        workers: unused: the compiled model runs on numba's threads.

    """
    return DiffDriveRobot(robot.name, robot.model)
