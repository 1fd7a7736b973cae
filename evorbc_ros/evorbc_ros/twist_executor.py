"""What a differential-drive robot's executor commands, and when it stops (pure code).

The counterpart of :class:`evorbc_ros.executor.PrimitiveExecutor` for a robot driven by a
body twist (:mod:`evorbc_ros.robots.diff_drive`): the current primitive's genes scaled to
``(v m/s, omega rad/s)``; a zero twist when the primitive or an input is stale, or the
arbitrator chose no primitive (:class:`~evorbc_ros.executor.InputWatch`).
"""

from __future__ import annotations

from dataclasses import dataclass

from evorbc_ros.executor import InputWatch
from evorbc_ros.robots.diff_drive import DiffDriveGeometry


@dataclass(frozen=True)
class TwistCommand:
    """One command for a differential-drive robot."""

    linear: float  # m/s, body x
    angular: float  # rad/s, about body z
    stopped: bool  # True when this is the safety stop
    reason: str = ""  # why the robot is stopped


class TwistExecutor(InputWatch):
    """The current primitive as a body twist; a zero twist to stop."""

    def __init__(
        self, name: str, geometry: DiffDriveGeometry, inputs: list[str], stale_timeout=0.3
    ):
        super().__init__(name, 2, inputs, stale_timeout)
        self.geometry = geometry

    def command(self, now: float) -> TwistCommand:
        """The command to send at time ``now``."""
        reason = self.stop_reason(now)
        if reason:
            return TwistCommand(0.0, 0.0, True, reason)
        v, omega = self.geometry.commands(self.genes)
        return TwistCommand(float(v), float(omega), False)
