"""Simulated sensors of a robot in a maze, compiled (docs/design.md section 5).

The reading formulas are the onboard ones from :mod:`evorbc_ros.sensors`, compiled as they
are, so the simulator and the ROS sensor nodes cannot drift apart. Rays are cast against
the maze's wall boxes (see :mod:`sim_bridge.geometry`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba as nb
import numpy as np

from evorbc_ros import sensors as onboard
from evorbc_ros.sensors import SensorLayout
from sim_bridge.geometry import cast_ray_dir

range_reading = nb.njit(cache=True)(onboard.range_reading)
in_sector = nb.njit(cache=True)(onboard.in_sector)
tiling_sector = nb.njit(cache=True)(onboard.tiling_sector)
goal_bearing_reading = nb.njit(cache=True)(onboard.goal_bearing_reading)
motion_reading = nb.njit(cache=True)(onboard.motion_reading)


class CompiledLayout(NamedTuple):
    """A :class:`SensorLayout` as arrays for the compiled kernels (see :func:`compile_layout`).

    Attributes:
        ray_angles: ``(n_rangefinders, rays)`` ray directions in the body frame, rad.
        max_range, mount_radius: m.
        sector_centres: ``(n_sectors,)`` rad; ``sector_width`` rad; ``sector_tiles`` 1 if
            the sectors tile the circle (one index per bearing), else 0.
        goal_bearing: 1 if the layout has a goal-bearing input, else 0.
        motion_cycles: the motion input's window in control cycles; 0: no motion input.
        motion_distance: m moved over the window that reads as 1.
        n_inputs: number of arbitrator inputs.
    """

    ray_angles: np.ndarray
    max_range: float
    mount_radius: float
    sector_centres: np.ndarray
    sector_width: float
    sector_tiles: int
    goal_bearing: int
    motion_cycles: int
    motion_distance: float
    n_inputs: int

    def reach(self) -> float:
        """How far from the body centre a ray can see (m)."""
        return self.mount_radius + self.max_range


def compile_layout(layout: SensorLayout, period: float = 0.1) -> CompiledLayout:
    """The arrays of ``layout`` for episodes of ``period`` s control cycles.

    Raises:
        ValueError: a motion window of no whole number of cycles
            (:meth:`~evorbc_ros.sensors.MotionLayout.cycles`).
    """
    rf = layout.rangefinders
    gs = layout.goal_sectors
    return CompiledLayout(
        ray_angles=(rf.ray_angles() if rf else np.zeros((0, 1))).astype(np.float64),
        max_range=float(rf.max_range) if rf else 1.0,
        mount_radius=float(rf.mount_radius) if rf else 0.0,
        sector_centres=np.array(gs.centres if gs else (), dtype=np.float64),
        sector_width=float(gs.width) if gs else 0.0,
        sector_tiles=int(bool(gs and gs.tiles)),
        goal_bearing=int(layout.goal_bearing),
        motion_cycles=layout.motion.cycles(period) if layout.motion else 0,
        motion_distance=float(layout.motion.distance) if layout.motion else 1.0,
        n_inputs=layout.n_inputs,
    )


@nb.njit(cache=True)
def read_sensors(x, y, heading, tx, ty, rx, ry, layout, boxes, candidates, out):
    """Write the arbitrator inputs of a robot at pose ``(x, y, heading)`` into ``out``.

    ``(tx, ty)`` is the goal (m, world); ``(rx, ry)`` the position a motion input compares
    with (one window ago, or the episode's first; unread without one); ``layout`` a
    :class:`CompiledLayout`. Rangefinder rays start at the mount point on the body's edge;
    goal sectors and bearing come from the goal's bearing in the body frame.
    """
    # Fields as locals: numba does not hoist NamedTuple loads out of the loops.
    ray_angles, max_range, mount = layout.ray_angles, layout.max_range, layout.mount_radius
    centres, width = layout.sector_centres, layout.sector_width
    n = 0
    for s in range(ray_angles.shape[0]):
        nearest = max_range
        for r in range(ray_angles.shape[1]):
            a = heading + ray_angles[s, r]
            dx = math.cos(a)
            dy = math.sin(a)
            d = cast_ray_dir(x + mount * dx, y + mount * dy, dx, dy, max_range, boxes, candidates)
            nearest = min(nearest, d)
        out[n] = range_reading(nearest, max_range)
        n += 1
    if centres.shape[0] > 0 or layout.goal_bearing:
        bearing = math.atan2(ty - y, tx - x) - heading
        n_sectors = centres.shape[0]
        if layout.sector_tiles:
            lit = tiling_sector(bearing, centres[0], width, n_sectors)
            for k in range(n_sectors):
                out[n + k] = 1.0 if k == lit else 0.0
        else:
            for k in range(n_sectors):
                inside = in_sector(bearing, centres[k], width)
                out[n + k] = 1.0 if inside else 0.0
        n += n_sectors
        if layout.goal_bearing:
            out[n] = goal_bearing_reading(bearing)
            n += 1
    if layout.motion_cycles > 0:
        out[n] = motion_reading(x - rx, y - ry, layout.motion_distance)
