"""The robot registry: every robot evorbc knows, each declared once, looked up by name.

A robot is one :class:`Robot` registration (docs/design.md section 19, docs/your-robot.md):
its locomotion parameters, the factories of its simulation, maze task, bridge adapter and
onboard command interface, its sensors and task defaults, its settings files, its
equal-budget generations and its shipped controller. Everything that used to branch on a
robot's name (the CLI, MAP-Elites, the tasks, file validation, the nodes, the bridge,
``evorbc-sim`` and the launch logic) looks the robot up here instead, so a new robot needs
no edit anywhere else (the model: QDax's ``environments.create(name)`` and Gymnasium's
registry by id).

Where robots come from:

* **Built in**: the modules in :data:`BUILTIN_MODULES` (the four 4WS types, the
  hexapod and the A1), each with a module-level ``ROBOTS`` tuple, imported on the first look-up.
* **Settings files**: YAML files with a ``kind`` key in ``config/robots/`` and in the
  folders of ``$EVORBC_ROBOT_PATH`` (:mod:`evorbc_ros.robots.settings_robots`): a robot
  declared without Python (a differential-drive robot, a 4WS robot of other dimensions).
  Read when a name is not built in, or when every name is needed. A file that does not
  load is reported once per process in one line naming the file and the key, and left
  out; looking its robot up raises that line.
* **Plugins**: third-party packages declare entry points in the group ``evorbc.robots``
  (:data:`PLUGIN_GROUP`). Each one gives a :class:`Robot`, or a callable returning one or
  an iterable of them. They are discovered lazily: only when a name is not built in, or
  when every name is needed (a help text, an error listing the known robots). A plugin
  that fails to load, or gives something that is not a valid registration, is reported
  once per process in one line on stderr naming the plugin, and left out; every other
  robot works as before.

Layering stays one-way (docs/design.md section 17): this module and the registrations
depend on numpy and PyYAML only. Factories that need the simulation or the search (numba,
PyBullet, pyribs) are named by import path, ``"package.module:attribute"``, and imported
only when called, so an onboard node looks a robot up without loading any of them.
"""

from __future__ import annotations

import importlib
import math
import re
import sys
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from evorbc_ros.config import ConfigError, config_dir
from evorbc_ros.robots.primitive import ParameterSpec

#: The entry-point group third-party packages add robots through.
PLUGIN_GROUP = "evorbc.robots"
#: Modules holding the built-in registrations (a ``ROBOTS`` tuple each), in listing order.
BUILTIN_MODULES = (
    "evorbc_ros.robots.builtin.four_ws",
    "evorbc_ros.robots.builtin.hexapod",
    "evorbc_ros.robots.builtin.a1",
)
#: The robot every command and node uses when none is named.
DEFAULT_ROBOT = "4ws-5"

#: A robot name: it appears in file names, node parameters and comma-separated lists.
_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.+-]*")
#: ``package.module:attribute``, the form of every factory (as entry points write it).
_IMPORT_PATH = re.compile(r"[A-Za-z_][\w.]*:[A-Za-z_][\w.]*")


class RobotError(ConfigError):
    """A robot cannot be used: unknown, invalid, or a factory fails to import.

    The message is one line naming the robot (and the plugin, if any).
    """


class UnknownRobot(RobotError, KeyError):
    """No robot of that name is registered; the message lists the known ones."""

    def __str__(self) -> str:
        # KeyError would quote the message; it is a sentence.
        return str(self.args[0]) if self.args else ""


@dataclass(frozen=True)
class SettingsFiles:
    """A robot's default settings files: relative to ``config/``, or absolute."""

    repertoire: str  # MAP-Elites settings (config/repertoire/*.yaml)
    arbitrator: str  # arbitrator and standard-NEAT run settings (config/arbitrator/*.yaml)
    neat: str  # NEAT settings, neat-python's INI format (config/neat/*.ini)
    task: str  # maze task settings (config/tasks/*.yaml)


@dataclass(frozen=True)
class Robot:
    """One robot, declared once: everything evorbc needs to know about it.

    Factories are import paths ``"package.module:attribute"``, imported on first use
    (docs/your-robot.md gives each one's call and what it must return). Lengths in m,
    times in s, speeds in m/s; frames follow REP 103 (x forward, y left).

    Attributes:
        name: the robot's name in files, settings, options and node parameters.
        description: one line for listings and docs.
        parameters: its locomotion parameters: names, SI units and physical ranges; a
            primitive's gene ``k`` in [-1, 1] maps linearly onto ``parameters[k]``.
        settings: its default settings files.
        simulation: ``f(robot, workers=None)`` -> a
            :class:`sim_bridge.robots.base.SimulatedRobot` that executes batches of
            primitives from rest (MAP-Elites' evaluation).
        task: ``f(robot, settings, workers=None)`` -> its maze task (episodes of
            networks driving the robot, eq. 5 fitness) for a ``MazeTaskSettings``.
        bridge: the bridge adapter class of ``sim_bridge``:
            ``cls(node, robot_name, maze, pose, episode_time, gui)``.
        commands: the onboard command interface class of ``primitive_executor``:
            ``cls(node, robot, inputs, stale_timeout)``.
        command_topics: the topics its command interface publishes by default; the
            bridge waits for a publisher on each before an episode starts.
        sensors: its default sensor layout, relative to ``config/`` or absolute.
        maze: the maze it runs in when none is named (a name in ``config/mazes/`` or a
            file).
        episode_time: s, the default episode length T of eq. 5 in that maze.
        footprint_radius: m, a circle about the body centre that holds the whole robot;
            start poses keep it clear of walls.
        max_speed: m/s, a bound on any primitive's mean displacement speed: the archive
            spans ``max_speed x T`` (memory estimates size it from this).
        equal_budget_generations: generations added to standard NEAT by
            ``--equal-budget``, so it gets the simulated time EvoRBC's repertoire cost.
        episode_bytes: bytes of memory one episode of a generation takes (estimates).
        shipped_repertoire: the repertoire shipped for it ("" for none), relative to
            ``evorbc_ros/data`` or absolute.
        shipped_arbitrator: the arbitrator shipped with that repertoire ("" for none).
        paper_arbitrator: the paper-protocol arbitrator (trained on the paper's mazes
            only) when the shipped default is another, e.g. one trained on generated
            mazes; "" means the shipped arbitrator is the paper protocol's. Relative to
            ``evorbc_ros/data`` or absolute, for the shipped repertoire; it needs a
            shipped controller. ``--paper`` and the tests pinning the paper protocol's
            figures use it.
        design_check: optional ``f(robot, controller)`` raising ``ConfigError`` when
            ``evorbc-sim`` is given a controller evolved for another design than the
            bridge simulates (the hexapod's geometry, physics and laser).
        model: the robot's own definition, for its factories (a 4WS robot: its
            ``FourWSType``); evorbc never reads it.
        node_defaults: ``(parameter, value)`` pairs: the robot's own defaults for the
            executor's and the bridge's parameters (a 4WS robot's ``wheel_radius``, m),
            used where no parameter file or ``--ros-args`` sets them.
        source: the settings file it was declared in ("" for one declared in Python).

    """

    name: str
    description: str
    parameters: tuple[ParameterSpec, ...]
    settings: SettingsFiles
    simulation: str
    task: str
    bridge: str
    commands: str
    command_topics: tuple[str, ...]
    sensors: str
    maze: str
    episode_time: float
    footprint_radius: float
    max_speed: float
    equal_budget_generations: int = 0
    episode_bytes: int = 400
    shipped_repertoire: str = ""
    shipped_arbitrator: str = ""
    paper_arbitrator: str = ""
    design_check: str = ""
    model: Any = None
    node_defaults: tuple[tuple[str, Any], ...] = ()
    source: str = ""

    @property
    def n_parameters(self) -> int:
        """Number of locomotion parameters (genes) of a primitive."""
        return len(self.parameters)

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """The parameters' names, as the arbitrator labels a primitive's genes."""
        return tuple(p.name for p in self.parameters)

    def node_default(self, parameter: str, fallback: Any) -> Any:
        """The robot's default for a node parameter, or ``fallback`` if it gives none."""
        return dict(self.node_defaults).get(parameter, fallback)

    def settings_file(self, kind: str) -> Path:
        """The default settings file of ``kind`` (repertoire, arbitrator, neat or task)."""
        return _in_config(getattr(self.settings, kind))

    def sensors_file(self) -> Path:
        """The default sensor layout file."""
        return _in_config(self.sensors)

    def load(self, field: str) -> Any:
        """The object a factory field names, imported now.

        Raises:
            RobotError: one line naming the robot, the field and why it cannot be imported.

        """
        path = getattr(self, field)
        module, _, attribute = path.partition(":")
        try:
            target = importlib.import_module(module)
            for part in attribute.split("."):
                target = getattr(target, part)
        except (ImportError, AttributeError) as e:
            raise RobotError(
                f"robot {self.name}: its {field} {path!r} cannot be loaded ({_one_line(e)})"
            ) from None
        return target

    def make_simulation(self, workers: int | None = None):
        """Its simulated robot for primitive evaluation (``simulation(self, workers)``)."""
        return self.load("simulation")(self, workers=workers)

    def make_task(self, settings, workers: int | None = None):
        """Its maze task for ``settings`` (``task(self, settings, workers)``)."""
        return self.load("task")(self, settings, workers=workers)

    def check_design(self, controller) -> None:
        """Run its design check on a controller, if it has one (``evorbc-sim``)."""
        if self.design_check:
            self.load("design_check")(self, controller)


def _in_config(name: str) -> Path:
    path = Path(name)
    return path if path.is_absolute() else config_dir() / path


def _one_line(error: BaseException) -> str:
    text = str(error).strip().splitlines()
    return f"{type(error).__name__}: {text[0]}" if text else type(error).__name__


def registration_problem(robot: Any) -> str | None:
    """The first reason ``robot`` is not a valid registration, or None."""
    if not isinstance(robot, Robot):
        return f"expected an evorbc_ros.robots.registry.Robot, got {type(robot).__name__}"
    if not isinstance(robot.name, str) or not _NAME.fullmatch(robot.name):
        return (
            f"name {robot.name!r} must be letters, digits and . _ + - (starting with a letter "
            "or digit)"
        )
    where = f"robot {robot.name}"
    params = robot.parameters
    if not isinstance(params, tuple) or not params:
        return f"{where}: parameters must be a non-empty tuple of ParameterSpec"
    for k, p in enumerate(params):
        if not isinstance(p, ParameterSpec):
            return f"{where}: parameters[{k}] must be a ParameterSpec, got {type(p).__name__}"
        if not (math.isfinite(p.low) and math.isfinite(p.high) and p.low < p.high):
            return f"{where}: parameters[{k}] ({p.name}) needs finite low < high"
    if not isinstance(robot.settings, SettingsFiles):
        return f"{where}: settings must be a SettingsFiles"
    for field in ("simulation", "task", "bridge", "commands"):
        value = getattr(robot, field)
        if not isinstance(value, str) or not _IMPORT_PATH.fullmatch(value):
            return f"{where}: {field} must be an import path 'package.module:attribute'"
    if robot.design_check and not _IMPORT_PATH.fullmatch(robot.design_check):
        return f"{where}: design_check must be '' or 'package.module:attribute'"
    for field in ("episode_time", "footprint_radius", "max_speed"):
        value = getattr(robot, field)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return f"{where}: {field} must be a number"
        if not (math.isfinite(value) and value > 0):
            return f"{where}: {field} must be > 0, got {value!r}"
    for field in ("equal_budget_generations", "episode_bytes"):
        value = getattr(robot, field)
        if isinstance(value, bool) or not isinstance(value, int) or value < 0:
            return f"{where}: {field} must be an integer >= 0"
    if not (isinstance(robot.command_topics, tuple) and robot.command_topics):
        return f"{where}: command_topics must be a non-empty tuple of topic names"
    if bool(robot.shipped_repertoire) != bool(robot.shipped_arbitrator):
        return f"{where}: a shipped controller needs both shipped_repertoire and shipped_arbitrator"
    if robot.paper_arbitrator and not robot.shipped_arbitrator:
        return (
            f"{where}: paper_arbitrator needs a shipped controller (shipped_repertoire and "
            "shipped_arbitrator)"
        )
    return None


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


def _report(problem: str) -> None:
    print(f"evorbc: warning: {problem}", file=sys.stderr)


class Registry:
    """Robots by name: the built-in ones, then plugins, each found on first need.

    Args:
        builtin_modules: modules with a ``ROBOTS`` tuple of registrations.
        group: the entry-point group plugins declare.
        report: called once with each broken plugin's one-line problem.

    """

    def __init__(
        self,
        builtin_modules: Sequence[str] = BUILTIN_MODULES,
        group: str = PLUGIN_GROUP,
        report: Callable[[str], None] = _report,
    ) -> None:
        self.builtin_modules = tuple(builtin_modules)
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
        for module in self.builtin_modules:
            for robot in importlib.import_module(module).ROBOTS:
                self.register(robot)

    def _settings_files(self) -> None:
        if self._files_done:
            return
        self._files_done = True
        self._builtins()
        from evorbc_ros.robots.settings_robots import read_robot_file, robot_files

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
                self._problem(f"{where} cannot be loaded ({_one_line(e)}); its robots are left out")
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


def plugin_problems() -> list[str]:
    """The broken plugins found so far, one line each."""
    return list(_registry.problems)


def reset() -> None:
    """Forget every registration and plugin found (tests that install a plugin)."""
    global _registry
    _registry = Registry()
