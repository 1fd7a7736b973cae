"""The four-wheel-steering (4WS) robot: geometry, limits and the four robot types.

This module says what a 4WS primitive *is* (its locomotion parameters and how they become
wheel commands). It is shared by the onboard primitive executor and the simulator, so it
depends on numpy only.

Frames follow REP 103: body x forward, y left, angles counter-clockwise. A wheel angle of 0
points the wheel along +x; a positive angle turns it to the left.

A wheel command is the 5-vector ``(speed, angle_fl, angle_fr, angle_rl, angle_rr)`` in
(m/s, rad, rad, rad, rad). One speed drives all four wheels (paper Sec. IV-A).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from evorbc_ros.config import ConfigError, build_settings, config_dir, load_yaml_mapping, setting
from evorbc_ros.robots.primitive import ParameterSpec

#: Order of the entries of a wheel command vector.
COMMAND_NAMES = ("speed", "angle_fl", "angle_fr", "angle_rl", "angle_rr")
#: Wheel names in command order (front-left, front-right, rear-left, rear-right).
WHEEL_NAMES = ("fl", "fr", "rl", "rr")


@dataclass(frozen=True)
class FourWSGeometry:
    """Body geometry and actuator limits of a 4WS robot (docs/design.md section 2).

    Defaults are the paper's robot, the original simulator's values: a 0.10 x 0.10 m body
    whose wheels touch the ground at (+-0.025, +-0.025) m from the centre. The registered
    robots read them from ``config/robots/4ws.yaml`` (:func:`paper_geometry`), which a test
    keeps equal to these defaults; a robot of other dimensions comes from its own settings
    file (:meth:`from_mapping`).
    """

    wheel_x: float = 0.025  # m, |x| of the wheel contact points in the body frame
    wheel_y: float = 0.025  # m, |y| of the wheel contact points in the body frame
    footprint_radius: float = 0.05  # m, collision circle around the body centre
    max_wheel_angle: float = math.radians(45.0)  # rad, |steering angle| limit
    max_wheel_rate: float = math.radians(90.0)  # rad/s, steering rate limit
    max_speed: float = 0.20  # m/s, |wheel speed| limit
    max_acceleration: float = 0.40  # m/s^2, |d speed / dt| limit
    # s, one control and integration step (10 Hz): the arbitrator's cycle, the same for
    # every robot, so not a setting of the file
    control_period: float = 0.1
    max_slip: float = math.radians(10.0)  # rad, more slip on any wheel: no motion
    parallel_tolerance: float = math.radians(1.0)  # rad, wheels this close: crab motion
    wheel_radius: float = 0.02  # m, wheel speed (m/s) to wheel velocity (rad/s) on the topics

    @classmethod
    def from_mapping(
        cls, values: dict, source: str, base: FourWSGeometry | None = None
    ) -> FourWSGeometry:
        """A geometry from a settings mapping (the keys of ``config/robots/4ws.yaml``).

        Args:
            values: file keys and values, angles in degrees (keys ending in ``_deg``).
            source: the file (or file and key) errors name.
            base: the geometry whose values the missing keys keep; None: every key is
                required.

        Raises:
            ConfigError: one line naming ``source`` and the key: an unknown or missing key,
                a value that is not a positive finite number, or wheels outside the footprint.

        """
        if not isinstance(values, dict):
            raise ConfigError(f"{source}: expected a mapping of 4WS geometry settings")
        given = build_settings(_GeometryKeys, values, source)
        changes: dict[str, Any] = {}
        for key in _GEOMETRY_KEYS:
            value = getattr(given, key)
            if value is None:
                if base is None:
                    raise ConfigError(f"{source}: missing setting {key!r}")
                continue
            field = key.removesuffix("_deg")
            # Degrees in the file, radians here: math.radians is what the defaults use, so
            # the paper's file gives the defaults bit for bit.
            changes[field] = math.radians(value) if key.endswith("_deg") else value
        geometry = dataclasses.replace(base or cls(), **changes)
        if math.hypot(geometry.wheel_x, geometry.wheel_y) > geometry.footprint_radius:
            raise ConfigError(
                f"{source}: footprint_radius {geometry.footprint_radius} m must hold the "
                f"wheels at ({geometry.wheel_x}, {geometry.wheel_y}) m"
            )
        return geometry

    @classmethod
    def load(cls, path, base: FourWSGeometry | None = None) -> FourWSGeometry:
        """The geometry in a settings file (:meth:`from_mapping`)."""
        return cls.from_mapping(load_yaml_mapping(path), str(path), base)

    def as_dict(self) -> dict:
        """Plain-data form, SI units (radians), as files record a design."""
        return dataclasses.asdict(self)

    def wheel_positions(self) -> np.ndarray:
        """Wheel contact points in the body frame, ``(4, 2)`` in m, order fl, fr, rl, rr."""
        x, y = self.wheel_x, self.wheel_y
        return np.array([[x, y], [x, -y], [-x, y], [-x, -y]])


@dataclass(frozen=True)
class _GeometryKeys:
    """The keys of a 4WS geometry file, in its units (None: not given)."""

    wheel_x: float | None = setting(None, doc="m", minimum=1e-6)
    wheel_y: float | None = setting(None, doc="m", minimum=1e-6)
    wheel_radius: float | None = setting(None, doc="m", minimum=1e-6)
    footprint_radius: float | None = setting(None, doc="m", minimum=1e-6)
    max_wheel_angle_deg: float | None = setting(None, doc="deg", minimum=1e-6, maximum=89.0)
    max_wheel_rate_deg: float | None = setting(None, doc="deg/s", minimum=1e-6)
    max_speed: float | None = setting(None, doc="m/s", minimum=1e-6)
    max_acceleration: float | None = setting(None, doc="m/s^2", minimum=1e-6)
    max_slip_deg: float | None = setting(None, doc="deg", minimum=0.0, maximum=89.0)
    parallel_tolerance_deg: float | None = setting(None, doc="deg", minimum=0.0, maximum=89.0)


_GEOMETRY_KEYS = tuple(f.name for f in dataclasses.fields(_GeometryKeys))

#: The paper's 4WS geometry, relative to ``config/``.
GEOMETRY_FILE = "robots/4ws.yaml"


@functools.cache
def paper_geometry() -> FourWSGeometry:
    """The paper's 4WS body and limits, read once from ``config/robots/4ws.yaml``.

    Raises:
        ConfigError: one line naming the file and the key.

    """
    return FourWSGeometry.load(config_dir() / GEOMETRY_FILE)


@dataclass(frozen=True)
class FourWSType:
    """One of the four 4WS robot types: which wheel commands its genes drive.

    ``gene_matrix[k, c]`` is the weight of gene ``k`` in wheel command ``c`` (before
    scaling by the command's limit); a type that pairs two wheels gives both the same gene,
    a fixed wheel has no gene.
    """

    name: str
    parameter_names: tuple[str, ...]
    gene_matrix: np.ndarray  # (n_genes, 5), entries 0 or 1
    # The body it is built on; None: the paper's (config/robots/4ws.yaml).
    geometry: FourWSGeometry | None = None

    def body(self) -> FourWSGeometry:
        """Its geometry and limits: its own, or the paper's."""
        return self.geometry if self.geometry is not None else paper_geometry()

    @property
    def n_parameters(self) -> int:
        """Number of locomotion parameters (genes) of a primitive."""
        return len(self.parameter_names)

    def parameter_specs(self, geometry: FourWSGeometry) -> tuple[ParameterSpec, ...]:
        """Names, units and physical ranges of the locomotion parameters."""
        specs = []
        for name in self.parameter_names:
            if name == "speed":
                specs.append(ParameterSpec(name, "m/s", -geometry.max_speed, geometry.max_speed))
            else:
                a = geometry.max_wheel_angle
                specs.append(ParameterSpec(name, "rad", -a, a))
        return tuple(specs)

    def commands(self, genes: np.ndarray, geometry: FourWSGeometry) -> np.ndarray:
        """Wheel commands for primitives.

        Args:
            genes: ``(n, n_parameters)`` or ``(n_parameters,)`` genes in [-1, 1]; each maps
                linearly onto its parameter's range.
            geometry: supplies the speed and angle limits.

        Returns:
            ``(n, 5)`` (or ``(5,)``) commands ``(speed m/s, fl, fr, rl, rr rad)``.

        """
        genes = np.asarray(genes, dtype=np.float64)
        scale = np.array([geometry.max_speed] + [geometry.max_wheel_angle] * 4, dtype=np.float64)
        return (np.clip(genes, -1.0, 1.0) @ self.gene_matrix) * scale


def gene_matrix(rows: list[tuple[int, ...]]) -> np.ndarray:
    """``(len(rows), 5)`` gene matrix: gene ``k`` drives the wheel commands ``rows[k]``.

    Columns are :data:`COMMAND_NAMES` indices (0 speed, 1-4 the fl, fr, rl, rr angles).
    """
    matrix = np.zeros((len(rows), len(COMMAND_NAMES)))
    for k, columns in enumerate(rows):
        matrix[k, list(columns)] = 1.0
    return matrix


# Paper Fig. 6: "fixed" wheels stay at 0, "together" wheels share one gene, "independent"
# wheels have their own. Every type has one speed gene for all wheels.
ROBOT_TYPES: dict[str, FourWSType] = {
    t.name: t
    for t in (
        FourWSType("2ws-2", ("speed", "angle_front"), gene_matrix([(0,), (1, 2)])),
        FourWSType("2ws-3", ("speed", "angle_fl", "angle_fr"), gene_matrix([(0,), (1,), (2,)])),
        FourWSType(
            "4ws-3", ("speed", "angle_front", "angle_rear"), gene_matrix([(0,), (1, 2), (3, 4)])
        ),
        FourWSType(
            "4ws-5",
            ("speed", "angle_fl", "angle_fr", "angle_rl", "angle_rr"),
            gene_matrix([(0,), (1,), (2,), (3,), (4,)]),
        ),
    )
}
