"""What the primitive executor commands a hexapod (pure code).

A hexapod primitive is a gait (eq. 10-11): joint targets that change continuously. Every
command covers the next control period with one trajectory point per physics step
(``dt = 1 / trajectory_rate`` s), the targets of :class:`~evorbc_ros.robots.hexapod.GaitTable`
sampled at the gait time of each step, so the joints follow the gait smoothly between the
arbitrator's 10 Hz decisions.

The gait clock starts with the first primitive and counts whole physics steps,
``round((now - t0) / dt)``: a new primitive takes over at the current phase of the
oscillators (as in the paper's simulation, where the gait time is the episode time), and
the times are bit-identical to the offline simulation's. When the primitive or a sensor
input is stale, the command holds the last targets: the legs stop where they are and the
robot stands still.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from evorbc_ros.executor import InputWatch
from evorbc_ros.robots.hexapod import (
    HEXAPOD,
    N_PARAMETERS,
    SERVO_RATE,
    GaitTable,
    HexapodGeometry,
    gait_step_times,
)


@dataclass(frozen=True)
class JointTargets:
    """One command for the hexapod: joint targets at evenly spaced times."""

    positions: np.ndarray  # (points, 18) rad, JOINT_NAMES order
    dt: float  # s between points; point k applies from k * dt after the command
    stopped: bool  # True when this is the safety stop (one point: hold)
    reason: str = ""


class HexapodExecutor(InputWatch):
    """The hexapod's executor: the current gait as joint-target trajectories."""

    def __init__(
        self,
        inputs: list[str],
        stale_timeout: float = 0.3,
        trajectory_rate: float = SERVO_RATE,
        geometry: HexapodGeometry | None = None,
    ):
        super().__init__(HEXAPOD, N_PARAMETERS, inputs, stale_timeout)
        self.geometry = geometry or HexapodGeometry()
        self.dt = 1.0 / trajectory_rate
        self.points = max(1, round(self.geometry.control_period * trajectory_rate))
        self.gait_start: float | None = None  # clock time (s) of the first primitive
        self.table: GaitTable | None = None
        self.held = self.geometry.neutral_pose()  # (18,) rad, last target sent

    def on_primitive(self, genes, now: float) -> None:
        """A new primitive; the gait clock starts with the first one."""
        super().on_primitive(genes, now)
        self.table = GaitTable(self.genes, self.geometry)
        if self.gait_start is None:
            self.gait_start = now

    def gait_step(self, now: float) -> int:
        """Whole physics steps since the gait began."""
        return round((now - self.gait_start) / self.dt)

    def command(self, now: float) -> JointTargets:
        """Targets for the next control period from ``now``, or a hold if stopped."""
        reason = self.stop_reason(now)
        if reason:
            return JointTargets(self.held[None, :].copy(), self.dt, True, reason)
        times = gait_step_times(self.gait_step(now), self.points, self.dt)
        positions = self.table.joint_targets(times, np.zeros(self.points, dtype=np.int64))
        self.held = positions[-1].copy()
        return JointTargets(positions, self.dt, False)
