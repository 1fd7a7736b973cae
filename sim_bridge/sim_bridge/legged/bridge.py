"""The simulation bridge's adapter for a legged robot from a URDF plus a settings file.

Named by legged registrations' ``bridge`` field (:mod:`evorbc_ros.robots.builtin.legged`):
the hexapod's trajectory adapter (:class:`~sim_bridge.bridge_robots.TrajectoryBridge`:
JointTrajectory commands resampled at the physics steps, zero-order hold, LaserScan,
Odometry and JointState) over the maze world of the robot its registration's settings
file describes, with the laser of its registration's sensor layout.
"""

from __future__ import annotations

from evorbc_ros.robots import registry
from sim_bridge.bridge_robots import TrajectoryBridge
from sim_bridge.legged.maze_world import LeggedMazeWorld
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.legged.settings import load_robot_settings


class LeggedBridge(TrajectoryBridge):
    """A legged robot from settings, stepped by joint-target trajectories."""

    def make_world(self, robot: str, maze, pose, episode_time: float, gui: bool):
        """The robot of ``robot``'s settings file in ``maze``, with its laser."""
        spec = registry.lookup(robot)
        settings = load_robot_settings(spec.model.path())
        self.joint_names = settings.gait.joint_names

        def sim(walls, gui):
            return LeggedSim(settings, walls, gui=gui)

        return LeggedMazeWorld(maze, sim, str(spec.sensors_file()), pose, episode_time, gui)
