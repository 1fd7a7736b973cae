"""A legged robot's onboard command interface: a ros2_control joint trajectory controller.

Named by legged registrations' ``commands`` field (:mod:`evorbc_ros.robots.builtin.legged`).
The hexapod's interface (:mod:`evorbc_ros.nodes.trajectory_commands`) with the gait of the
robot's settings file: on ``joint_trajectory_controller/joint_trajectory``
(trajectory_msgs/JointTrajectory, reliable) its joints' targets (rad) for the next
``stale_timeout`` s, one point per physics step. Unless ``trajectory_rate`` is set (not 0),
the points come at the robot's own physics rate
(``physics.rate_hz`` of its settings file), the rate its simulation's servos track.
"""

from __future__ import annotations

from evorbc_ros.legged_executor import LeggedExecutor
from evorbc_ros.nodes.trajectory_commands import JointTrajectoryCommands


class LeggedTrajectoryCommands(JointTrajectoryCommands):
    """The current gait of a legged robot from settings as joint-target trajectories."""

    @staticmethod
    def default_rate(robot) -> float:
        """Hz: the robot's physics rate (its settings file's ``physics.rate_hz``)."""
        return robot.model.physics_rate

    @staticmethod
    def executor(robot, inputs: list[str], stale_timeout: float, rate: float) -> LeggedExecutor:
        """The executor logic with the robot's gait and control period."""
        model = robot.model
        return LeggedExecutor(
            robot.name, model.gait(), inputs, stale_timeout, rate, model.control_period
        )
