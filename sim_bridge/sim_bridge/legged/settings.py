"""A legged robot from a URDF plus a settings file (``config/robots/*.yaml``).

The settings say everything the simulation needs besides the URDF: the gait (oscillators
and joint couplings, :mod:`evorbc_ros.robots.legged`), the servo model, the physics, the
base and foot links, the tilt limits, the control period and the fastest speed a gait can
reach. ``docs/legged.md`` describes every key; ``config/robots/a1.yaml`` and
``config/robots/hexapod.yaml`` are examples.

Units: rad (or deg where a key ends in ``_deg``), m, s, N m.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
from dataclasses import dataclass
from pathlib import Path

from evorbc_ros.config import ConfigError, build_settings, load_yaml_mapping, setting
from evorbc_ros.robots.hexapod import SERVO_RATE
from evorbc_ros.robots.legged import Gait, gait_from_settings


@dataclass(frozen=True)
class PhysicsSettings:
    """How a legged robot is simulated; the defaults are the hexapod's (docs/hexapod.md)."""

    rate: float = SERVO_RATE  # Hz, physics steps per second (the servo loop runs at this rate)
    solver_iterations: int = 50  # Bullet's constraint solver iterations per step
    friction: float = 1.0  # lateral friction of feet, body, ground and walls
    settle_time: float = 1.0  # s, holding the standing pose before the rest state is saved
    wall_height: float = 0.4  # m

    @property
    def dt(self) -> float:
        """s, one physics step."""
        return 1.0 / self.rate

    def steps(self, duration: float) -> int:
        """Whole physics steps in ``duration`` s.

        Raises:
            ValueError: ``duration`` is not a whole number of steps.

        """
        n = round(duration * self.rate)
        if abs(n / self.rate - duration) > 1e-9:
            raise ValueError(f"{duration:g} s is not a whole number of {self.dt:g} s steps")
        return n

    def as_dict(self) -> dict:
        """Plain-data form (recorded in repertoire and arbitrator files)."""
        return {
            "engine": "pybullet",
            "rate_hz": self.rate,
            "solver_iterations": self.solver_iterations,
            "friction": self.friction,
            "settle_time": self.settle_time,
        }


#: ``urdf:`` values starting with this name a file of pybullet_data (PyBullet's own models).
PYBULLET_DATA = "pybullet_data:"


@dataclass(frozen=True)
class ServoModel:
    """Every joint a position servo (docs/design.md section 11).

    The commanded joint velocity is ``clip(gain x (target - angle), -max_velocity,
    max_velocity)`` and the motor applies at most ``torques[k]`` to reach it.
    """

    gain: float  # 1/s, commanded joint velocity per rad of error
    max_velocity: float  # rad/s
    torques: tuple[float, ...]  # N m, per actuated joint in command order


@dataclass(frozen=True)
class LeggedRobotSettings:
    """A legged robot as the simulation builds it."""

    name: str
    gait: Gait
    servo: ServoModel
    physics: PhysicsSettings
    urdf: str | None = None  # absolute path of the URDF file
    urdf_text: str | None = None  # or the URDF itself (a robot generated in code)
    base_link: str = "base"  # the URDF's root link: its pose is the robot's pose
    foot_links: tuple[str, ...] = ()
    control_period: float = 0.1  # s, the arbitrator's cycle
    discard_tilt: float = math.radians(45.0)  # rad, a primitive tilting more is discarded
    fallen_tilt: float = math.radians(90.0)  # rad, an episode ends: the robot fell over
    spawn_height: float | None = None  # m, root link height at load (None: feet touch)
    footprint_radius: float | None = None  # m, None: measured at the standing pose
    speed_bound: float = 0.6  # m/s, no gait is faster: the archive spans it times T
    self_collision: bool = True
    source: str = ""  # the settings file, for messages

    def urdf_sha256(self) -> str:
        """SHA-256 of the URDF's text: a repertoire records which robot it was made for."""
        text = self.urdf_text if self.urdf_text is not None else Path(self.urdf).read_text()
        return hashlib.sha256(text.encode()).hexdigest()

    def describe(self) -> dict:
        """Plain-data description recorded in repertoire and arbitrator files.

        Another design (other servos, ranges, couplings, physics or URDF) compares
        unequal, so its files are refused rather than reused.
        """
        gait = self.gait
        described = {
            "robot": self.name,
            "urdf_sha256": self.urdf_sha256(),
            "oscillators": [dataclasses.asdict(o) for o in gait.oscillators],
            "joints": [dataclasses.asdict(j) for j in gait.joints],
            "frequency": gait.frequency,
            "servo": dataclasses.asdict(self.servo),
            "physics": self.physics.as_dict(),
            "links": {"base": self.base_link, "feet": list(self.foot_links)},
            "control_period": self.control_period,
            "discard_tilt": self.discard_tilt,
            "fallen_tilt": self.fallen_tilt,
            "spawn_height": self.spawn_height,
            "self_collision": self.self_collision,
        }
        return json.loads(json.dumps(described))  # as a file holds it: tuples become lists


# -- the settings file ------------------------------------------------------------------


@dataclass(frozen=True)
class _Servo:
    gain: float = setting(doc="1/s, joint velocity per rad of error", minimum=1e-9)
    max_velocity: float = setting(doc="rad/s", minimum=1e-9)
    max_torque: float = setting(doc="N m, every joint", minimum=1e-9)


@dataclass(frozen=True)
class _Physics:
    rate_hz: float = setting(doc="physics steps per second (the servo loop)", minimum=1.0)
    solver_iterations: int = setting(50, minimum=1, maximum=10_000)
    friction: float = setting(1.0, minimum=0.0)
    settle_time: float = setting(1.0, doc="s standing before the rest state", minimum=0.0)
    wall_height: float = setting(0.4, doc="m", minimum=1e-6)


@dataclass(frozen=True)
class _Tilt:
    discard_deg: float = setting(45.0, minimum=0.0, maximum=180.0)
    fallen_deg: float = setting(90.0, minimum=0.0, maximum=180.0)


@dataclass(frozen=True)
class _Links:
    base: str = setting(doc="the URDF's root link")
    feet: tuple[str, ...] = setting(())


@dataclass(frozen=True)
class _Top:
    name: str = setting()
    urdf: str = setting(doc="a path relative to the settings file, or pybullet_data:PATH")
    speed_bound: float = setting(doc="m/s, faster than any gait", minimum=1e-6)
    control_period: float = setting(0.1, minimum=1e-6)
    spawn_height: float | None = setting(None, minimum=0.0)
    footprint_radius: float | None = setting(None, minimum=0.0)
    self_collision: bool = setting(True)


#: Sections of a settings file (mappings), besides :class:`_Top`'s keys; tilt is optional.
_SECTIONS = ("links", "oscillators", "joints", "gait", "servo", "physics", "tilt")
#: Optional records the simulation does not read: how ``evorbc-evolve design-gait`` chose
#: the gait design (docs/legged.md, "The gait design search").
_RECORDS = ("design_search",)


def _section(cls, values, source: str, key: str):
    if not isinstance(values, dict):
        raise ConfigError(f"{source}: {key}: expected a mapping")
    return build_settings(cls, values, f"{source}: {key}")


def resolve_urdf(value: str, settings_file: Path) -> Path:
    """The URDF file a settings file names (relative to its folder, or in pybullet_data).

    Raises:
        ConfigError: no such file.

    """
    if value.startswith(PYBULLET_DATA):
        import pybullet_data

        path = Path(pybullet_data.getDataPath()) / value[len(PYBULLET_DATA) :]
    else:
        path = Path(value)
        if not path.is_absolute():
            path = settings_file.parent / path
    if not path.is_file():
        raise ConfigError(f"{settings_file}: urdf: no such file {str(path)!r}")
    return path.resolve()


def load_robot_settings(path: str | Path) -> LeggedRobotSettings:
    """The legged robot described by settings file ``path``.

    Raises:
        ConfigError: one line naming the file and the key that is wrong.

    """
    path = Path(path)
    return robot_settings_from_mapping(load_yaml_mapping(path), path)


def robot_settings_from_mapping(data: dict, path: str | Path) -> LeggedRobotSettings:
    """The legged robot described by ``data``, a settings file's mapping read from ``path``.

    ``path`` names the file in messages and anchors a relative ``urdf``; benchmarks that
    compare designs change ``data`` before building the robot.

    Raises:
        ConfigError: one line naming the file and the key that is wrong.

    """
    path = Path(path)
    source = str(path)
    # The typed keys first: an unknown or missing key is named before anything else.
    for key in _SECTIONS[:-1]:
        if key not in data:
            raise ConfigError(f"{source}: missing setting {key!r}")
    for key in _RECORDS:
        if key in data and not isinstance(data[key], dict):
            raise ConfigError(f"{source}: {key}: expected a mapping")
    top_keys = {k: v for k, v in data.items() if k not in _SECTIONS + _RECORDS}
    top = build_settings(_Top, top_keys, source)
    servo = _section(_Servo, data["servo"], source, "servo")
    physics_file = _section(_Physics, data["physics"], source, "physics")
    tilt = _section(_Tilt, data.get("tilt", {}), source, "tilt")
    links = _section(_Links, data["links"], source, "links")
    gait = gait_from_settings(data, source)
    physics = PhysicsSettings(
        rate=physics_file.rate_hz,
        solver_iterations=physics_file.solver_iterations,
        friction=physics_file.friction,
        settle_time=physics_file.settle_time,
        wall_height=physics_file.wall_height,
    )
    checks = (("control_period", top.control_period), ("physics.settle_time", physics.settle_time))
    for key, duration in checks:
        try:
            physics.steps(duration)
        except ValueError as e:
            raise ConfigError(f"{source}: {key}: {e} at physics.rate_hz") from None
    return LeggedRobotSettings(
        name=top.name,
        gait=gait,
        servo=ServoModel(servo.gain, servo.max_velocity, (servo.max_torque,) * len(gait.joints)),
        physics=physics,
        urdf=str(resolve_urdf(top.urdf, path)),
        base_link=links.base,
        foot_links=links.feet,
        control_period=top.control_period,
        discard_tilt=math.radians(tilt.discard_deg),
        fallen_tilt=math.radians(tilt.fallen_deg),
        spawn_height=top.spawn_height,
        footprint_radius=top.footprint_radius,
        speed_bound=top.speed_bound,
        self_collision=top.self_collision,
        source=source,
    )
