"""A legged robot's 2D laser scanner, exactly as a ``sensor_msgs/LaserScan`` carries it.

The scanner's beams are the rays of the sensor layout (the hexapod's, paper Sec. V-A: 25
beams over [-90, 90] deg, 2 m): evenly spaced, so a scan is ``angle_min``,
``angle_increment`` and the ranges. LaserScan stores these as float32; the scanner rounds
them the same way and casts its rays along ``angle_min + k * angle_increment`` computed
from the rounded values, as the laser node does. Offline evolution and the ROS graph
therefore see identical numbers, which keeps a lockstep run equal to the offline replay
cycle by cycle.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from evorbc_ros.sensors import RangefinderLayout
from sim_bridge.legged.physics import LeggedSim


@dataclass(frozen=True)
class Scanner:
    """Evenly spaced beams in the body frame (rad), float32 like a LaserScan."""

    angle_min: float  # rad, float32 value
    angle_increment: float  # rad, float32 value
    beams: int
    range_max: float  # m
    range_min: float = 0.0  # m
    mount_height: float = 0.04  # m above the body centre; rays stay horizontal

    @classmethod
    def from_layout(cls, layout: RangefinderLayout, mount_height: float = 0.04) -> Scanner:
        """The scanner whose beams are the layout's rays (sorted, evenly spaced).

        Raises:
            ValueError: the rays are not evenly spaced, so no single scan holds them.
        """
        rays = np.unique(np.round(layout.ray_angles().ravel(), 12))
        if len(rays) < 2:
            raise ValueError("a scanner needs at least two beams")
        steps = np.diff(rays)
        if np.ptp(steps) > 1e-9:
            raise ValueError("the layout's rays are not evenly spaced; no LaserScan holds them")
        return cls(
            angle_min=float(np.float32(rays[0])),
            angle_increment=float(np.float32(steps.mean())),
            beams=len(rays),
            range_max=float(layout.max_range),
            mount_height=mount_height,
        )

    @property
    def angle_max(self) -> float:
        """Direction of the last beam (rad), as LaserScan's ``angle_max``."""
        return float(np.float32(self.angle_min + self.angle_increment * (self.beams - 1)))

    def angles(self) -> np.ndarray:
        """Beam directions (rad, body frame), computed as the laser node computes them."""
        return self.angle_min + self.angle_increment * np.arange(self.beams)

    def scan(self, sim: LeggedSim, base: tuple | None = None) -> np.ndarray:
        """``(beams,)`` float32 ranges (m) from the robot in ``sim``; +inf: no return.

        ``base``: the body's :meth:`~LeggedSim.base_pose` read since the last step, or
        None to read it now.
        """
        base = sim.base_pose() if base is None else base
        height = base[0][2] + self.mount_height
        return sim.laser(self.angles(), self.range_max, height, base).astype(np.float32)
