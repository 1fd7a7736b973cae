"""The built-in robots' maze-task factories, named by their registrations' ``task`` field.

Each is called ``task(robot, settings, workers=None)`` with the robot's registration
(:class:`~evorbc_ros.robots.registry.Robot`) and a
:class:`~offline_evolution.maze_task.task.MazeTaskSettings`.
"""

from __future__ import annotations


def kinematic_task(robot, settings, workers: int | None = None):
    """The compiled maze task of a kinematic robot, 4WS or differential drive.

    Its episodes run on numba's threads, in the robot's own motion model.
    """
    from offline_evolution.maze_task.task import MazeTask

    return MazeTask(settings, robot.make_simulation())


#: The name 4WS registrations made before differential-drive robots used.
four_ws_task = kinematic_task


def hexapod_task(robot, settings, workers: int | None = None):
    """The hexapod's maze task, episodes in PyBullet on ``workers`` processes."""
    from offline_evolution.maze_task.hexapod_task import HexapodMazeTask

    return HexapodMazeTask(settings, workers=workers)
