"""Inputs from the robot's pose and the goal (pure code of the radar node).

Poses come from odometry (``nav_msgs/Odometry``: position and orientation quaternion in a
fixed frame) and the goal as a point in the same frame. The bearing of the goal in the body
frame gives the goal-sector readings (4WS) or the goal-bearing reading (hexapod), with the
formulas of :mod:`evorbc_ros.sensors`; a layout with a motion input adds the distance moved
over its window (:mod:`evorbc_ros.motion`), for which the pose's stamp counts.
"""

from __future__ import annotations

import math

import numpy as np

from evorbc_ros.laser import InputError
from evorbc_ros.motion import MotionWindow
from evorbc_ros.sensors import SensorLayout, goal_bearing_reading, goal_sector_readings


def yaw_from_quaternion(x: float, y: float, z: float, w: float) -> float:
    """Yaw (rad, about z) of an orientation quaternion.

    Raises:
        InputError: non-finite components or a quaternion far from unit length.
    """
    q = (x, y, z, w)
    if not all(math.isfinite(v) for v in q):
        raise InputError(f"orientation {q} is not finite")
    norm = math.sqrt(sum(v * v for v in q))
    if not 0.9 < norm < 1.1:
        raise InputError(f"orientation quaternion has length {norm:.3g}, expected 1")
    return quaternion_yaw(x, y, z, w)


def quaternion_yaw(x: float, y: float, z: float, w: float) -> float:
    """Yaw (rad, about z) of a unit quaternion, unchecked; numba compiles it to the same bits.

    The offline episode kernel computes an adapting controller's odometry yaw with it, as
    the arbitrator node does from the odometry message (docs/design/adaptation.md).
    """
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


class GoalInputs:
    """Every input of a layout after the rangefinders: goal sectors, bearing and motion.

    The motion input keeps the poses of its window; :meth:`reset` forgets them.
    """

    def __init__(self, layout: SensorLayout):
        if layout.goal_sectors is None and not layout.goal_bearing and layout.motion is None:
            raise ValueError("the sensor layout has no goal or motion inputs")
        self.layout = layout
        self.motion = MotionWindow(layout.motion) if layout.motion else None

    def reset(self) -> None:
        """Forget the motion input's poses (a new episode); nothing else has state."""
        if self.motion is not None:
            self.motion.reset()

    @property
    def names(self) -> list[str]:
        """Names of the readings, in order."""
        n_range = len(self.layout.rangefinders.angles) if self.layout.rangefinders else 0
        return self.layout.input_names()[n_range:]

    def readings(
        self, x: float, y: float, yaw: float, gx: float, gy: float, stamp_ns: int | None = None
    ) -> np.ndarray:
        """Readings for a robot at ``(x, y, yaw)`` and a goal at ``(gx, gy)`` (one frame).

        ``stamp_ns``: the pose's time (ns), which a motion input needs (ValueError without).

        Raises:
            InputError: a non-finite pose or goal (the motion window keeps no such pose).
        """
        for name, v in (("x", x), ("y", y), ("yaw", yaw), ("goal x", gx), ("goal y", gy)):
            if not math.isfinite(v):
                raise InputError(f"{name} is {v}, expected a finite number")
        bearing = math.atan2(gy - y, gx - x) - yaw
        out = []
        if self.layout.goal_sectors is not None:
            out.extend(goal_sector_readings(bearing, self.layout.goal_sectors))
        if self.layout.goal_bearing:
            out.append(goal_bearing_reading(bearing))
        if self.motion is not None:
            if stamp_ns is None:
                raise ValueError("the layout's motion input needs the pose's stamp")
            out.append(self.motion.reading(stamp_ns, x, y))
        return np.array(out, dtype=np.float64)
