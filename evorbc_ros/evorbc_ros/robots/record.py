"""The onboard robot record: what evorbc knows about a robot below the simulation and search.

A :class:`Robot` holds the facts the onboard nodes and the file checks need (its
locomotion parameters, its onboard command interface and topics, sensors, limits,
settings files, shipped controller) and its ``family``, the key under which the
simulation and the search layers keep their own adapters for it (docs/design.md section
19). It names no module of those layers: they register their adapters in their own
tables (:mod:`evorbc_ros.robots.adapters`), so this package stays the lowest layer
(section 17).

This module imports numpy and PyYAML only (through :mod:`evorbc_ros.config`), and nothing
of the registry, so the registrations can import it without a cycle.
"""

from __future__ import annotations

import importlib
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from evorbc_ros.config import ConfigError, config_dir
from evorbc_ros.robots.primitive import ParameterSpec

#: A robot name: it appears in file names, node parameters and comma-separated lists.
_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.+-]*")
#: ``package.module:attribute``, the form of every import path (as entry points write it).
IMPORT_PATH = re.compile(r"[A-Za-z_][\w.]*:[A-Za-z_][\w.]*")
#: Fields a record used to name the simulation's and the search's factories by; read only
#: for robots declared that way (deprecated: the layers' adapter tables replace them).
LEGACY_FIELDS = ("simulation", "task", "bridge", "design_check")
#: The one line that names the replacement of :data:`LEGACY_FIELDS`.
LEGACY_NOTICE = (
    "Robot(simulation=, task=, bridge=, design_check=) is deprecated; give the robot a "
    "family and declare its adapters in the entry-point groups evorbc.sim_adapters and "
    "evorbc.search_adapters (docs/your-robot.md)"
)


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
    """One robot, declared once: the facts evorbc needs onboard and to check files.

    Lengths in m, times in s, speeds in m/s; frames follow REP 103 (x forward, y left).
    docs/your-robot.md gives each field and who reads it.

    Attributes:
        name: the robot's name in files, settings, options and node parameters.
        description: one line for listings and docs.
        parameters: its locomotion parameters: names, SI units and physical ranges; a
            primitive's gene ``k`` in [-1, 1] maps linearly onto ``parameters[k]``.
        settings: its default settings files.
        commands: import path of the onboard command interface class of
            ``primitive_executor``: ``cls(node, robot, inputs, stale_timeout)``.
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
        family: the key the simulation and the search find its adapters under
            (``four_ws``, ``diff_drive``, ``hexapod``, ``legged``, or a plugin's own);
            "" means the robot's name (:attr:`adapter_key`).
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
            shipped controller.
        model: the robot's own definition, for its adapters (a 4WS robot: its
            ``FourWSType``); the onboard code reads it only through its family's code.
        node_defaults: ``(parameter, value)`` pairs: the robot's own defaults for the
            executor's and the bridge's parameters (a 4WS robot's ``wheel_radius``, m),
            used where no parameter file or ``--ros-args`` sets them.
        source: the settings file it was declared in ("" for one declared in Python).
        simulation, task, bridge, design_check: deprecated import paths of the
            simulation's and the search's factories (:data:`LEGACY_NOTICE`); "" for every
            robot declared the current way. Set, they override the family's adapters.

    """

    name: str
    description: str
    parameters: tuple[ParameterSpec, ...]
    settings: SettingsFiles
    commands: str
    command_topics: tuple[str, ...]
    sensors: str
    maze: str
    episode_time: float
    footprint_radius: float
    max_speed: float
    family: str = ""
    equal_budget_generations: int = 0
    episode_bytes: int = 400
    shipped_repertoire: str = ""
    shipped_arbitrator: str = ""
    paper_arbitrator: str = ""
    model: Any = None
    node_defaults: tuple[tuple[str, Any], ...] = ()
    source: str = ""
    simulation: str = ""
    task: str = ""
    bridge: str = ""
    design_check: str = ""

    @property
    def n_parameters(self) -> int:
        """Number of locomotion parameters (genes) of a primitive."""
        return len(self.parameters)

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """The parameters' names, as the arbitrator labels a primitive's genes."""
        return tuple(p.name for p in self.parameters)

    @property
    def adapter_key(self) -> str:
        """The key the layers' adapter tables know this robot by: its family, or its name."""
        return self.family or self.name

    @property
    def legacy_factories(self) -> dict[str, str]:
        """The deprecated factory fields it sets (:data:`LEGACY_FIELDS`), by field."""
        return {f: getattr(self, f) for f in LEGACY_FIELDS if getattr(self, f)}

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
        """The object an import-path field names (``commands``), imported now.

        Raises:
            RobotError: one line naming the robot, the field and why it cannot be imported.

        """
        return load_path(getattr(self, field), f"robot {self.name}: its {field}")


def load_path(path: str, where: str) -> Any:
    """The object ``"package.module:attribute"`` names, imported now.

    Args:
        path: the import path.
        where: what names it, for the message (``robot crab: its simulation``).

    Raises:
        RobotError: one line, ``where`` first, saying why it cannot be imported.

    """
    module, _, attribute = path.partition(":")
    try:
        target = importlib.import_module(module)
        for part in attribute.split("."):
            target = getattr(target, part)
    except (ImportError, AttributeError) as e:
        raise RobotError(f"{where} {path!r} cannot be loaded ({one_line(e)})") from None
    return target


def _in_config(name: str) -> Path:
    path = Path(name)
    return path if path.is_absolute() else config_dir() / path


def one_line(error: BaseException) -> str:
    """``Type: first line of the message``, for one-line reports."""
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
    if not isinstance(robot.commands, str) or not IMPORT_PATH.fullmatch(robot.commands):
        return f"{where}: commands must be an import path 'package.module:attribute'"
    for field in LEGACY_FIELDS:
        value = getattr(robot, field)
        if value and (not isinstance(value, str) or not IMPORT_PATH.fullmatch(value)):
            return f"{where}: {field} must be an import path 'package.module:attribute'"
    if not isinstance(robot.family, str) or (robot.family and not _NAME.fullmatch(robot.family)):
        return f"{where}: family must be '' or letters, digits and . _ + -"
    return _figures_problem(robot, where)


def _figures_problem(robot: Robot, where: str) -> str | None:
    """The first problem with the record's numbers, topics and shipped files, or None."""
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
