"""Simulated robots, looked up by name."""

from __future__ import annotations

from evorbc_ros.robots.four_ws import ROBOT_TYPES as FOUR_WS_TYPES
from evorbc_ros.robots.hexapod import HEXAPOD
from sim_bridge.robots.base import PrimitiveOutcome, SimulatedRobot

__all__ = ["ROBOT_NAMES", "PrimitiveOutcome", "SimulatedRobot", "make_robot"]

#: Every robot the project can simulate.
ROBOT_NAMES: tuple[str, ...] = (*FOUR_WS_TYPES, HEXAPOD)


def make_robot(name: str, workers: int | None = None) -> SimulatedRobot:
    """The simulated robot called ``name``.

    Args:
        name: a 4WS type or ``hexapod``.
        workers: processes that evaluate primitives (robots simulated in PyBullet only;
            default: every core). Results do not depend on it.

    Raises:
        KeyError: naming the known robots.

    """
    if name in FOUR_WS_TYPES:
        from sim_bridge.robots.four_ws import FourWSRobot

        return FourWSRobot(name)
    if name == HEXAPOD:
        from sim_bridge.robots.hexapod import HexapodRobot

        return HexapodRobot(workers=workers)
    raise KeyError(f"unknown robot {name!r}; expected one of {', '.join(ROBOT_NAMES)}")
