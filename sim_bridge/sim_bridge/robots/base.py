"""The interface every simulated robot offers to the search code.

A robot says what its locomotion parameters are and how a batch of primitives behaves when
executed for T seconds from rest; the search code (MAP-Elites, NEAT tasks) never needs to
know which robot it drives: adding a robot does not touch the search code.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from evorbc_ros.robots.primitive import ParameterSpec


@dataclass(frozen=True)
class PrimitiveOutcome:
    """What executing ``n`` primitives for T seconds from rest produced.

    Positions and headings are in the robot's start frame (x forward, y left); the robot
    starts at the origin facing +x.
    """

    x: np.ndarray  # (n,) m
    y: np.ndarray  # (n,) m
    heading: np.ndarray  # (n,) rad, final heading, not wrapped
    path: np.ndarray  # (n,) m, distance the body centre travelled
    max_tilt: np.ndarray | None = None  # (n,) rad, largest body tilt (legged robots only)

    @property
    def displacement(self) -> np.ndarray:
        """``(n, 2)`` final displacement ``(x, y)`` in m: the behaviour descriptor."""
        return np.column_stack([self.x, self.y])


def control_steps(duration: float, period: float) -> int:
    """Number of control steps in ``duration`` s.

    Raises:
        ValueError: ``duration`` is not a positive whole number of control periods.

    """
    steps = round(duration / period)
    if steps < 1 or abs(steps * period - duration) > 1e-9:
        raise ValueError(
            f"must be a positive multiple of the {period:g} s control period, got {duration:g} s"
        )
    return steps


class SimulatedRobot(Protocol):
    """A robot as the offline search sees it."""

    name: str
    control_period: float  # s, primitives run for whole numbers of control periods

    @property
    def parameter_specs(self) -> tuple[ParameterSpec, ...]:
        """Names, units and ranges of the locomotion parameters (genes in [-1, 1])."""
        ...

    def max_reach(self, eval_time: float) -> float:
        """An upper bound (m) on the displacement of any primitive after ``eval_time`` s."""
        ...

    def evaluate_primitives(self, genes: np.ndarray, eval_time: float) -> PrimitiveOutcome:
        """Execute ``(n, n_parameters)`` primitives from rest for ``eval_time`` seconds."""
        ...
