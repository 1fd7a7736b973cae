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

import math
from dataclasses import dataclass

import numpy as np

from evorbc_ros.robots.primitive import ParameterSpec

#: Order of the entries of a wheel command vector.
COMMAND_NAMES = ("speed", "angle_fl", "angle_fr", "angle_rl", "angle_rr")
#: Wheel names in command order (front-left, front-right, rear-left, rear-right).
WHEEL_NAMES = ("fl", "fr", "rl", "rr")


@dataclass(frozen=True)
class FourWSGeometry:
    """Body geometry and actuator limits of the 4WS robot (docs/design.md section 2).

    Defaults are the original simulator's values: a 0.10 x 0.10 m body whose wheels touch
    the ground at (+-0.025, +-0.025) m from the centre.
    """

    wheel_x: float = 0.025  # m, |x| of the wheel contact points in the body frame
    wheel_y: float = 0.025  # m, |y| of the wheel contact points in the body frame
    footprint_radius: float = 0.05  # m, collision circle around the body centre
    max_wheel_angle: float = math.radians(45.0)  # rad, |steering angle| limit
    max_wheel_rate: float = math.radians(90.0)  # rad/s, steering rate limit
    max_speed: float = 0.20  # m/s, |wheel speed| limit
    max_acceleration: float = 0.40  # m/s^2, |d speed / dt| limit
    control_period: float = 0.1  # s, one control and integration step (10 Hz)
    max_slip: float = math.radians(10.0)  # rad, more slip on any wheel: no motion
    parallel_tolerance: float = math.radians(1.0)  # rad, wheels this close: crab motion

    def wheel_positions(self) -> np.ndarray:
        """Wheel contact points in the body frame, ``(4, 2)`` in m, order fl, fr, rl, rr."""
        x, y = self.wheel_x, self.wheel_y
        return np.array([[x, y], [x, -y], [-x, y], [-x, -y]])


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


def robot_type(name: str) -> FourWSType:
    """The 4WS robot type called ``name``: a built-in one, or a plugin's 4WS variant.

    Looked up in the robot registry (:mod:`evorbc_ros.robots.registry`), whose 4WS
    registrations carry their type as ``model``.

    Raises:
        KeyError: with a message listing the known 4WS types.

    """
    from evorbc_ros.robots import registry

    if registry.known(name) and isinstance(registry.lookup(name).model, FourWSType):
        return registry.lookup(name).model
    known = ", ".join(r.name for r in registry.robots() if isinstance(r.model, FourWSType))
    raise KeyError(f"unknown 4WS robot type {name!r}; expected one of {known}")
