"""The simulated 4WS robot as the search code sees it (see :mod:`sim_bridge.robots.base`)."""

from __future__ import annotations

import numpy as np

from evorbc_ros.robots.four_ws import FourWSGeometry, FourWSType
from evorbc_ros.robots.primitive import ParameterSpec
from evorbc_ros.robots.registry import robot_type
from sim_bridge.four_ws.motion import motion_limits
from sim_bridge.kinematics import run_model_primitives
from sim_bridge.robots.base import PrimitiveOutcome, control_steps


class FourWSRobot:
    """A 4WS robot type driven by the compiled motion model."""

    def __init__(self, type_name: str, geometry: FourWSGeometry | None = None) -> None:
        self.type: FourWSType = robot_type(type_name)
        self.name = self.type.name
        self.geometry = geometry or self.type.body()
        self.limits = motion_limits(self.geometry)
        self.control_period = self.geometry.control_period
        self.footprint_radius = self.geometry.footprint_radius
        #: How a standard controller's outputs become commands: ``(n_genes, 5)`` weights and
        #: the ``(5,)`` command limits (m/s, rad) they scale to.
        self.gene_matrix = self.type.gene_matrix
        g = self.geometry
        self.command_scale = np.array([g.max_speed] + [g.max_wheel_angle] * 4)
        #: m: onboard the speed travels as wheel rad/s (speed / r) and the bridge turns it
        #: back (x r), which can move it by one ulp; maze episodes apply the same round
        #: trip so that the lockstep graph reproduces them bit for bit (docs/design.md
        #: section 2). Primitive evaluation (MAP-Elites) does not: no ROS interface there.
        self.speed_wheel_radius = g.wheel_radius

    def commands(self, genes: np.ndarray) -> np.ndarray:
        """``(n, 5)`` wheel commands (speed m/s, fl, fr, rl, rr rad) of ``(n, d)`` genes."""
        return self.type.commands(genes, self.geometry)

    def describe(self) -> dict | None:
        """Its body, as files record a design.

        None for the paper's body (files made before the geometry came from a settings
        file record none), else the geometry (SI units).
        """
        if self.geometry == FourWSGeometry():
            return None
        return {"kinematics": "four_ws", "geometry": self.geometry.as_dict()}

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
        out = run_model_primitives(commands, steps, self.limits)
        return PrimitiveOutcome(x=out[:, 0], y=out[:, 1], heading=out[:, 2], path=out[:, 3])


def simulated_robot(robot, workers: int | None = None) -> FourWSRobot:
    """A 4WS registration's simulated robot (the ``four_ws`` family's ``simulation``).

    Args:
        robot: the :class:`~evorbc_ros.robots.registry.Robot`; its ``model`` is the type.
        workers: unused: the compiled model runs on numba's threads.

    """
    return FourWSRobot(robot.name)
