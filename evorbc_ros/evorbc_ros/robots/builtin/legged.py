"""Registering a legged robot from a URDF plus a settings file (docs/legged.md).

:func:`legged_robot` turns a settings file (``config/robots/*.yaml``: URDF, gait, servos,
physics, tilt limits) into a :class:`~evorbc_ros.robots.record.Robot` of the ``legged``
family, whose simulation, maze task, bridge adapter and design check are the generic
legged ones of the simulation's and the search's adapter tables, and whose onboard command
interface is the joint-trajectory one (:mod:`evorbc_ros.nodes.legged_commands`). The A1
(:mod:`.a1`) is one; a plugin registers its own robot the same way with an absolute
settings path.

Like every registration module this reads YAML only (numpy and PyYAML), so onboard nodes
look a legged robot up without loading PyBullet.
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass
from pathlib import Path

from evorbc_ros.config import ConfigError, config_dir, load_yaml_mapping
from evorbc_ros.robots.legged import Gait, gait_from_settings
from evorbc_ros.robots.record import Robot, SettingsFiles


@functools.lru_cache(maxsize=16)
def _read(path: Path) -> dict:
    return load_yaml_mapping(path)


@dataclass(frozen=True)
class LeggedModel:
    """A legged registration's ``model``: its settings file.

    Attributes:
        settings_file: ``config/robots/*.yaml``, relative to ``config/`` or absolute.

    """

    settings_file: str

    def path(self) -> Path:
        """The settings file's path."""
        path = Path(self.settings_file)
        return path if path.is_absolute() else config_dir() / path

    def data(self) -> dict:
        """The settings file's mapping (read once per process)."""
        return _read(self.path())

    def gait(self) -> Gait:
        """The robot's gait: oscillators, joint couplings, omega."""
        return gait_from_settings(self.data(), str(self.path()))

    def _number(self, *keys: str) -> float:
        value = self.data()
        try:
            for key in keys:
                value = value[key]
        except (KeyError, TypeError):
            raise ConfigError(f"{self.path()}: missing setting {'.'.join(keys)!r}") from None
        if isinstance(value, bool) or not isinstance(value, (int, float)) or value <= 0:
            raise ConfigError(f"{self.path()}: {'.'.join(keys)}: expected a number > 0")
        return float(value)

    @property
    def physics_rate(self) -> float:
        """Hz, physics steps per second: the servo loop and the trajectory points' rate."""
        return self._number("physics", "rate_hz")

    @property
    def control_period(self) -> float:
        """s, the arbitrator's cycle."""
        return self._number("control_period") if "control_period" in self.data() else 0.1

    @property
    def footprint_radius(self) -> float:
        """m, a circle about the body centre holding the robot at rest."""
        return self._number("footprint_radius")

    @property
    def speed_bound(self) -> float:
        """m/s, faster than any gait."""
        return self._number("speed_bound")


def legged_robot(settings_file: str, description: str, **changes) -> Robot:
    """The registration of the legged robot a settings file describes.

    Args:
        settings_file: ``config/robots/NAME.yaml`` (relative to ``config/``) or an
            absolute path; it must give ``footprint_radius`` and ``speed_bound``.
        description: one line for listings.
        changes: fields to set otherwise (maze, episode time, equal budget, shipped
            controller, ...). The settings files default to ``repertoire/NAME.yaml``,
            ``arbitrator/NAME.yaml``, ``neat/NAME.ini`` and ``tasks/maze-NAME.yaml``, the
            sensors to ``sensors/NAME.yaml`` and the maze to ``NAME``.

    Raises:
        ConfigError: the settings file is missing or wrong (one line naming it).

    """
    model = LeggedModel(settings_file)
    data = model.data()
    name = data.get("name")
    if not isinstance(name, str):
        raise ConfigError(f"{model.path()}: name: expected the robot's name")
    robot = Robot(
        name=name,
        description=description,
        parameters=model.gait().parameter_specs(),
        settings=SettingsFiles(
            repertoire=f"repertoire/{name}.yaml",
            arbitrator=f"arbitrator/{name}.yaml",
            neat=f"neat/{name}.ini",
            task=f"tasks/maze-{name}.yaml",
        ),
        commands="evorbc_ros.nodes.legged_commands:LeggedTrajectoryCommands",
        command_topics=("joint_trajectory_controller/joint_trajectory",),
        sensors=f"sensors/{name}.yaml",
        maze=name,
        episode_time=30.0,
        footprint_radius=model.footprint_radius,
        max_speed=model.speed_bound,
        episode_bytes=16_000,
        family="legged",
        model=model,
    )
    return dataclasses.replace(robot, **changes) if changes else robot
