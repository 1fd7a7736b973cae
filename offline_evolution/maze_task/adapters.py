"""The search's own code for each robot family: its maze task.

The onboard robot record names no search code (docs/design.md section 19): this table
gives it, by the record's ``family`` (:attr:`~evorbc_ros.robots.record.Robot.adapter_key`).
The built-in families are below; a robot package adds its own through the entry-point
group :data:`GROUP` (docs/your-robot.md), or a script through ``TABLE.register``. Import
paths are imported when used.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from evorbc_ros.robots.adapters import AdapterTable
from evorbc_ros.robots.record import Robot

#: The entry-point group robot packages declare their search adapters in.
GROUP = "evorbc.search_adapters"


@dataclass(frozen=True)
class SearchAdapters:
    """A robot family's search code: an import path ``"package.module:attribute"`` or object.

    Attributes:
        task: ``f(robot, settings, workers=None)`` -> its maze task (episodes of networks
            driving the robot, eq. 5 fitness) for a
            :class:`~offline_evolution.maze_task.task.MazeTaskSettings`; ``workers`` are
            the processes that run episodes (PyBullet robots; default: every core).

    """

    task: str | Callable[..., Any]


_KINEMATIC = SearchAdapters("offline_evolution.maze_task.factories:kinematic_task")
#: The families evorbc searches for.
BUILTIN = {
    "four_ws": _KINEMATIC,
    "diff_drive": _KINEMATIC,
    "hexapod": SearchAdapters("offline_evolution.maze_task.factories:hexapod_task"),
    "legged": SearchAdapters("offline_evolution.maze_task.legged_task:legged_task"),
}

#: The search's adapters by family: ``TABLE.register(family, SearchAdapters(...))`` adds a
#: script's own, ``TABLE.adapters(robot)`` gives a robot's.
TABLE: AdapterTable[SearchAdapters] = AdapterTable(SearchAdapters, GROUP, BUILTIN, legacy=("task",))


def make_task(robot: Robot, settings, workers: int | None = None):
    """``robot``'s maze task for ``settings`` (a ``MazeTaskSettings``).

    Raises:
        RobotError: no adapters, or a factory that cannot be imported, in one line.

    """
    return TABLE.load(robot, "task")(robot, settings, workers=workers)
