"""Simulated robots, looked up by name in the robot registry."""

from __future__ import annotations

from evorbc_ros.robots.registry import ROBOT_NAMES, lookup
from sim_bridge.robots.base import PrimitiveOutcome, SimulatedRobot

__all__ = ["ROBOT_NAMES", "PrimitiveOutcome", "SimulatedRobot", "make_robot"]


def make_robot(name: str, workers: int | None = None) -> SimulatedRobot:
    """The simulated robot called ``name`` (its family's ``simulation`` adapter).

    Args:
        name: a registered robot (:data:`ROBOT_NAMES`).
        workers: processes that evaluate primitives (robots simulated in PyBullet only;
            default: every core). Results do not depend on it.

    Raises:
        evorbc_ros.robots.registry.UnknownRobot: a KeyError naming the known robots.

    """
    from sim_bridge.robots.adapters import make_simulation

    return make_simulation(lookup(name), workers)
