"""What the primitive executor commands a legged robot (pure code).

A legged primitive is a gait (eq. 10-11, :mod:`evorbc_ros.robots.legged`): joint targets
that change continuously. Every command is a trajectory with one point per servo step
(``dt = 1 / trajectory_rate`` s), the gait's joint targets sampled at the gait time of
each step, so the joints follow the gait smoothly between the arbitrator's 10 Hz
decisions. It covers ``horizon`` s ahead (by default the stale timeout, 0.3 s, three
control periods): the next command replaces it after one period, and a late one finds the
legs still walking rather than frozen mid-stride. A controller that reaches the end of a
trajectory holds its last point, so the robot stops by itself if the executor dies.

The gait clock starts with the first primitive and counts whole servo steps,
``round((now - t0) / dt)``: a new primitive takes over at the current phase of the
oscillators (as in the paper's simulation, where the gait time is the episode time), and
the times are bit-identical to the offline simulation's. When the primitive or a sensor
input is stale, or the arbitrator chose no primitive (an empty message: its network's
outputs were not finite), the command holds the last targets: the legs stop where they are
and the robot stands still. Before any target was sent there is none to hold; the node then
sends an empty trajectory, ROS's "stop and hold where you are" (docs/design.md section 7).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from evorbc_ros.executor import InputWatch
from evorbc_ros.robots.legged import Gait, LeggedGaitTable, gait_step_times


@dataclass(frozen=True)
class JointTargets:
    """One command for a legged robot: joint targets at evenly spaced times."""

    positions: np.ndarray  # (points, joints) rad, the gait's joint order; none: send nothing
    dt: float  # s between points; point k is the target from k * dt after the command on
    stopped: bool  # True when this is the safety stop (one point: hold)
    reason: str = ""


class LeggedExecutor(InputWatch):
    """A legged robot's executor: the current gait as joint-target trajectories.

    Args:
        robot_name: the robot (primitives labelled for another are refused upstream).
        gait: its gait (oscillators, couplings, omega).
        inputs: sensor topics whose silence stops the robot.
        stale_timeout: s.
        trajectory_rate: points per second, the simulation's physics rate.
        control_period: s, the arbitrator's cycle; a command covers at least one.
        horizon: s ahead a command covers (default: the stale timeout).

    """

    def __init__(
        self,
        robot_name: str,
        gait: Gait,
        inputs: list[str],
        stale_timeout: float = 0.3,
        trajectory_rate: float = 50.0,
        control_period: float = 0.1,
        horizon: float | None = None,
    ):
        super().__init__(robot_name, gait.n_parameters, inputs, stale_timeout)
        self.gait = gait
        self.dt = 1.0 / trajectory_rate
        horizon = max(control_period, stale_timeout if horizon is None else horizon)
        self.points = max(1, round(horizon * trajectory_rate))
        self.gait_start: float | None = None  # clock time (s) of the first primitive
        self.table: LeggedGaitTable | None = None
        # The last trajectory sent and the clock time (s) it was sent at; a stop holds the
        # point that was being tracked then. Nothing is sent before the first primitive:
        # a made-up pose would jerk every joint of a real robot from wherever it stands,
        # and a joint trajectory controller that has no command holds its position anyway.
        self.sent = np.empty((0, len(gait.joints)))  # (points, joints) rad
        self.sent_at = 0.0

    def make_table(self, genes: np.ndarray) -> LeggedGaitTable:
        """The gait table of one primitive's genes."""
        return LeggedGaitTable(genes, self.gait, self.robot_name)

    def reset(self) -> None:
        """Back to the start-up state; the last targets sent are still held."""
        super().reset()
        self.gait_start = None
        self.table = None

    def on_primitive(self, genes, now: float) -> None:
        """A new primitive; the gait clock starts with the first one.

        An empty one ("no primitive") stops the gait: :meth:`command` then holds the
        target being tracked, and the gait clock runs on for the next primitive.
        """
        super().on_primitive(genes, now)
        if self.halted:
            return
        self.table = self.make_table(self.genes)
        if self.gait_start is None:
            self.gait_start = now

    def gait_step(self, now: float) -> int:
        """Whole servo steps since the gait began."""
        return round((now - self.gait_start) / self.dt)

    def command(self, now: float) -> JointTargets:
        """Targets for the next ``horizon`` s from ``now``, or a hold if stopped."""
        reason = self.stop_reason(now)
        if reason:
            if len(self.sent):  # hold the point being tracked; before any command, none
                k = min(max(round((now - self.sent_at) / self.dt), 0), len(self.sent) - 1)
                self.sent, self.sent_at = self.sent[k : k + 1].copy(), now
            return JointTargets(self.sent.copy(), self.dt, True, reason)
        times = gait_step_times(self.gait_step(now), self.points, self.dt)
        positions = self.table.joint_targets(times, np.zeros(self.points, dtype=np.int64))
        self.sent, self.sent_at = positions, now
        return JointTargets(positions.copy(), self.dt, False)
