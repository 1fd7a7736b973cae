"""Walls, rooms and posts as segments, an independent ray cast, and the scans and
rangefinder readings that follow from them (for the laser tests and bench/bench_laser.py).

Written apart from :mod:`evorbc_ros.scan_geometry`: a plain analytic ray-segment
intersection, cast from each rangefinder's own mount point (body frame, m, rad).
"""

from __future__ import annotations

import math

import numpy as np

from evorbc_ros.laser import LaserPose
from evorbc_ros.sensors import RangefinderLayout, range_reading

FAR = 20.0  # m, half length of a "long" wall


def cast(ox, oy, dx, dy, segments: np.ndarray) -> np.ndarray:
    """Distance along each ray ``o + t d`` (|d| = 1) to the nearest segment, +inf if none.

    Args:
        ox, oy, dx, dy: ``(r,)`` ray origins and unit directions.
        segments: ``(s, 4)`` rows ``x0, y0, x1, y1``.
    """
    ox, oy, dx, dy = (
        np.atleast_1d(np.asarray(v, dtype=np.float64))[:, None] for v in (ox, oy, dx, dy)
    )
    x0, y0, x1, y1 = segments.T
    # Solve o + t d = p0 + s (p1 - p0) for t and s by Cramer's rule.
    wx, wy = x1 - x0, y1 - y0
    det = -dx * wy + dy * wx
    rx, ry = x0 - ox, y0 - oy
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (-rx * wy + ry * wx) / det
        s = (dx * ry - dy * rx) / det
    hit = (det != 0) & (t >= 0) & (s >= 0) & (s <= 1)
    return np.where(hit, t, np.inf).min(axis=1)


def wall(side: str, d: float) -> np.ndarray:
    """A long straight wall ``d`` m from the body centre: in front, behind, left or right."""
    return np.array(
        {
            "front": [[d, -FAR, d, FAR]],
            "behind": [[-d, -FAR, -d, FAR]],
            "left": [[-FAR, d, FAR, d]],
            "right": [[-FAR, -d, FAR, -d]],
        }[side]
    )


def box(x0, y0, x1, y1) -> np.ndarray:
    """The four walls of an axis-aligned rectangle."""
    return np.array([[x0, y0, x1, y0], [x1, y0, x1, y1], [x1, y1, x0, y1], [x0, y1, x0, y0]])


def post(cx, cy, half, turn) -> np.ndarray:
    """A square post of side ``2 half`` centred at ``(cx, cy)``, turned by ``turn`` rad."""
    c, s = math.cos(turn), math.sin(turn)
    corners = [(cx + c * x - s * y, cy + s * x + c * y) for x, y in
               ((-half, -half), (half, -half), (half, half), (-half, half))]  # fmt: skip
    return np.array([[*corners[k], *corners[(k + 1) % 4]] for k in range(4)])


def scan(pose: LaserPose, segments: np.ndarray, n: int, range_max: float = 8.0, angle_min=-math.pi):
    """A full turn of ``n`` beams from ``angle_min`` (scanner frame) of a scanner at ``pose``.

    Returns ``angle_min``, the increment, and ranges (+inf: no return within range_max).
    """
    inc = 2 * math.pi / n
    a = angle_min + inc * np.arange(n) + pose.yaw
    r = cast(np.full(n, pose.x), np.full(n, pose.y), np.cos(a), np.sin(a), segments)
    return angle_min, inc, np.where(r <= range_max, r, np.inf)


def ray_distances(layout: RangefinderLayout, segments: np.ndarray, offsets) -> np.ndarray:
    """``(n_rangefinders, len(offsets))`` distances from the mount ring along rays at
    ``axis + offset`` (rays start at ``mount_radius`` along their own direction)."""
    a = (np.asarray(layout.angles)[:, None] + np.asarray(offsets)[None, :]).ravel()
    m = layout.mount_radius
    d = cast(m * np.cos(a), m * np.sin(a), np.cos(a), np.sin(a), segments)
    return d.reshape(len(layout.angles), -1)


def true_distances(layout: RangefinderLayout, segments: np.ndarray) -> np.ndarray:
    """``(n_rangefinders,)`` what each rangefinder's rays read, m from the mount ring.

    A field of view reads the nearest wall point inside it: the edge rays' hits, and the
    nearest point of each segment to the centre (its foot or an end) if inside the field
    of view and ahead of the mount ring. Exact for straight segments.
    """
    half = 0.5 * layout.field_of_view
    d = ray_distances(layout, segments, [-half, 0.0, half] if half else [0.0]).min(axis=1)
    if not half:
        return d
    x0, y0, x1, y1 = segments.T
    wx, wy = x1 - x0, y1 - y0
    s = np.clip(-(x0 * wx + y0 * wy) / (wx * wx + wy * wy), 0.0, 1.0)
    pts = np.concatenate(
        [np.stack([x0 + s * wx, y0 + s * wy], 1), segments[:, :2], segments[:, 2:]]
    )
    rho = np.hypot(pts[:, 0], pts[:, 1])
    bearing = np.arctan2(pts[:, 1], pts[:, 0])
    for k, axis in enumerate(layout.angles):
        off = np.abs(np.mod(bearing - axis + math.pi, 2 * math.pi) - math.pi)
        inside = (off <= half) & (rho >= layout.mount_radius)
        if inside.any():
            d[k] = min(d[k], rho[inside].min() - layout.mount_radius)
    return d


def true_readings(layout: RangefinderLayout, segments: np.ndarray) -> np.ndarray:
    """The rangefinder readings a ray cast from the mount points gives."""
    return np.array([range_reading(v, layout.max_range) for v in true_distances(layout, segments)])
