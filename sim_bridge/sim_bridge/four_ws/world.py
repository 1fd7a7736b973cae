"""The bridge's world for a 4WS robot: the kinematic world with the 4WS motion model.

The robot moves by :func:`sim_bridge.four_ws.motion.step_robot`, the model offline
evolution steps (docs/design.md section 2), or with a damaged wheel by
:func:`sim_bridge.four_ws.damaged.step_damaged`; the maze, walls, laser and episode are
:class:`~sim_bridge.world.KinematicWorld`'s.
"""

from __future__ import annotations

import numpy as np

from evorbc_ros.robots.registry import robot_type
from sim_bridge.four_ws.damaged import step_damaged
from sim_bridge.four_ws.motion import ANGLE_FL, SPEED, STATE_SIZE, motion_limits, step_robot
from sim_bridge.world import KinematicWorld

_NO_BOXES = np.empty((0, 6))
_NO_CANDIDATES = np.empty(0, dtype=np.int64)


class FourWSWorld(KinematicWorld):
    """A 4WS robot in a maze, stepped by wheel commands ``(speed m/s, fl, fr, rl, rr rad)``.

    Constructed as :class:`~sim_bridge.world.KinematicWorld`; ``robot`` names a registered
    4WS robot type and ``geometry`` (a :class:`~evorbc_ros.robots.four_ws.FourWSGeometry`)
    may replace its body.
    """

    def _model(self, robot: str, geometry) -> None:
        """The robot's type, geometry and limits."""
        self.type = robot_type(robot)
        self.geometry = geometry or self.type.body()
        self.limits = motion_limits(self.geometry)
        self.state_size = STATE_SIZE
        self.n_wheels = 4

    def _move(self, command: np.ndarray) -> float:
        if self.damage is not None:  # cycle: the one this step runs, as the kernel's t
            return step_damaged(
                self.state, 0, command, self.limits, _NO_BOXES, _NO_CANDIDATES,
                self.damage, self.damage_key, self.cycles,
            )  # fmt: skip
        return step_robot(self.state, 0, command, self.limits, _NO_BOXES, _NO_CANDIDATES)

    def _roll_wheels(self, wheel_radius: float) -> None:
        """Integrate the wheels' rotation (rad) over the step: one speed for all four."""
        self.wheel_angle += self.state[0, SPEED] * self.limits.dt / wheel_radius

    @property
    def steering(self) -> np.ndarray:
        """(4,) current wheel angles (rad)."""
        return self.state[0, ANGLE_FL : ANGLE_FL + 4].copy()

    @property
    def speed(self) -> float:
        """Current wheel speed (m/s)."""
        return float(self.state[0, SPEED])
