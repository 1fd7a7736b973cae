"""The bridge's world for a differential-drive robot.

The kinematic world's maze, walls, laser and episode
(:class:`~sim_bridge.world.KinematicWorld`), with the differential-drive motion model
(:mod:`sim_bridge.diff_drive.motion`).
"""

from __future__ import annotations

import numpy as np

from evorbc_ros.robots.registry import lookup
from sim_bridge.diff_drive.motion import OMEGA, STATE_SIZE, V, body_twist, diff_limits, step_diff
from sim_bridge.world import KinematicWorld

_NO_BOXES = np.empty((0, 6))
_NO_CANDIDATES = np.empty(0, dtype=np.int64)


class DiffDriveWorld(KinematicWorld):
    """A differential-drive robot in a maze, stepped by body twists ``(v m/s, omega rad/s)``.

    Constructed as :class:`~sim_bridge.world.KinematicWorld`; ``robot`` names a registered
    differential-drive robot (its ``model`` is its geometry) and ``geometry`` may replace it.
    """

    def _model(self, robot: str, geometry) -> None:
        self.robot_name = robot
        self.geometry = geometry or lookup(robot).model
        self.limits = diff_limits(self.geometry)
        self.state_size = STATE_SIZE
        self.n_wheels = 2

    def _move(self, command: np.ndarray) -> float:
        return step_diff(self.state, 0, command, self.limits, _NO_BOXES, _NO_CANDIDATES)

    def _roll_wheels(self, wheel_radius: float) -> None:
        """Integrate the left and right wheels' rotation (rad) over the step."""
        left, right = self.wheel_speeds
        self.wheel_angle += np.array([left, right]) * self.limits.dt / wheel_radius

    @property
    def twist(self) -> tuple[float, float]:
        """The body's ``(v m/s, omega rad/s)`` this step (after the wheels' limit)."""
        return body_twist(self.state[0, V], self.state[0, OMEGA], self.limits)

    @property
    def wheel_speeds(self) -> tuple[float, float]:
        """``(left, right)`` wheel rim speeds (m/s)."""
        v, omega = self.twist
        half = 0.5 * self.geometry.wheel_separation * omega
        return v - half, v + half

    @property
    def speed(self) -> float:
        """Forward speed of the body (m/s)."""
        return float(self.twist[0])
