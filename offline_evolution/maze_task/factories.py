"""The built-in robots' maze-task factories, named by their registrations' ``task`` field.

Each is called ``task(robot, settings, workers=None)`` with the robot's registration
(:class:`~evorbc_ros.robots.registry.Robot`) and a
:class:`~offline_evolution.maze_task.task.MazeTaskSettings`.
"""

from __future__ import annotations


def four_ws_task(robot, settings, workers: int | None = None):
    """The compiled maze task of a 4WS robot (its episodes run on numba's threads)."""
    from offline_evolution.maze_task.task import MazeTask

    return MazeTask(settings, robot.name)


def hexapod_task(robot, settings, workers: int | None = None):
    """The hexapod's maze task, episodes in PyBullet on ``workers`` processes."""
    from offline_evolution.maze_task.hexapod_task import HexapodMazeTask

    return HexapodMazeTask(settings, workers=workers)
