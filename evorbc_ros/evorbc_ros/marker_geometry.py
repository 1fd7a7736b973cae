"""Where the visualization markers go, in the robot's body frame (pure code; m and rad).

x forward, y left, as everything onboard (docs/design.md section 1). The nodes turn these
points into visualization_msgs/MarkerArray messages (:mod:`evorbc_ros.nodes.markers`) when
their ``markers`` parameter is on:

* the laser node: each rangefinder's ray from its mount to what it reads (a reading r of a
  range R is a wall at R (1 - r) beyond the mount; nothing seen: the whole range);
* the radar node: the lit goal sectors as wedges, or the goal bearing as an arrow;
* the arbitrator: the mapping's target point and the chosen primitive's expected
  displacement (its recorded behaviour) and end heading.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from evorbc_ros.sensors import GoalSectorLayout, RangefinderLayout


def rangefinder_rays(layout: RangefinderLayout, readings: np.ndarray) -> np.ndarray:
    """``(n, 2, 2)``: each rangefinder's segment, mount point then reach (m, body frame).

    Args:
        layout: the rangefinders.
        readings: ``(n,)`` in [0, 1], 1 = touching (docs/design.md section 5).

    """
    axes = np.asarray(layout.angles, dtype=np.float64)
    direction = np.stack([np.cos(axes), np.sin(axes)], axis=1)
    mount = layout.mount_radius * direction
    reach = layout.max_range * (1.0 - np.clip(readings, 0.0, 1.0))
    return np.stack([mount, mount + reach[:, None] * direction], axis=1)


def sector_wedges(
    layout: GoalSectorLayout, readings: np.ndarray, radius: float, steps: int = 8
) -> np.ndarray:
    """``(k, 3, 2)``: triangles filling the lit sectors out to ``radius`` (m).

    A sector is lit when its reading is above 0.5 (they are 0 or 1).
    """
    triangles = []
    for centre, reading in zip(layout.centres, readings, strict=True):
        if reading <= 0.5:
            continue
        edges = np.linspace(centre - 0.5 * layout.width, centre + 0.5 * layout.width, steps + 1)
        arc = radius * np.stack([np.cos(edges), np.sin(edges)], axis=1)
        for a, b in itertools.pairwise(arc):
            triangles.append([[0.0, 0.0], a, b])
    return np.asarray(triangles, dtype=np.float64).reshape(-1, 3, 2)


def bearing_arrow(reading: float, length: float) -> np.ndarray:
    """``(2, 2)``: an arrow from the centre along the goal bearing that ``reading`` encodes.

    The reading maps a bearing in [-pi, pi) onto [0, 1) (docs/design.md section 5).
    """
    bearing = reading * 2.0 * math.pi - math.pi
    return np.array([[0.0, 0.0], [length * math.cos(bearing), length * math.sin(bearing)]])


def primitive_arrows(
    displacement: tuple[float, float], heading: float, length: float
) -> tuple[np.ndarray, np.ndarray]:
    """The chosen primitive's expected motion, two ``(2, 2)`` arrows (m).

    From the centre to its displacement, and a short one there along its end ``heading``
    (rad).
    """
    x, y = displacement
    move = np.array([[0.0, 0.0], [x, y]])
    turn = np.array([[x, y], [x + length * math.cos(heading), y + length * math.sin(heading)]])
    return move, turn


def reading_colour(reading: float) -> tuple[float, float, float]:
    """RGB in [0, 1]: green for nothing seen (0) through yellow to red for touching (1)."""
    r = min(max(reading, 0.0), 1.0)
    return (min(1.0, 2.0 * r), min(1.0, 2.0 * (1.0 - r)), 0.0)
