"""Rangefinder inputs from any ``sensor_msgs/LaserScan`` (pure code of the laser node).

The arbitrator was evolved with rangefinders mounted on the body's edge (see
:mod:`evorbc_ros.sensors`): each is one ray, or a fan of rays over its field of view, from
the body centre, starting at the mount ring. A real robot has a laser scanner somewhere on
its body; each rangefinder reads what its own rays would read (docs/laser.md):

* **Scanner at the body centre** (``laser_x = laser_y = 0``, any yaw). Every beam runs along
  a rangefinder ray, so it measures that ray directly. A one-ray rangefinder reads the valid
  beam nearest its axis; a field of view reads its nearest valid beam inside it. The
  distance from the mount point is ``d = |hit - centre| - mount_radius``. With every beam
  valid this is exactly the rule the shipped controllers were evolved and tested with.
* **Scanner anywhere else**: no beam runs along a rangefinder ray, so the scanner's view is
  rebuilt as surfaces in the body frame and the rays are cast into it
  (:mod:`evorbc_ros.scan_geometry`).

Range values follow REP 117: ``+inf`` is no return within range (nothing seen), ``-inf``
is an object closer than ``range_min`` (touching), NaN is an invalid measurement. Finite
values below ``range_min`` are invalid too; above ``range_max`` they are no return.

**Dropouts.** A valid beam stands in for its invalid neighbours within the tolerance of
:func:`beam_tolerance` (2.5 beam spacings, at least 1 deg and at most 5 deg). Only a
rangefinder that no valid beam covers is blind; then the scan is refused (the input goes
stale and the executor stops the robot): reading it as "nothing seen" would steer the robot
blind. A rangefinder outside the scan's span reads "nothing seen" as a fixed property of the
scanner; :meth:`LaserToRangefinders.coverage` lists them, and the node warns once.

**Beam count.** Beam ``k`` points at ``angle_min + k * angle_increment``. A scan whose
``angle_max`` lies more than one increment from its last beam's direction is refused (see
:func:`check_beam_count`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from evorbc_ros import scan_geometry as geo
from evorbc_ros.sensors import RangefinderLayout, range_reading


class InputError(ValueError):
    """A message cannot be used; the text says what is wrong with it."""


@dataclass(frozen=True)
class LaserPose:
    """Where the scanner sits on the robot: position (m) and yaw (rad) in the body frame."""

    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0


#: Slack (rad) when deciding whether a beam lies in a field of view or on an axis. LaserScan
#: angles are float32, rounded by up to about 1e-7 rad, and a layout's edge beams lie
#: exactly on its field-of-view edges.
ANGLE_TOLERANCE = 1e-6

#: Dropout tolerance: a valid beam counts for directions up to this many beam spacings
#: away, so any run of up to 4 invalid beams is bridged ...
TOLERANCE_SPACINGS = 2.5
#: ... but never less than this (rad): dense scanners (0.25 deg and finer) lose small
#: sectors, not single beams, to a speck of dust or a drop on the window ...
TOLERANCE_FLOOR = math.radians(1.0)
#: ... and never more (rad): 5 deg is 8.7 cm sideways at the 1 m range of the 4WS
#: rangefinders, about the robot's own half width. Coarse scanners (the hexapod's 7.5 deg
#: beams) still reach half a spacing, so a clean scan always covers what it spans.
TOLERANCE_CAP = math.radians(5.0)

#: ``angle_max`` may differ from the last beam's direction by this many increments: 0 is
#: the REP 138 convention, 1 covers drivers whose ``angle_max`` closes a full turn or ends
#: the last beam's interval; the 5 % is float32 rounding of the three angles.
BEAM_COUNT_SLACK = 1.05


def beam_tolerance(angle_increment: float) -> float:
    """How far (rad) from a valid beam its range counts for a rangefinder.

    2.5 beam spacings clipped to [1, 5] deg, and at least half a spacing (plus
    :data:`ANGLE_TOLERANCE`), so that every direction within a clean scan's span is covered.
    """
    spacing = abs(angle_increment)
    tol = min(max(TOLERANCE_SPACINGS * spacing, TOLERANCE_FLOOR), TOLERANCE_CAP)
    return max(tol, 0.5 * spacing + ANGLE_TOLERANCE)


def check_beam_count(
    angle_min: float, angle_max: float, angle_increment: float, n_beams: int
) -> None:
    """Refuse a scan whose number of ranges disagrees with its angles.

    Beam ``k`` is taken to point at ``angle_min + k * angle_increment`` (as REP 138 and the
    drivers define it); ``angle_max`` is accepted within one increment of the last beam's
    direction. Beyond that, the increment, the angles or the ranges are wrong, and some
    rangefinders would silently look the wrong way or read nothing.

    Raises:
        InputError: naming the counts and angles.
    """
    beyond = (angle_max - angle_min) / angle_increment - (n_beams - 1)  # increments
    if abs(beyond) <= BEAM_COUNT_SLACK:
        return
    expected = round((angle_max - angle_min) / angle_increment) + 1
    raise InputError(
        f"the scan has {n_beams} ranges, but angle_min {angle_min:.6g} to angle_max "
        f"{angle_max:.6g} rad at angle_increment {angle_increment:.6g} rad hold {expected} "
        "beams; refused, since beam directions are ambiguous (angle_max must lie within one "
        "increment of angle_min + (ranges - 1) * angle_increment)"
    )


@dataclass(frozen=True)
class Coverage:
    """Which rangefinders a scanner's span covers (axes in deg, body frame).

    Attributes:
        unseen: rangefinders the scan never covers; they read 0 ("nothing seen").
        partly: rangefinder axis -> share (0-1) of its rays' length (or of its field of
            view, for a scanner at the centre) that the scan covers; walls in the rest are
            not seen.
    """

    unseen: list[float] = field(default_factory=list)
    partly: dict[float, float] = field(default_factory=dict)


def _wrap(angle: np.ndarray) -> np.ndarray:
    return np.mod(angle + np.pi, 2.0 * np.pi) - np.pi


def _degrees(angle: float) -> float:
    return round(math.degrees(angle), 1)


class LaserToRangefinders:
    """Turns LaserScan ranges into the configured rangefinder readings."""

    def __init__(self, layout: RangefinderLayout, pose: LaserPose = LaserPose()):
        self.layout = layout
        self.pose = pose
        self.axes = np.asarray(layout.angles, dtype=np.float64)  # (n,) body frame, rad
        # Beams measure the rangefinder rays directly only from the body centre.
        self.centred = pose.x == 0.0 and pose.y == 0.0
        self.rays = layout.ray_angles()  # (n, rays) body frame, rad
        self._ray_cos_sin = (np.cos(self.rays.ravel()), np.sin(self.rays.ravel()))
        half = 0.5 * layout.field_of_view
        # Fields of view as wedges from the centre narrower than 180 deg (cone_nearest).
        cones = [geo.split_wedges(np.array([[a - half, a + half]])) for a in self.axes]
        self._cone_owner = np.repeat(np.arange(len(cones)), [len(c) for c in cones])
        self._cones = np.concatenate(cones) if half > 0.0 else np.empty((0, 2))
        self._beam_key: tuple | None = None  # the scan geometry the beam cache holds
        self._beam_cos_sin: tuple[np.ndarray, np.ndarray] = (np.empty(0), np.empty(0))
        self._beams: geo.ScanBeams | None = None

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
            self._beams = geo.ScanBeams.from_scan(
                heading, angle_increment, self.pose.x, self.pose.y
            )
            self._beam_key = key
        return self._beam_cos_sin

    def _scan_beams(self, angle_min: float, angle_increment: float, n_beams: int):
        self._cos_sin(angle_min, angle_increment, n_beams)
        return self._beams

    # -- coverage ----------------------------------------------------------------------

    def coverage(self, angle_min: float, angle_increment: float, n_beams: int) -> Coverage:
        """Which rangefinders a scan with this span covers, wholly, partly or not at all.

        Rangefinders it never covers read 0 ("nothing seen") from such a scanner; the
        arbitrator was evolved with them, so the node warns rather than refusing every scan.
        """
        if self.centred:
            return self._centred_coverage(angle_min, angle_increment, n_beams)
        beams = self._scan_beams(angle_min, angle_increment, n_beams)
        m, length = self.layout.mount_radius, self.layout.max_range
        dirs = self.rays.ravel()
        outside = geo.stretch_inside(beams.origin, dirs, beams.outside(), m, m + length)
        seen = (1.0 - outside / length).reshape(self.rays.shape)
        seen = np.where(seen > 1.0 - 1e-9, 1.0, np.where(seen < 1e-9, 0.0, seen))
        return self._report(seen.mean(axis=1), seen.max(axis=1) == 0.0)

    def _centred_coverage(self, angle_min, angle_increment, n_beams) -> Coverage:
        self._cos_sin(angle_min, angle_increment, n_beams)
        heading = self._beams.angle  # the beam directions, counter-clockwise
        gap = 0.5 * abs(angle_increment) + ANGLE_TOLERANCE

        def nearest(direction: np.ndarray) -> np.ndarray:
            return np.abs(_wrap(heading[None, :] - direction[:, None])).min(axis=1)

        in_span = nearest(self.axes) <= self._edge() + gap
        rays = (nearest(self.rays.ravel()) <= gap).reshape(self.rays.shape)
        return self._report(np.where(in_span, rays.mean(axis=1), 0.0), ~in_span)

    def _report(self, seen: np.ndarray, unseen: np.ndarray) -> Coverage:
        return Coverage(
            unseen=[_degrees(a) for a in self.axes[unseen]],
            partly={
                _degrees(a): round(float(s), 3)
                for a, s, u in zip(self.axes, seen, unseen, strict=True)
                if not u and s < 1.0
            },
        )

    def unseen(self, angle_min: float, angle_increment: float, n_beams: int) -> list[float]:
        """Axes (deg, body frame) of the rangefinders a scan with this span never covers."""
        return self.coverage(angle_min, angle_increment, n_beams).unseen

    def _edge(self) -> float:
        """Half the field of view plus slack (rad): beams this close to an axis are inside."""
        return 0.5 * self.layout.field_of_view + ANGLE_TOLERANCE

    # -- readings ----------------------------------------------------------------------

    def readings(
        self,
        angle_min: float,
        angle_increment: float,
        ranges,
        range_min: float,
        range_max: float,
        angle_max: float | None = None,
    ) -> np.ndarray:
        """Rangefinder readings in [0, 1] from one scan.

        Args:
            angle_min, angle_increment: beam ``k`` points at ``angle_min + k *
                angle_increment`` (rad, scanner frame).
            ranges: ``(n,)`` ranges, m (REP 117 values allowed).
            range_min, range_max: the scanner's limits, m.
            angle_max: the message's ``angle_max`` (rad), checked against the number of
                ranges (:func:`check_beam_count`); None when the caller builds the beam
                directions from ``angle_min`` and the increment itself.

        Returns:
            ``(n_rangefinders,)`` readings: 1 touching, 0 nothing within range.

        Raises:
            InputError: a malformed scan (non-finite or zero increment, non-finite angles or
                limits, no beams, a beam count that disagrees with the angles), or one that
                leaves a rangefinder it covers without a valid beam.
        """
        r = np.asarray(ranges, dtype=np.float64)
        for name, value in (
            ("angle_min", angle_min),
            ("angle_max", 0.0 if angle_max is None else angle_max),
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
        if angle_max is not None:
            check_beam_count(angle_min, angle_max, angle_increment, r.size)

        tolerance = beam_tolerance(angle_increment)
        if self.centred:
            nearest, blind = self._centred(angle_min, angle_increment, r, range_min, range_max)
        else:
            nearest, blind = self._offset(angle_min, angle_increment, r, range_min, range_max)
        if blind.any():
            # The scanner looks that way but has no valid beam there: reading it as
            # "nothing seen" (0) would steer the robot blind. Refuse the scan instead, so the
            # input goes stale and the executor stops the robot.
            k = int(np.argmax(blind))
            nan = int(np.isnan(r).sum())
            short = int((np.isfinite(r) & (r < range_min)).sum())
            raise InputError(
                f"no valid beam covers the rangefinder at {math.degrees(self.axes[k]):.1f} deg "
                f"(body frame; a beam counts within {math.degrees(tolerance):.2g} deg): "
                f"{nan + short} of the scan's {r.size} ranges are invalid ({nan} NaN, "
                f"{short} below range_min {range_min:g} m)"
            )
        return np.array([range_reading(float(d), self.layout.max_range) for d in nearest])

    def _centred(self, angle_min, angle_increment, r, range_min, range_max):
        """Distances (m, from the mount points) and blindness, scanner at the centre.

        The arithmetic of a clean scan is the one the shipped controllers were evolved
        and replayed with; keep it bit for bit (tests/test_laser_reference.py).
        """
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

        offset = np.abs(_wrap(direction[None, :] - self.axes[:, None]))  # (axes, beams)
        gap = 0.5 * abs(angle_increment) + ANGLE_TOLERANCE
        tolerance = beam_tolerance(angle_increment)
        if self.layout.field_of_view > 0.0:
            # The valid beams inside the field of view; if there are none, the valid beams
            # within the tolerance of its edges.
            inside = valid[None, :] & (offset <= self._edge())
            near = valid[None, :] & (offset <= self._edge() + tolerance)
            members = np.where(inside.any(axis=1)[:, None], inside, near)
            in_span = offset.min(axis=1) <= self._edge() + gap
            usable = in_span & members.any(axis=1)
            nearest = np.where(members & in_span[:, None], from_mount[None, :], np.inf).min(axis=1)
        else:
            # One ray: the valid beam nearest the axis (first of equals), within tolerance.
            candidates = np.where(valid[None, :], offset, np.inf)
            j = np.argmin(candidates, axis=1)
            in_span = offset.min(axis=1) <= gap
            usable = in_span & (candidates[np.arange(len(j)), j] <= tolerance)
            nearest = np.where(usable, from_mount[j], np.inf)
        return nearest, in_span & ~usable

    def _offset(self, angle_min, angle_increment, r, range_min, range_max):
        """Distances (m, from the mount points) and blindness, scanner off the centre."""
        beams = self._scan_beams(angle_min, angle_increment, r.size)
        kind, rr = geo.classify(r, range_min, range_max)
        m, length = self.layout.mount_radius, self.layout.max_range
        tolerance = beam_tolerance(angle_increment)
        boundary = geo.build_boundary(beams, kind, rr, tolerance, reach=m + length)
        ux, uy = self._ray_cos_sin
        one_ray = self._cones.shape[0] == 0
        hits = None
        if one_ray or boundary.unknown.shape[0]:
            hits = geo.ray_hits(boundary, ux, uy, m)  # m from the centre
        if one_ray:
            rho = hits
        else:
            cone = geo.cone_nearest(boundary, self._cones[:, 0], self._cones[:, 1], m)
            rho = np.full(len(self.axes), np.inf)
            np.minimum.at(rho, self._cone_owner, cone)
        blind = np.zeros(len(self.axes), dtype=bool)
        if boundary.unknown.shape[0]:
            # A ray is blind if no valid beam covers the point it reads: its first hit, or
            # the end of its range. A field of view is blind only if all its rays are.
            far = np.minimum(hits, m + length)
            ends = np.stack([far * ux, far * uy], axis=1)
            blind = geo.in_wedges(beams.origin, ends, boundary.unknown)
            blind = blind.reshape(self.rays.shape).all(axis=1)
        return np.maximum(rho - m, 0.0), blind
