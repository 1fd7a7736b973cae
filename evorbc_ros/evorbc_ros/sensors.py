"""Sensor layouts and how raw measurements become arbitrator inputs (docs/design.md section 5).

Rangefinders: each is mounted at ``mount_radius`` from the body centre, pointing along its
angle; it reads the nearest wall within its field of view as ``(range - d) / range``
clipped to [0, 1], so 1 means touching and 0 means nothing within range. With a field of
view of 0 it is a single ray; otherwise ``rays`` rays spread evenly over the field of view
and the nearest hit counts.

Goal sectors ("radar"): each is 1 when the goal's bearing from the robot lies in the
sector ``[centre - width/2, centre + width/2)``, else 0.

Goal bearing (hexapod): one input, the bearing of the goal mapped from [-pi, pi) to [0, 1).

Motion (odometry): one input, how far the robot's centre moved over the last ``window``
seconds, ``|p(t) - p(t - window)| / distance`` clipped to [0, 1], so 0 means it has not
moved (stuck, or turning on the spot) and 1 that it moved ``distance`` or more. Before a
whole window has passed, ``p(t - window)`` is the first pose seen.

Inputs are ordered: rangefinders, then goal sectors, then goal bearing, then motion.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from dataclasses import dataclass

import numpy as np

from evorbc_ros.config import ConfigError, load_yaml_mapping


@dataclass(frozen=True)
class RangefinderLayout:
    """Where the rangefinders point and how far they see (angles in rad, body frame)."""

    angles: tuple[float, ...]
    max_range: float  # m
    mount_radius: float = 0.0  # m
    field_of_view: float = 0.0  # rad
    rays: int = 1

    def ray_offsets(self) -> np.ndarray:
        """``(rays,)`` ray directions relative to a rangefinder's axis, rad."""
        if self.field_of_view <= 0.0 or self.rays == 1:
            return np.zeros(1)
        return np.linspace(-0.5 * self.field_of_view, 0.5 * self.field_of_view, self.rays)

    def ray_angles(self) -> np.ndarray:
        """``(n_sensors, rays)`` ray directions in the body frame, rad."""
        return np.asarray(self.angles)[:, None] + self.ray_offsets()[None, :]


@dataclass(frozen=True)
class GoalSectorLayout:
    """Boolean goal-direction sectors (rad, body frame)."""

    centres: tuple[float, ...]
    width: float

    @property
    def tiles(self) -> bool:
        """True if the sectors cover the circle edge to edge in order (like the 4WS radar).

        Then each bearing lights exactly one sector, found from one wrapped angle, so no
        rounding at a shared edge can light none or two.
        """
        n = len(self.centres)
        if abs(n * self.width - 2.0 * math.pi) > 1e-9:
            return False
        c0 = self.centres[0]
        return all(
            abs(math.remainder(c - c0 - k * self.width, 2.0 * math.pi)) < 1e-9
            for k, c in enumerate(self.centres)
        )


@dataclass(frozen=True)
class MotionLayout:
    """The motion input: distance moved over a window of odometry (docs/design.md section 5)."""

    window: float  # s, how far back the pose compared with lies
    distance: float  # m moved over the window that reads as 1

    @property
    def window_ns(self) -> int:
        """The window in ns, as odometry stamps count time."""
        return round(self.window * 1e9)

    def cycles(self, period: float) -> int:
        """The window in control cycles of ``period`` s.

        Raises:
            ValueError: a window that is not a whole number of cycles: offline episodes
                compare positions whole cycles apart, which is what the odometry stamps
                of a lockstep graph give onboard only then.
        """
        cycles = round(self.window / period)
        # Exact in ns, the unit of the stamps onboard: a window a nanosecond off would
        # compare with another pose there than here.
        if cycles < 1 or self.window_ns != cycles * round(period * 1e9):
            raise ValueError(
                f"motion.window must be a whole number of {period:g} s control cycles, "
                f"got {self.window!r} s"
            )
        return cycles


@dataclass(frozen=True)
class SensorLayout:
    """Every input of an arbitrator, in order."""

    rangefinders: RangefinderLayout | None = None
    goal_sectors: GoalSectorLayout | None = None
    goal_bearing: bool = False
    motion: MotionLayout | None = None

    @property
    def n_inputs(self) -> int:
        """Number of network inputs."""
        n = len(self.rangefinders.angles) if self.rangefinders else 0
        n += len(self.goal_sectors.centres) if self.goal_sectors else 0
        return n + int(self.goal_bearing) + int(self.motion is not None)

    def input_names(self) -> list[str]:
        """A name per input, e.g. ``range_060`` or ``goal_sector_090``."""
        names = []
        if self.rangefinders:
            names += [f"range_{round(math.degrees(a)) % 360:03d}" for a in self.rangefinders.angles]
        if self.goal_sectors:
            names += [
                f"goal_sector_{round(math.degrees(c)) % 360:03d}" for c in self.goal_sectors.centres
            ]
        if self.goal_bearing:
            names.append("goal_bearing")
        if self.motion:
            names.append("motion")
        return names

    def to_dict(self) -> dict:
        """Plain-data form in the units of the YAML file (degrees, m)."""
        out: dict = {}
        if self.rangefinders:
            r = self.rangefinders
            out["rangefinders"] = {
                "angles_deg": [_degrees(a) for a in r.angles],
                "range": r.max_range,
                "mount_radius": r.mount_radius,
                "field_of_view_deg": _degrees(r.field_of_view),
                "rays": r.rays,
            }
        if self.goal_sectors:
            out["goal_sectors"] = {
                "centres_deg": [_degrees(c) for c in self.goal_sectors.centres],
                "width_deg": _degrees(self.goal_sectors.width),
            }
        if self.goal_bearing:
            out["goal_bearing"] = True
        # Only when set: the layouts without it keep their fingerprints.
        if self.motion:
            out["motion"] = {"window": self.motion.window, "distance": self.motion.distance}
        return out

    def difference(self, expected: SensorLayout, where: str) -> str | None:
        """The first setting in which this layout differs from ``expected``, in one short line.

        ``rangefinders.range is 2.0 in <where> but 2.5 now``: ``where`` names what holds
        ``expected`` (``the arbitrator``); None when the layouts are the same.
        """
        from evorbc_ros.json_files import first_difference

        return first_difference(expected.to_dict(), self.to_dict(), where)

    def fingerprint(self) -> str:
        """Short hash of the layout; arbitrators record it to detect a different layout."""
        text = json.dumps(self.to_dict(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    @classmethod
    def from_dict(cls, data: dict, source: str = "sensor layout") -> SensorLayout:
        """Build and validate a layout from its YAML mapping.

        Raises:
            ConfigError: naming ``source`` and the offending key.
        """
        if not isinstance(data, dict):
            raise ConfigError(f"{source}: expected a mapping")
        unknown = set(data) - {"rangefinders", "goal_sectors", "goal_bearing", "motion"}
        if unknown:
            raise ConfigError(f"{source}: unknown key {sorted(unknown)[0]!r}")
        rf = gs = None
        if "rangefinders" in data:
            d = _mapping(
                data["rangefinders"],
                "rangefinders",
                source,
                {"angles_deg", "range", "mount_radius", "field_of_view_deg", "rays"},
            )
            angles = _number_list(d.get("angles_deg"), "rangefinders.angles_deg", source)
            rays = d.get("rays", 1)
            if isinstance(rays, bool) or not isinstance(rays, int) or not 1 <= rays <= MAX_RAYS:
                raise ConfigError(
                    f"{source}: rangefinders.rays must be an integer from 1 to {MAX_RAYS}"
                )
            rf = RangefinderLayout(
                angles=tuple(math.radians(a) for a in angles),
                max_range=_positive(
                    d.get("range"), "rangefinders.range", source, maximum=MAX_RANGE
                ),
                mount_radius=_positive(
                    d.get("mount_radius", 0.0),
                    "rangefinders.mount_radius",
                    source,
                    allow_zero=True,
                    maximum=MAX_MOUNT_RADIUS,
                ),
                field_of_view=math.radians(
                    _positive(
                        d.get("field_of_view_deg", 0.0),
                        "rangefinders.field_of_view_deg",
                        source,
                        allow_zero=True,
                        maximum=360.0,
                    )
                ),
                rays=rays,
            )
            if rf.field_of_view == 0.0 and rays > 1:
                raise ConfigError(
                    f"{source}: rangefinders.rays is {rays} but field_of_view_deg is 0; "
                    "several rays need a field of view to spread over"
                )
        if "goal_sectors" in data:
            d = _mapping(data["goal_sectors"], "goal_sectors", source, {"centres_deg", "width_deg"})
            centres = _number_list(d.get("centres_deg"), "goal_sectors.centres_deg", source)
            gs = GoalSectorLayout(
                tuple(math.radians(c) for c in centres),
                math.radians(
                    _positive(d.get("width_deg"), "goal_sectors.width_deg", source, maximum=360.0)
                ),
            )
        bearing = data.get("goal_bearing", False)
        if not isinstance(bearing, bool):
            raise ConfigError(f"{source}: goal_bearing must be true or false")
        motion = None
        if "motion" in data:
            d = _mapping(data["motion"], "motion", source, {"window", "distance"})
            motion = MotionLayout(
                window=_positive(d.get("window"), "motion.window", source, maximum=60.0),
                distance=_positive(d.get("distance"), "motion.distance", source, maximum=MAX_RANGE),
            )
        layout = cls(rf, gs, bearing, motion)
        if layout.n_inputs == 0:
            raise ConfigError(f"{source}: the layout has no inputs")
        return layout

    @classmethod
    def load(cls, path: str | os.PathLike) -> SensorLayout:
        """Load a layout from a YAML file."""
        return cls.from_dict(load_yaml_mapping(path), str(path))


def _degrees(angle: float) -> float:
    """Degrees for files, rounded to 1e-9 deg so that files read back exactly.

    Without the rounding the shipped 60 deg would be written as 59.99999999999999.
    """
    return round(math.degrees(angle), 9) + 0.0  # + 0.0 turns -0.0 into 0.0


def _mapping(value, where: str, source: str, keys: set[str]) -> dict:
    if not isinstance(value, dict):
        raise ConfigError(f"{source}: {where} must be a mapping")
    unknown = set(value) - keys
    if unknown:
        raise ConfigError(f"{source}: unknown key {where}.{sorted(unknown)[0]}")
    return value


def _number_list(value, where: str, source: str) -> list[float]:
    if (
        not isinstance(value, list)
        or not value
        or len(value) > MAX_DIRECTIONS
        or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
            for v in value
        )
    ):
        raise ConfigError(f"{source}: {where} must be a list of 1 to {MAX_DIRECTIONS} numbers")
    return [float(v) for v in value]


def _positive(
    value, where: str, source: str, allow_zero: bool = False, maximum: float = math.inf
) -> float:
    if (
        isinstance(value, bool)
        or not isinstance(value, (int, float))
        or not math.isfinite(value)
        or value < 0
        or (value == 0 and not allow_zero)
        or value > maximum
    ):
        bound = ">= 0" if allow_zero else "> 0"
        if maximum < math.inf:
            bound += f" and <= {maximum:g}"
        raise ConfigError(f"{source}: {where} must be a number {bound}, got {value!r}")
    return float(value)


# Bounds on a layout (docs/design.md section 5): far beyond any robot's sensors, and small
# enough that the simulated sensors' lookup tables (sized by the range) and the rays cast
# each cycle fit the machine. A 300 m range asked for 1.4 GiB at once.
#: The longest rangefinder range (m): beyond the largest maze.
MAX_RANGE = 50.0
#: How far from the robot's centre a rangefinder may sit (m): a fuzzed 300 m mount
#: radius (a beam angle swapped into it) cast every ray from far outside the maze.
MAX_MOUNT_RADIUS = 2.0
#: Rays per rangefinder, and rangefinders or goal sectors per layout.
MAX_RAYS, MAX_DIRECTIONS = 100, 360


def range_reading(distance: float, max_range: float) -> float:
    """One rangefinder input: ``(range - d) / range`` clipped to [0, 1] (1 = touching).

    Scalar and plain ``math`` so that the compiled simulator uses the same formula.
    """
    return min(max((max_range - distance) / max_range, 0.0), 1.0)


def in_sector(bearing: float, centre: float, width: float) -> bool:
    """True if ``bearing`` lies in ``[centre - width/2, centre + width/2)`` (rad, wrapped).

    Used for layouts whose sectors do not tile the circle. Scalar and plain ``math`` so
    that the compiled simulator uses the same formula.
    """
    rel = (bearing - centre + math.pi) % (2.0 * math.pi) - math.pi
    return -0.5 * width <= rel < 0.5 * width


def tiling_sector(bearing: float, first_centre: float, width: float, n: int) -> int:
    """Index of the sector holding ``bearing`` when ``n`` sectors tile the circle.

    Sector ``k`` covers ``[first_centre + (k - 1/2) width, first_centre + (k + 1/2) width)``.
    """
    u = (bearing - first_centre + 0.5 * width) % (2.0 * math.pi)
    return min(int(u // width), n - 1)  # u can round up to 2 pi: that is sector 0's start


def goal_bearing_reading(bearing: float) -> float:
    """The goal bearing (rad, body frame) mapped from [-pi, pi) onto [0, 1)."""
    return ((bearing + math.pi) % (2.0 * math.pi)) / (2.0 * math.pi)


def motion_reading(dx: float, dy: float, distance: float) -> float:
    """The motion input for a displacement ``(dx, dy)`` (m) over the window: 0 to 1.

    Scalar and plain ``math`` so that the compiled simulator uses the same formula.
    """
    return min(math.sqrt(dx * dx + dy * dy) / distance, 1.0)


def rangefinder_readings(distances: np.ndarray, layout: RangefinderLayout) -> np.ndarray:
    """Readings from ``(n_sensors, rays)`` distances (m) measured from the mount points.

    Non-finite distances mean "nothing seen" (REP 117 +inf); the caller decides what NaN
    means before calling (see the laser node).
    """
    d = np.asarray(distances, dtype=np.float64).reshape(len(layout.angles), -1)
    nearest = np.min(np.where(np.isfinite(d), d, np.inf), axis=1)
    return np.array([range_reading(v, layout.max_range) for v in nearest])


def goal_sector_readings(bearing: float, layout: GoalSectorLayout) -> np.ndarray:
    """1 for each sector that contains ``bearing`` (rad, body frame), else 0."""
    if layout.tiles:
        out = np.zeros(len(layout.centres))
        out[tiling_sector(bearing, layout.centres[0], layout.width, len(layout.centres))] = 1.0
        return out
    return np.array([float(in_sector(bearing, c, layout.width)) for c in layout.centres])
