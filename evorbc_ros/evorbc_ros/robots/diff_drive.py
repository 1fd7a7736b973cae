"""The differential-drive robot: geometry, limits and what a primitive is.

A differential-drive primitive has two locomotion parameters, the body's linear speed
``v`` (m/s, +x forward) and angular speed ``omega`` (rad/s, counter-clockwise), held for
the primitive's duration: exactly what a ``geometry_msgs/Twist`` on ``cmd_vel`` carries to
nav2's and ros2_control's diff_drive_controller (docs/design.md section 19). Gene ``k`` in
[-1, 1] maps linearly onto ``[-limit_k, limit_k]``.

The robot is declared in a settings file only (``kind: diff_drive``,
``config/robots/turtlebot3-burger.yaml``, docs/your-robot.md). This module is shared by
the onboard executor and the simulation, so it depends on numpy and PyYAML only.
Frames follow REP 103: body x forward, y left, angles counter-clockwise.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from evorbc_ros.config import ConfigError, build_settings, setting
from evorbc_ros.robots.primitive import ParameterSpec

#: The entries of a command: the body twist.
COMMAND_NAMES = ("linear", "angular")
#: Wheel joint names, in the bridge's joint states.
WHEEL_JOINTS = ("left_wheel_joint", "right_wheel_joint")


@dataclass(frozen=True)
class DiffDriveGeometry:
    """Body geometry and limits of a differential-drive robot (the settings file's keys).

    The limits are those of ros2_control's diff_drive_controller (``linear.x`` and
    ``angular.z``: velocity and acceleration) plus the wheels' top speed.
    """

    wheel_separation: float = setting(doc="m, between the wheels' contact points", minimum=1e-6)
    wheel_radius: float = setting(doc="m", minimum=1e-6)
    footprint_radius: float = setting(doc="m, circle about the body centre", minimum=1e-6)
    max_linear_speed: float = setting(doc="m/s, |v| limit", minimum=1e-6)
    max_angular_speed: float = setting(doc="rad/s, |omega| limit", minimum=1e-6)
    max_linear_acceleration: float = setting(doc="m/s^2, |dv/dt| limit", minimum=1e-6)
    max_angular_acceleration: float = setting(doc="rad/s^2, |d omega/dt| limit", minimum=1e-6)
    max_wheel_speed: float = setting(doc="m/s, each wheel's rim speed limit", minimum=1e-6)
    # s, one control and integration step: the arbitrator's cycle, the same for every robot
    control_period: float = 0.1

    @classmethod
    def from_mapping(cls, values: dict, source: str) -> DiffDriveGeometry:
        """The geometry from a settings mapping (every key but ``control_period`` required).

        Raises:
            ConfigError: one line naming ``source`` and the key.

        """
        if not isinstance(values, dict):
            raise ConfigError(f"{source}: expected a mapping of differential-drive settings")
        if "control_period" in values:
            raise ConfigError(
                f"{source}: control_period is the arbitrator's 0.1 s cycle for every robot; "
                "remove it"
            )
        geometry = build_settings(cls, values, source)
        if geometry.footprint_radius < 0.5 * geometry.wheel_separation:
            raise ConfigError(
                f"{source}: footprint_radius {geometry.footprint_radius} m must hold the "
                f"wheels ({geometry.wheel_separation} m apart)"
            )
        return geometry

    @property
    def max_speed(self) -> float:
        """m/s, the fastest the body centre moves (a bound on any primitive's speed)."""
        return min(self.max_linear_speed, self.max_wheel_speed)

    def parameter_specs(self) -> tuple[ParameterSpec, ...]:
        """The two locomotion parameters: linear (m/s) and angular (rad/s) speed."""
        return (
            ParameterSpec("linear", "m/s", -self.max_linear_speed, self.max_linear_speed),
            ParameterSpec("angular", "rad/s", -self.max_angular_speed, self.max_angular_speed),
        )

    @property
    def command_scale(self) -> np.ndarray:
        """``(2,)`` what a gene of 1 commands: (m/s, rad/s)."""
        return np.array([self.max_linear_speed, self.max_angular_speed])

    def commands(self, genes: np.ndarray) -> np.ndarray:
        """Body twists of primitives.

        Args:
            genes: ``(n, 2)`` or ``(2,)`` genes in [-1, 1].

        Returns:
            ``(n, 2)`` (or ``(2,)``) commands ``(v m/s, omega rad/s)``.

        """
        genes = np.asarray(genes, dtype=np.float64)
        return np.clip(genes, -1.0, 1.0) * self.command_scale

    def as_dict(self) -> dict:
        """Plain-data form, SI units, as files record a design."""
        return dataclasses.asdict(self)


def wheel_speeds(v: float, omega: float, separation: float) -> tuple[float, float]:
    """``(left, right)`` wheel rim speeds (m/s) of the body twist ``(v, omega)``."""
    half = 0.5 * separation * omega
    return v - half, v + half
