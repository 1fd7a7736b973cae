"""Today's laser conversion, kept verbatim as the reference for the centred, all-valid case.

This is ``evorbc_ros.laser.LaserToRangefinders`` as it was before issue 18 (commit 26768b6):
a beam belongs to a rangefinder by its direction from the body centre, and one invalid beam
on an axis refuses the scan. The new code must give bit-for-bit the same readings for a
scanner at the body centre whose beams are all valid (the hexapod's offline episodes and the
lockstep parity tests depend on it); ``tests/test_laser_reference.py`` compares the two.
"""

from __future__ import annotations

import math

import numpy as np

from evorbc_ros.laser import InputError, LaserPose
from evorbc_ros.sensors import RangefinderLayout, range_reading

ANGLE_TOLERANCE = 1e-6


def _wrap(angle: np.ndarray) -> np.ndarray:
    return np.mod(angle + np.pi, 2.0 * np.pi) - np.pi


class OldLaserToRangefinders:
    """The conversion before issue 18 (reference only)."""

    def __init__(self, layout: RangefinderLayout, pose: LaserPose = LaserPose()):  # noqa: B008
        self.layout = layout
        self.pose = pose
        self.axes = np.asarray(layout.angles, dtype=np.float64)  # (n,) body frame, rad
        self._beam_key: tuple | None = None  # the scan geometry _beam_cos_sin last saw
        self._beam_cos_sin: tuple[np.ndarray, np.ndarray] = (np.empty(0), np.empty(0))

    def unseen(self, angle_min: float, angle_increment: float, n_beams: int) -> list[float]:
        """Axes (deg, body frame) of the rangefinders that a scan with this span never covers.

        They read 0 ("nothing seen") from such a scanner; the arbitrator was evolved with
        them, so the node warns rather than refusing every scan.
        """
        heading = angle_min + angle_increment * np.arange(n_beams) + self.pose.yaw
        # Directions of points 1 m along each beam, as ``readings`` takes for no return.
        direction = np.arctan2(self.pose.y + np.sin(heading), self.pose.x + np.cos(heading))
        missed = ~(self._offsets(direction) <= self._reach(angle_increment)).any(axis=1)
        return [round(math.degrees(a), 1) for a in self.axes[missed]]

    def _offsets(self, direction: np.ndarray) -> np.ndarray:
        """(n_axes, n_beams) angle (rad) of each beam direction from each rangefinder axis."""
        return np.abs(_wrap(direction[None, :] - self.axes[:, None]))

    def _reach(self, angle_increment: float) -> float:
        """Largest offset (rad) at which a beam counts for a rangefinder.

        Half its field of view, or for a one-ray rangefinder half the beam spacing.
        """
        half_fov = 0.5 * self.layout.field_of_view
        return (half_fov if half_fov > 0.0 else 0.5 * abs(angle_increment)) + ANGLE_TOLERANCE

    def _cos_sin(
        self, angle_min: float, angle_increment: float, n_beams: int
    ) -> tuple[np.ndarray, np.ndarray]:
        """Cosine and sine of each beam's direction in the body frame.

        A scanner publishes the same span in every scan, so they are computed again only
        when the span (or the scanner's pose) changes: the same operations on the same
        values, so the same bits as computing them every scan.
        """
        key = (float(angle_min), float(angle_increment), n_beams, self.pose)
        if key != self._beam_key:
            beam = angle_min + angle_increment * np.arange(n_beams)  # laser frame, rad
            heading = beam + self.pose.yaw
            self._beam_cos_sin = (np.cos(heading), np.sin(heading))
            self._beam_key = key
        return self._beam_cos_sin

    def readings(
        self, angle_min: float, angle_increment: float, ranges, range_min: float, range_max: float
    ) -> np.ndarray:
        """Rangefinder readings in [0, 1] from one scan.

        Raises:
            InputError: a malformed scan (non-finite or zero increment, non-finite angles or
                limits, no beams), or one whose beams towards a rangefinder are all invalid.
        """
        r = np.asarray(ranges, dtype=np.float64)
        for name, value in (
            ("angle_min", angle_min),
            ("angle_increment", angle_increment),
            ("range_min", range_min),
            ("range_max", range_max),
        ):
            if not math.isfinite(value):
                raise InputError(f"{name} is {value}, expected a finite number")
        if angle_increment == 0.0:
            raise InputError("angle_increment is 0: beam directions are undefined")
        if r.ndim != 1 or r.size == 0:
            raise InputError("the scan has no ranges")
        if range_max <= 0 or range_min < 0 or range_min > range_max:
            raise InputError(f"range limits [{range_min}, {range_max}] are not valid")

        finite_r = np.isfinite(r)
        valid = ~np.isnan(r) & ~(finite_r & (r < range_min))
        touching = np.isneginf(r)
        seen = valid & finite_r & (r <= range_max)
        dist = np.where(seen, r, np.inf)
        dist = np.where(touching, 0.0, dist)
        # Hit points in the body frame. A beam's direction from the body centre comes from
        # its hit point; beams with no return or a zero range use a point 1 m along the beam.
        cos, sin = self._cos_sin(angle_min, angle_increment, r.size)
        finite = np.isfinite(dist)
        along = np.where(finite & (dist > 0.0), dist, 1.0)
        direction = np.arctan2(self.pose.y + along * sin, self.pose.x + along * cos)
        reached = np.where(finite, dist, 0.0)
        hx = self.pose.x + reached * cos
        hy = self.pose.y + reached * sin
        from_centre = np.where(finite, np.hypot(hx, hy), np.inf)
        from_mount = np.maximum(from_centre - self.layout.mount_radius, 0.0)

        offset = self._offsets(direction)
        reach = self._reach(angle_increment)
        if self.layout.field_of_view > 0.0:
            inside = offset <= reach
            members = valid[None, :] & inside
            in_span, usable = inside.any(axis=1), members.any(axis=1)
            nearest = np.where(members, from_mount[None, :], np.inf).min(axis=1)
        else:
            # One ray: the beam nearest the axis (first of equals), if within half a gap.
            candidates = np.where(valid[None, :], offset, np.inf)
            j = np.argmin(candidates, axis=1)
            usable = candidates[np.arange(len(j)), j] <= reach
            in_span = offset.min(axis=1) <= reach
            nearest = np.where(usable, from_mount[j], np.inf)
        blind = in_span & ~usable
        if blind.any():
            # The scanner looks that way but every beam there is invalid: reading it as
            # "nothing seen" (0) would steer the robot blind. Refuse the scan instead, so the
            # input goes stale and the executor stops the robot. (Directions the scan does
            # not span at all read 0, as a fixed property of the scanner; see ``unseen``.)
            k = int(np.argmax(blind))
            raise InputError(
                f"no valid beam for the rangefinder at {math.degrees(self.axes[k]):.1f} deg "
                f"(body frame): {int(np.isnan(r).sum())} of the scan's {r.size} ranges are "
                "NaN or below range_min"
            )
        return np.array([range_reading(float(d), self.layout.max_range) for d in nearest])
