"""The hexapod's bridge adapter: the legged robots' trajectory adapter over its maze world."""

from __future__ import annotations

from evorbc_ros.robots.hexapod import JOINT_NAMES
from sim_bridge.hexapod.maze_world import HexapodMazeWorld
from sim_bridge.legged.bridge import TrajectoryBridge


class HexapodBridge(TrajectoryBridge):
    """The hexapod: its 18 joints, the maze world of :mod:`sim_bridge.hexapod.maze_world`."""

    joint_names = JOINT_NAMES

    def make_world(self, robot: str, maze, pose, episode_time: float, gui: bool):
        """The hexapod in ``maze``."""
        return HexapodMazeWorld(maze, pose, episode_time, gui)
