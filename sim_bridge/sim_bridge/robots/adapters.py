"""The simulation's own code for each robot family: simulated robot, bridge adapter, design check.

The onboard robot record names no simulation code (docs/design.md section 19): this table
gives it, by the record's ``family`` (:attr:`~evorbc_ros.robots.record.Robot.adapter_key`).
The built-in families are below; a robot package adds its own through the entry-point
group :data:`GROUP` (docs/your-robot.md), or a script through ``TABLE.register``. Import
paths are imported when used, so looking adapters up loads no PyBullet or numba.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from evorbc_ros.robots.adapters import AdapterTable
from evorbc_ros.robots.record import Robot

#: The entry-point group robot packages declare their simulation adapters in.
GROUP = "evorbc.sim_adapters"


@dataclass(frozen=True)
class SimAdapters:
    """A robot family's simulation code: import paths ``"package.module:attribute"`` or objects.

    Attributes:
        simulation: ``f(robot, workers=None)`` -> a
            :class:`~sim_bridge.robots.base.SimulatedRobot` that executes batches of
            primitives from rest (MAP-Elites' evaluation, the maze tasks' motion).
        bridge: the bridge adapter class: ``cls(node, robot_name, maze, pose,
            episode_time, gui)``.
        design_check: optional ``f(robot, controller)`` raising ``ConfigError`` when
            ``evorbc-sim`` is given a controller evolved for another design than the
            bridge simulates ("" for none).

    """

    simulation: str | Callable[..., Any]
    bridge: str | type
    design_check: str | Callable[..., Any] = ""


#: The families evorbc simulates.
BUILTIN = {
    "four_ws": SimAdapters(
        "sim_bridge.four_ws.robot:simulated_robot", "sim_bridge.four_ws.bridge:FourWSBridge"
    ),
    "diff_drive": SimAdapters(
        "sim_bridge.diff_drive.robot:simulated_robot",
        "sim_bridge.diff_drive.bridge:DiffDriveBridge",
    ),
    "hexapod": SimAdapters(
        "sim_bridge.hexapod.robot:simulated_robot",
        "sim_bridge.hexapod.bridge:HexapodBridge",
        "sim_bridge.hexapod.design:check_controller",
    ),
    "legged": SimAdapters(
        "sim_bridge.legged.robot:simulated_robot",
        "sim_bridge.legged.bridge:LeggedBridge",
        "sim_bridge.legged.design:check_controller",
    ),
}

#: The simulation's adapters by family: ``TABLE.register(family, SimAdapters(...))`` adds
#: a script's own, ``TABLE.adapters(robot)`` gives a robot's.
TABLE: AdapterTable[SimAdapters] = AdapterTable(
    SimAdapters, GROUP, BUILTIN, legacy=("simulation", "bridge", "design_check")
)


def make_simulation(robot: Robot, workers: int | None = None):
    """``robot``'s simulated robot for primitive evaluation.

    Args:
        robot: the record.
        workers: processes that evaluate primitives (PyBullet robots; default: every
            core). Results do not depend on it.

    Raises:
        RobotError: no adapters, or a factory that cannot be imported, in one line.

    """
    return TABLE.load(robot, "simulation")(robot, workers=workers)


def bridge_class(robot: Robot) -> type:
    """``robot``'s bridge adapter class (the ``sim_bridge`` node makes one at start-up)."""
    return TABLE.load(robot, "bridge")


def check_design(robot: Robot, controller) -> None:
    """Run ``robot``'s design check on a controller, if its family has one (``evorbc-sim``).

    Raises:
        ConfigError: the controller was evolved for another design than the bridge's.

    """
    check = TABLE.load(robot, "design_check")
    if check is not None:
        check(robot, controller)
