"""The built-in robot families' maze-task factories (:mod:`.adapters` names them).

Each is called ``task(robot, settings, workers=None)`` with the robot's record
(:class:`~evorbc_ros.robots.record.Robot`) and a
:class:`~offline_evolution.maze_task.task.MazeTaskSettings`.
"""

from __future__ import annotations


def kinematic_task(robot, settings, workers: int | None = None):
    """The compiled maze task of a kinematic robot, 4WS or differential drive.

    Its episodes run on numba's threads, in the robot's own motion model.
    """
    from offline_evolution.maze_task.task import MazeTask
    from sim_bridge.robots.adapters import make_simulation

    return MazeTask(settings, make_simulation(robot))


#: The name 4WS registrations made before differential-drive robots used.
four_ws_task = kinematic_task


def hexapod_task(robot, settings, workers: int | None = None):
    """The hexapod's maze task, episodes in PyBullet on ``workers`` processes."""
    from offline_evolution.maze_task.hexapod_task import HexapodMazeTask

    return HexapodMazeTask(settings, workers=workers)
