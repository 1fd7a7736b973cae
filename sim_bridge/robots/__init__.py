"""Simulated robots, looked up by name."""

from __future__ import annotations

from evorbc_ros.robots.four_ws import ROBOT_TYPES as FOUR_WS_TYPES
from sim_bridge.robots.base import PrimitiveOutcome, SimulatedRobot

__all__ = ["ROBOT_NAMES", "PrimitiveOutcome", "SimulatedRobot", "make_robot"]

#: Every robot the project can simulate.
ROBOT_NAMES: tuple[str, ...] = tuple(FOUR_WS_TYPES)


def make_robot(name: str) -> SimulatedRobot:
    """The simulated robot called ``name``.

    Raises:
        KeyError: naming the known robots.

    """
    if name in FOUR_WS_TYPES:
        from sim_bridge.robots.four_ws import FourWSRobot

        return FourWSRobot(name)
    raise KeyError(f"unknown robot {name!r}; expected one of {', '.join(ROBOT_NAMES)}")
