"""The hexapod's onboard command interface: a ros2_control joint trajectory controller.

Named by the hexapod registration's ``commands`` field (docs/your-robot.md). Publishes,
reliable, ``joint_trajectory_controller/joint_trajectory`` (trajectory_msgs/JointTrajectory):
the 18 joints' targets
(rad) for the next ``stale_timeout`` s, one point per physics step (``trajectory_rate``,
50 Hz), see :mod:`evorbc_ros.hexapod_executor`.
"""

from __future__ import annotations

from builtin_interfaces.msg import Duration
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from evorbc_ros.hexapod_executor import HexapodExecutor
from evorbc_ros.legged_executor import JointTargets, LeggedExecutor
from evorbc_ros.robots.hexapod import JOINT_NAMES, SERVO_RATE


class JointTrajectoryCommands:
    """The current gait as joint-target trajectories.

    Args:
        node: the ``primitive_executor`` node: its lifecycle publishers, and its parameter
            ``trajectory_rate`` (points per second; 0: :meth:`default_rate`).
        robot: the robot's registration.
        inputs: sensor topics whose silence stops the robot.
        stale_timeout: s, inputs older than this stop the robot (and how far ahead a
            trajectory reaches).

    """

    def __init__(self, node, robot, inputs: list[str], stale_timeout: float) -> None:
        rate = float(node.get_parameter("trajectory_rate").value) or self.default_rate(robot)
        self.logic = self.executor(robot, inputs, stale_timeout, rate)
        self.joint_names = list(self.logic.gait.joint_names)
        self.pub = node.lifecycle_publisher(
            JointTrajectory, "joint_trajectory_controller/joint_trajectory"
        )

    @staticmethod
    def default_rate(robot) -> float:
        """Trajectory points per second when ``trajectory_rate`` is 0: 50 Hz."""
        return SERVO_RATE

    @staticmethod
    def executor(robot, inputs: list[str], stale_timeout: float, rate: float) -> LeggedExecutor:
        """The pure executor logic for ``robot`` (the hexapod's)."""
        return HexapodExecutor(inputs, stale_timeout, rate)

    def publish(self, command: JointTargets, halt: bool = False) -> None:
        """Send one command; none before the first target, which there is nothing to hold.

        Args:
            halt: the command answers the arbitrator's "no primitive". Before any target
                was sent there is none to hold, and an empty trajectory, ROS's "stop and
                hold where you are" for a joint trajectory controller, is sent instead.

        """
        if len(command.positions):
            self.pub.publish(trajectory_message(command, self.joint_names))
        elif halt:
            self.pub.publish(JointTrajectory(joint_names=self.joint_names))


def trajectory_message(command: JointTargets, joint_names=JOINT_NAMES) -> JointTrajectory:
    """A JointTrajectory with point ``k`` at ``k * dt`` s (header stamp 0: start on receipt).

    ``joint_names``: the joints of ``command.positions``' columns (default: the hexapod's).
    """
    msg = JointTrajectory()
    msg.joint_names = list(joint_names)
    points = []
    for k, row in enumerate(command.positions):
        ns = round(k * command.dt * 1e9)
        points.append(
            JointTrajectoryPoint(
                positions=row.tolist(),
                time_from_start=Duration(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000),
            )
        )
    msg.points = points
    return msg
