"""The robot registry: every robot evorbc knows, each declared once, looked up by name.

A robot is one :class:`~evorbc_ros.robots.record.Robot` record (docs/design.md section 19,
docs/your-robot.md): its locomotion parameters, onboard command interface, sensors, task
defaults, settings files, equal-budget generations and shipped controller, and its
``family``. Everything that used to branch on a robot's name (the CLI, MAP-Elites, the
tasks, file validation, the nodes, the bridge, ``evorbc-sim`` and the launch logic) looks
the robot up here instead, so a new robot needs no edit anywhere else (the model: QDax's
``environments.create(name)`` and Gymnasium's registry by id). The simulation and the
search find their own code for a robot in their own adapter tables, by its family
(:mod:`evorbc_ros.robots.adapters`); this registry names none of it.

Where robots come from:

* **Built in**: the modules of :mod:`evorbc_ros.robots.builtin` (the four 4WS types, the
  hexapod and the A1), each with a module-level ``ROBOTS`` tuple, imported on the first
  look-up.
* **Settings files**: YAML files with a ``kind`` key in ``config/robots/`` and in the
  folders of ``$EVORBC_ROBOT_PATH`` (:mod:`evorbc_ros.robots.settings_robots`): a robot
  declared without Python (a differential-drive robot, a 4WS robot of other dimensions).
  Read when a name is not built in, or when every name is needed. A file that does not
  load is reported once per process in one line naming the file and the key, and left
  out; looking its robot up raises that line.
* **Plugins**: third-party packages declare entry points in the group ``evorbc.robots``
  (:data:`PLUGIN_GROUP`). Each one gives a record, or a callable returning one or an
  iterable of them. They are discovered lazily: only when a name is not built in, or
  when every name is needed (a help text, an error listing the known robots). A plugin
  that fails to load, or gives something that is not a valid registration, is reported
  once per process in one line on stderr naming the plugin, and left out; every other
  robot works as before.

Imports go one way (docs/design.md section 17): this module imports the registrations
and the settings-file reader, which import :mod:`~evorbc_ros.robots.record` and never this
module; all of them need numpy and PyYAML only.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterable, Iterator, Sequence
from typing import Any

from evorbc_ros.config import ConfigError
from evorbc_ros.robots.adapters import report as _report
from evorbc_ros.robots.four_ws import FourWSType
from evorbc_ros.robots.record import (
    LEGACY_NOTICE,
    Robot,
    RobotError,
    SettingsFiles,
    UnknownRobot,
    one_line,
    registration_problem,
)
from evorbc_ros.robots.settings_robots import read_robot_file, robot_files

__all__ = [
    "DEFAULT_ROBOT",
    "PLUGIN_GROUP",
    "ROBOT_NAMES",
    "Registry",
    "Robot",
    "RobotError",
    "SettingsFiles",
    "UnknownRobot",
    "known",
    "lookup",
    "names",
    "plugin_problems",
    "register",
    "registration_problem",
    "reset",
    "robot_type",
    "robots",
]

#: The entry-point group third-party packages add robots through.
PLUGIN_GROUP = "evorbc.robots"
#: The robot every command and node uses when none is named.
DEFAULT_ROBOT = "4ws-5"


def builtin_robots() -> tuple[Robot, ...]:
    """The robots evorbc ships in Python, in listing order (imported when first needed)."""
    from evorbc_ros.robots.builtin import a1, four_ws, hexapod

    return four_ws.ROBOTS + hexapod.ROBOTS + a1.ROBOTS


def _registrations(loaded: Any) -> list:
    """What an entry point gave: one registration, or those a callable returns."""
    if isinstance(loaded, Robot):
        return [loaded]
    if not callable(loaded):
        raise TypeError(
            f"gave a {type(loaded).__name__}, expected a Robot or a callable returning robots"
        )
    made = loaded()
    if isinstance(made, Robot):
        return [made]
    if isinstance(made, Iterable) and not isinstance(made, (str, bytes)):
        return list(made)
    raise TypeError(f"its callable returned a {type(made).__name__}, expected robots")


class Registry:
    """Robots by name: the built-in ones, then settings files', then plugins', each on need.

    Args:
        builtin_modules: modules with a ``ROBOTS`` tuple of registrations (default:
            :func:`builtin_robots`).
        group: the entry-point group plugins declare.
        report: called once with each broken plugin's one-line problem.

    """

    def __init__(
        self,
        builtin_modules: Sequence[str] | None = None,
        group: str = PLUGIN_GROUP,
        report: Callable[[str], None] = _report,
    ) -> None:
        self.builtin_modules = None if builtin_modules is None else tuple(builtin_modules)
        self.group = group
        self.report = report
        self._robots: dict[str, Robot] = {}
        self._builtin_done = False
        self._files_done = False
        self._plugins_done = False
        #: The one-line problem of each robot settings file that failed, by its stem.
        self.file_problems: dict[str, str] = {}
        self._files_failed = 0
        #: One line per plugin or registration that could not be used.
        self.problems: list[str] = []

    def _builtins(self) -> None:
        if self._builtin_done:
            return
        self._builtin_done = True
        if self.builtin_modules is None:
            robots = builtin_robots()
        else:
            robots = [r for m in self.builtin_modules for r in importlib.import_module(m).ROBOTS]
        for robot in robots:
            self.register(robot)

    def _settings_files(self) -> None:
        if self._files_done:
            return
        self._files_done = True
        self._builtins()
        for path in robot_files():
            try:
                robot = read_robot_file(path)
                if robot is not None:
                    self.register(robot)
            except ConfigError as e:  # RobotError too: an invalid or taken name
                self.file_problems.setdefault(path.stem, str(e))
                self._files_failed += 1
                self._problem(f"robot file {e}; left out")

    def _plugins(self) -> None:
        if self._plugins_done:
            return
        self._plugins_done = True
        self._settings_files()
        from importlib.metadata import entry_points

        for point in sorted(entry_points(group=self.group), key=lambda p: p.name):
            dist = getattr(point, "dist", None)
            origin = f" in {dist.name} {dist.version}" if dist is not None else ""
            where = f"robot plugin {point.name} ({point.value}{origin})"
            try:
                robots = _registrations(point.load())
            except Exception as e:  # whatever a plugin does, it must not stop evorbc
                self._problem(f"{where} cannot be loaded ({one_line(e)}); its robots are left out")
                continue
            for robot in robots:
                try:
                    self.register(robot)
                except RobotError as e:
                    self._problem(f"{where}: {e}; left out")

    def _problem(self, text: str) -> None:
        self.problems.append(text)
        self.report(text)

    def register(self, robot: Robot) -> None:
        """Add a registration.

        Raises:
            RobotError: it is invalid, or its name is taken.

        """
        problem = registration_problem(robot)
        if problem:
            raise RobotError(problem)
        if robot.name in self._robots:
            raise RobotError(f"robot {robot.name} is already registered")
        self._robots[robot.name] = robot
        if robot.legacy_factories:
            # Not a problem: the robot works; its declaration has a newer form.
            self.report(f"robot {robot.name}: {LEGACY_NOTICE}")

    def lookup(self, name: str) -> Robot:
        """The robot called ``name``.

        Raises:
            UnknownRobot: one line listing the known robots (and any broken plugin).

        """
        if self.known(name):
            return self._robots[name]
        if isinstance(name, str) and name in self.file_problems:
            raise RobotError(f"robot {name}: {self.file_problems[name]}")
        known = ", ".join(self.names())
        plugins = len(self.problems) - self._files_failed
        broken = f" ({plugins} robot plugin(s) failed to load)" if plugins else ""
        if self._files_failed:
            broken += f" ({self._files_failed} robot file(s) failed to load)"
        raise UnknownRobot(f"unknown robot {name!r}; known robots: {known}{broken}")

    def known(self, name: Any) -> bool:
        """True if ``name`` is a registered robot (plugins are looked at only if needed)."""
        if not isinstance(name, str):
            return False
        self._builtins()
        if name not in self._robots:
            self._settings_files()
        if name not in self._robots:
            self._plugins()
        return name in self._robots

    def names(self) -> tuple[str, ...]:
        """Every robot's name.

        Built-in ones first, then settings files' (by folder, then file name), then
        plugins' (by entry-point name).
        """
        self._plugins()
        return tuple(self._robots)

    def robots(self) -> tuple[Robot, ...]:
        """Every registration, in :meth:`names` order."""
        self._plugins()
        return tuple(self._robots.values())


class RobotNames(Sequence):
    """The registered names as a live, lazy sequence, for choices given before lookup.

    Usable wherever choices are declared at import time (argparse's ``choices``, settings
    fields) before any plugin has been looked for.
    ``name in ROBOT_NAMES`` looks at plugins only when ``name`` is not built in; listing
    the names finds every plugin.
    """

    def __contains__(self, name: object) -> bool:
        return _registry.known(name)

    def __iter__(self) -> Iterator[str]:
        return iter(_registry.names())

    def __len__(self) -> int:
        return len(_registry.names())

    def __getitem__(self, index):
        return _registry.names()[index]

    def __repr__(self) -> str:
        return f"RobotNames({', '.join(self)})"


_registry = Registry()
#: Every registered robot's name (live: plugins included once looked for).
ROBOT_NAMES = RobotNames()


def lookup(name: str) -> Robot:
    """The robot called ``name`` (:meth:`Registry.lookup`)."""
    return _registry.lookup(name)


def known(name: Any) -> bool:
    """True if ``name`` is a registered robot."""
    return _registry.known(name)


def names() -> tuple[str, ...]:
    """Every registered robot's name, built-in ones first."""
    return _registry.names()


def robots() -> tuple[Robot, ...]:
    """Every registration."""
    return _registry.robots()


def register(robot: Robot) -> None:
    """Register a robot in this process (a script's own robot; plugins use entry points).

    Raises:
        RobotError: it is invalid, or its name is taken.

    """
    _registry.register(robot)


def robot_type(name: str) -> FourWSType:
    """The 4WS robot type called ``name``: a built-in one, or a plugin's 4WS variant.

    The registry's 4WS robots carry their type as ``model``.

    Raises:
        KeyError: with a message listing the known 4WS types.

    """
    if known(name) and isinstance(lookup(name).model, FourWSType):
        return lookup(name).model
    known_types = ", ".join(r.name for r in robots() if isinstance(r.model, FourWSType))
    raise KeyError(f"unknown 4WS robot type {name!r}; expected one of {known_types}")


def plugin_problems() -> list[str]:
    """The broken plugins found so far, one line each."""
    return list(_registry.problems)


def reset() -> None:
    """Forget every registration and plugin found (tests that install a plugin)."""
    global _registry
    _registry = Registry()
