"""Robots declared in settings files only: ``kind:`` plus the robot's figures, no Python.

A robot settings file is a YAML file with a ``kind`` key in ``config/robots/`` (shipped)
or in a folder named by ``$EVORBC_ROBOT_PATH`` (the user's; folders separated by
``os.pathsep``, as ``PATH``). The registry reads them after its built-in robots and
before plugins (docs/design.md section 19, docs/your-robot.md). A YAML file there without
``kind`` is not a robot declaration (``4ws.yaml``, the paper's 4WS body; the legged
robots' URDF settings) and is left alone.

Kinds (:data:`KINDS`): ``four_ws``, one of the paper's 4WS gene layouts on a body of the
file's dimensions; ``diff_drive``, a differential-drive robot; and ``legged``, a legged
robot from its URDF, whose ``model`` key names its legged settings file (docs/legged.md:
URDF, joints, gait, servos, physics). Keys every kind takes:

* ``kind``, ``name`` (default: the file's stem), ``description``;
* ``settings``: ``repertoire``, ``arbitrator``, ``neat``, ``task`` files, and ``sensors``,
  relative paths from this file's folder (one found only in evorbc's ``config/``, where
  they were taken from before, still works with a deprecation line; docs/design.md
  section 12);
* ``maze``, ``episode_time`` (s), ``equal_budget_generations``;
* ``geometry``: the kind's body and limits (:class:`~evorbc_ros.robots.four_ws.FourWSGeometry`
  keys for ``four_ws``, which keep the paper's value for a key not given;
  :class:`~evorbc_ros.robots.diff_drive.DiffDriveGeometry` keys, all required, for
  ``diff_drive``; none for ``legged``, whose body is its ``model``).

This module depends on numpy and PyYAML only (docs/design.md section 17).
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from evorbc_ros.config import ConfigError, build_settings, config_dir, load_yaml_mapping, setting
from evorbc_ros.robots.record import Robot, SettingsFiles
from evorbc_ros.settings_paths import resolve_beside

#: The environment variable naming the user's folders of robot settings files.
PATH_VARIABLE = "EVORBC_ROBOT_PATH"
#: The kinds a robot settings file may declare.
KINDS = ("four_ws", "diff_drive", "legged")


@dataclass(frozen=True)
class RobotFileKeys:
    """The top-level keys of a robot settings file (``geometry`` is the kind's)."""

    kind: str = setting(doc="what the robot is", choices=KINDS)
    name: str | None = setting(None, doc="the robot's name (default: the file's stem)")
    description: str = setting("", doc="one line for listings")
    type: str | None = setting(None, doc="four_ws: the paper's gene layout it uses")
    model: str | None = setting(None, doc="legged: its legged settings file (docs/legged.md)")
    # Mappings, checked by the kind (geometry) and by _SettingsKeys (settings).
    geometry: Any = None
    settings: Any = None
    sensors: str | None = setting(None, doc="sensor layout file")
    maze: str | None = setting(None, doc="the maze it runs in when none is named")
    episode_time: float | None = setting(None, doc="s, T of eq. 5 there", minimum=0.1)
    equal_budget_generations: int | None = setting(None, doc="standard --equal-budget", minimum=0)


@dataclass(frozen=True)
class _SettingsKeys:
    repertoire: str | None = setting(None)
    arbitrator: str | None = setting(None)
    neat: str | None = setting(None)
    task: str | None = setting(None)


def robot_folders() -> list[Path]:
    """Where robot settings files are looked for.

    ``config/robots``, then each folder of ``$EVORBC_ROBOT_PATH`` in order (empty entries
    skipped).
    """
    folders = [config_dir() / "robots"]
    for entry in os.environ.get(PATH_VARIABLE, "").split(os.pathsep):
        if entry.strip():
            folders.append(Path(entry).expanduser())
    return folders


def robot_files() -> list[Path]:
    """Every ``*.yaml`` file in :func:`robot_folders`, by folder, then by name."""
    files = []
    for folder in robot_folders():
        if folder.is_dir():
            files += sorted(p for p in folder.glob("*.yaml") if p.is_file())
    return files


def _resolve(value: str, source: Path, key: str, old: Path | None = None) -> str:
    """A file named by key ``key`` of the robot settings file ``source``, as kept.

    Beside the file if there (made absolute); absolute paths as they are. Else from where
    such paths used to be taken, ``old`` (default: evorbc's ``config/``), kept as given,
    with one deprecation line unless ``source`` is one of evorbc's own files in
    ``config/`` (:func:`~evorbc_ros.settings_paths.resolve_beside`); else the absolute
    path beside the file, which the caller then reports missing.
    """
    path = Path(value).expanduser()
    beside = source.resolve().parent / path
    if path.is_absolute() or beside.is_file():
        return str(beside.resolve())
    return resolve_beside(value, source, key, old or config_dir(), config_dir())


def read_robot_file(path: str | os.PathLike) -> Robot | None:
    """The registration a robot settings file declares, or None if it has no ``kind``.

    Raises:
        ConfigError: one line naming the file and the key.

    """
    path = Path(path)
    source = str(path)
    values = load_yaml_mapping(path)
    if "kind" not in values:
        return None
    keys = build_settings(RobotFileKeys, values, source)
    geometry = keys.geometry if keys.geometry is not None else {}
    if not isinstance(geometry, dict):
        raise ConfigError(f"{source}: geometry must be a mapping of the {keys.kind} robot's keys")
    files = keys.settings if keys.settings is not None else {}
    if not isinstance(files, dict):
        raise ConfigError(
            f"{source}: settings must be a mapping of repertoire, arbitrator, neat, task"
        )
    files = build_settings(_SettingsKeys, files, f"{source}: settings")
    if keys.model is not None:
        if keys.kind != "legged":
            raise ConfigError(f"{source}: model is for legged robots; remove it")
        keys = dataclasses.replace(keys, model=_resolve(keys.model, path, "model"))
    builder = {"four_ws": _four_ws, "diff_drive": _diff_drive, "legged": _legged}[keys.kind]
    robot = builder(keys, geometry, source)
    given = {
        f.name: _resolve(getattr(files, f.name), path, f"settings.{f.name}")
        for f in dataclasses.fields(files)
        if getattr(files, f.name) is not None
    }
    changes = {
        "name": keys.name or path.stem,
        "settings": dataclasses.replace(robot.settings, **given),
        "source": source,
    }
    if keys.description:
        changes["description"] = keys.description
    if keys.sensors is not None:
        changes["sensors"] = _resolve(keys.sensors, path, "sensors")
    for key in ("episode_time", "equal_budget_generations"):
        if getattr(keys, key) is not None:
            changes[key] = getattr(keys, key)
    if keys.maze is not None:
        # A maze file (a path: a YAML suffix or a folder part) was taken from the
        # working directory; a shipped maze's name stays a name.
        is_file = keys.maze.endswith((".yaml", ".yml")) or os.sep in keys.maze
        changes["maze"] = _resolve(keys.maze, path, "maze", Path.cwd()) if is_file else keys.maze
    robot = dataclasses.replace(robot, **changes)
    _check_files(robot, source)
    return robot


def _check_files(robot: Robot, source: str) -> None:
    """Every file the robot names exists, so a typo is reported against this file."""
    named = {
        f"settings.{f.name}": getattr(robot.settings, f.name)
        for f in dataclasses.fields(SettingsFiles)
    }
    named["sensors"] = robot.sensors
    for key, value in named.items():
        file = Path(value) if Path(value).is_absolute() else config_dir() / value
        if not file.is_file():
            raise ConfigError(
                f"{source}: {key}: no such file {value} (relative paths are from this file's "
                "folder)"
            )


def _four_ws(keys: RobotFileKeys, geometry: dict, source: str) -> Robot:
    """A 4WS robot: one of the paper's gene layouts on the file's body."""
    from evorbc_ros.robots.builtin.four_ws import four_ws_robot
    from evorbc_ros.robots.four_ws import ROBOT_TYPES, FourWSGeometry, paper_geometry

    if keys.type not in ROBOT_TYPES:
        raise ConfigError(
            f"{source}: type must be one of {', '.join(ROBOT_TYPES)} (the paper's 4WS gene "
            f"layouts), got {keys.type!r}"
        )
    body = FourWSGeometry.from_mapping(geometry, f"{source}: geometry", base=paper_geometry())
    layout = ROBOT_TYPES[keys.type]
    name = keys.name or Path(source).stem
    return four_ws_robot(
        dataclasses.replace(layout, name=name, geometry=body),
        f"4WS robot ({keys.type} genes) of its own dimensions",
    )


def _diff_drive(keys: RobotFileKeys, geometry: dict, source: str) -> Robot:
    """A differential-drive robot."""
    from evorbc_ros.robots.builtin.diff_drive import diff_drive_robot
    from evorbc_ros.robots.diff_drive import DiffDriveGeometry

    if keys.type is not None:
        raise ConfigError(f"{source}: type is for four_ws robots; remove it")
    body = DiffDriveGeometry.from_mapping(geometry, f"{source}: geometry")
    return diff_drive_robot(keys.name or Path(source).stem, body)


def _legged(keys: RobotFileKeys, geometry: dict, source: str) -> Robot:
    """A legged robot: the generic legged registration of its ``model`` settings file."""
    from evorbc_ros.robots.builtin.legged import legged_robot

    if keys.type is not None or geometry:
        raise ConfigError(
            f"{source}: type and geometry are not for legged robots; their body is the "
            "model settings file"
        )
    if keys.model is None:
        raise ConfigError(f"{source}: model: expected the legged settings file (docs/legged.md)")
    model = Path(keys.model) if Path(keys.model).is_absolute() else config_dir() / keys.model
    if not model.is_file():
        raise ConfigError(
            f"{source}: model: no such file {keys.model} (relative paths are from this "
            "file's folder)"
        )
    robot = legged_robot(str(model), "legged robot from its URDF")
    name = keys.name or Path(source).stem
    if robot.name != name:
        # The model's name is what its repertoire and arbitrator files record.
        raise ConfigError(
            f"{source}: the robot is named {name!r} but its model {keys.model} names "
            f"{robot.name!r}; give both the same name"
        )
    return robot
