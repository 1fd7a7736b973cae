"""Quality (fitness) metrics of a locomotion primitive (paper Sec. III-A, docs/design.md section 3).

Every metric takes the outcome of primitives executed for T seconds from rest at the
origin facing +x, as arrays: final position ``x, y`` (m, start frame), final heading
``heading`` (rad, any winding), path length ``path`` (m) and, for legged robots, the
largest tilt seen ``max_tilt`` (rad). Every metric returns ``(n,)`` qualities; NaN marks a
primitive that must be discarded.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from evorbc_ros.repertoire_checks import QUALITY_RANGES
from sim_bridge.robots.base import PrimitiveOutcome

#: Tilt above which a legged primitive is discarded (paper eq. 6, T = 45 deg).
MAX_TILT = np.radians(45.0)


def wrap_angle(angle: np.ndarray) -> np.ndarray:
    """Wrap angles (rad) into (-pi, pi]."""
    wrapped = np.mod(np.asarray(angle, dtype=np.float64) + np.pi, 2.0 * np.pi) - np.pi
    return np.where(wrapped == -np.pi, np.pi, wrapped)


def _heading_quality(desired: np.ndarray, heading: np.ndarray) -> np.ndarray:
    return 1.0 - np.abs(wrap_angle(desired - heading)) / np.pi


def circular_quality(o: PrimitiveOutcome) -> np.ndarray:
    """Circular metric: heading against the tangent of the circle through the end point.

    quality = 1 - |wrap(omega - lambda)| / pi, with omega the tangent at (x, y) of the
    circle through the origin that is tangent to the initial heading: omega = 2 atan2(y, x).
    The doubling maps backward arcs onto the same formula: a robot that reverses along
    the circle ends facing its forward tangent, so no case split is needed.
    """
    return _heading_quality(2.0 * np.arctan2(o.y, o.x), o.heading)


def radial_quality(o: PrimitiveOutcome) -> np.ndarray:
    """Radial metric: heading against the bearing of the end point from the start.

    quality = 1 - |wrap(omega - lambda)| / pi, with omega = atan2(y, x), plus pi behind the
    start (x < 0) so that the robot faces forward while moving backward.
    """
    desired = np.arctan2(o.y, o.x) + np.where(o.x < 0.0, np.pi, 0.0)
    return _heading_quality(desired, o.heading)


def distance_quality(o: PrimitiveOutcome) -> np.ndarray:
    """Straight-line displacement over path length: 1 for a straight path, 0 for none."""
    reach = np.hypot(o.x, o.y)
    with np.errstate(invalid="ignore", divide="ignore"):
        q = np.where(o.path > 0.0, reach / o.path, 0.0)
    # Round-off can put a straight path a hair above 1.
    return np.minimum(q, 1.0)


def circular_tilt_quality(o: PrimitiveOutcome) -> np.ndarray:
    """Paper eq. 6: 1 - tilt / 45 deg + circular, or NaN (discard) above 45 deg of tilt."""
    if o.max_tilt is None:
        raise ValueError("metric 'circular+tilt' needs the tilt of a legged robot")
    q = 1.0 - o.max_tilt / MAX_TILT + circular_quality(o)
    return np.where(o.max_tilt > MAX_TILT, np.nan, q)


def _sum(*metrics: Callable[[PrimitiveOutcome], np.ndarray]):
    def combined(o: PrimitiveOutcome) -> np.ndarray:
        return np.sum([m(o) for m in metrics], axis=0)

    return combined


class Metric(NamedTuple):
    """A quality metric and the range of qualities it gives (``low <= q <= high``)."""

    function: Callable[[PrimitiveOutcome], np.ndarray]
    high: float
    low: float


def _metric(name: str, function: Callable[[PrimitiveOutcome], np.ndarray]) -> Metric:
    # The range lives with the onboard package, which checks repertoire files against it
    # and must not import this module (docs/design.md section 12).
    low, high = QUALITY_RANGES[name]
    return Metric(function, high, low)


#: Metric name -> (function, highest possible quality, lowest possible quality).
METRICS: dict[str, Metric] = {
    "circular": _metric("circular", circular_quality),
    "radial": _metric("radial", radial_quality),
    "distance": _metric("distance", distance_quality),
    "distance+circular": _metric("distance+circular", _sum(distance_quality, circular_quality)),
    "distance+radial": _metric("distance+radial", _sum(distance_quality, radial_quality)),
    "circular+tilt": _metric("circular+tilt", circular_tilt_quality),
}


def quality_metric(name: str) -> Callable[[PrimitiveOutcome], np.ndarray]:
    """The metric called ``name``; raises ``KeyError`` naming the known metrics."""
    try:
        return METRICS[name][0]
    except KeyError:
        known = ", ".join(METRICS)
        raise KeyError(f"unknown quality metric {name!r}; expected one of {known}") from None
