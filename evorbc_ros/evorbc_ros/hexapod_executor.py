"""What the primitive executor commands a hexapod (pure code).

The legged robot's executor (:mod:`evorbc_ros.legged_executor`) with the hexapod's gait:
every command is a trajectory of the 18 joints' targets, one point per physics step
(50 Hz), covering the stale timeout ahead; a stop holds the point being tracked.
"""

from __future__ import annotations

from evorbc_ros.legged_executor import JointTargets, LeggedExecutor
from evorbc_ros.robots.hexapod import HEXAPOD, SERVO_RATE, GaitTable, HexapodGeometry, hexapod_gait

__all__ = ["HexapodExecutor", "JointTargets"]


class HexapodExecutor(LeggedExecutor):
    """The hexapod's executor: the current gait as joint-target trajectories."""

    def __init__(
        self,
        inputs: list[str],
        stale_timeout: float = 0.3,
        trajectory_rate: float = SERVO_RATE,
        geometry: HexapodGeometry | None = None,
        horizon: float | None = None,
    ):
        self.geometry = geometry or HexapodGeometry()
        super().__init__(
            HEXAPOD,
            hexapod_gait(self.geometry),
            inputs,
            stale_timeout,
            trajectory_rate,
            self.geometry.control_period,
            horizon,
        )

    def make_table(self, genes) -> GaitTable:
        """The hexapod's gait table of one primitive's genes."""
        return GaitTable(genes, self.geometry)
