"""What every maze task shares: settings, mazes, start poses, eq. 5 fitness and traces.

A controller's fitness in one episode is (paper eq. 5, docs/design.md section 4)::

    2 - t / T          if the target was reached after t seconds (T = episode_time)
    1 - d_f / d_i      otherwise (final over initial distance to the target)

and its fitness for selection is the mean over the task's episodes (one per maze by
default, new random starts each generation). With a ``training`` setting, each generation
also runs on newly drawn generated mazes (:mod:`~offline_evolution.maze_task.training`,
docs/design.md section 22).

:class:`MazeTaskBase` holds this; the 4WS task (:mod:`~offline_evolution.maze_task.task`)
and the hexapod's (:mod:`~offline_evolution.maze_task.hexapod_task`) add how episodes run.
Both implement :class:`~offline_evolution.task_protocol.ArbitratorTask`.
"""

from __future__ import annotations

import abc
import dataclasses
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from evorbc_ros.config import ConfigError, build_settings, config_dir, load_yaml_mapping, setting
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.primitive import ParameterSpec
from evorbc_ros.sensors import SensorLayout
from evorbc_ros.settings_paths import resolve_beside
from offline_evolution.maze_task.perturbation import is_set_file
from offline_evolution.maze_task.training import TrainingMazes, TrainingSettings, check_training
from offline_evolution.task_protocol import EpisodeResult
from sim_bridge.maze import Maze, is_maze_file, load_named_maze
from sim_bridge.robots.base import control_steps

#: s between the arbitrator's decisions, for the 4WS robots and the hexapod alike.
CONTROL_PERIOD = 0.1

#: The choice a trace holds for a cycle the episode did not run (it ended before).
NOT_RUN = -2


@dataclass(frozen=True)
class MazeTaskSettings:
    """What defines the task (``config/tasks/*.yaml``)."""

    mazes: tuple[str, ...] = setting(doc="maze names or files")
    episode_time: float = setting(120.0, doc="episode length T (s)", minimum=0.1)
    samples_per_maze: int = setting(1, doc="random starts per maze per evaluation", minimum=1)
    sensors: str = setting(
        "sensors/4ws.yaml",
        doc="sensor layout file: in a task file, from the file's folder; as recorded, "
        "relative to config/ or absolute",
    )
    # A frozen dataclass: the default call is a field declaration, not a shared value.
    training: TrainingSettings | None = setting(  # noqa: RUF009
        None, doc="training on generated mazes (docs/design.md section 22); none: the paper's"
    )
    maze_scale: tuple[float, ...] | None = setting(
        None,
        doc="per maze, the factor it is scaled up by to fit the robot (docs/design.md "
        "section 21); recorded by a run that scaled one; none: each maze as its file has it",
    )

    def __post_init__(self):
        # A recorded task (checkpoint, arbitrator file) holds ``training`` as a mapping.
        if isinstance(self.training, dict):
            training = TrainingSettings.from_dict(self.training, "the task's training")
            object.__setattr__(self, "training", training)
        if self.maze_scale is not None:  # a recorded list (``MazeTaskSettings(**task)``)
            object.__setattr__(self, "maze_scale", tuple(float(f) for f in self.maze_scale))

    @classmethod
    def load(cls, path: str | os.PathLike) -> MazeTaskSettings:
        """Settings from a task file (``config/tasks/*.yaml``).

        Relative paths (``sensors``, maze files in ``mazes``) are from the file's folder
        (:func:`~evorbc_ros.settings_paths.resolve_beside`; the old locations, ``config/``
        for ``sensors`` and the working directory for maze files, still work with a
        deprecation line). Maze names stay names (``config/mazes/``).

        Raises:
            ConfigError: naming the file and the key, for any bad setting (see
                :meth:`from_dict`).
        """
        return cls.from_dict(task_file_values(path), str(path))

    @classmethod
    def from_dict(cls, values: dict, source: str) -> MazeTaskSettings:
        """Settings from a mapping: a task file's, or the one an arbitrator file records.

        Raises:
            ConfigError: naming ``source`` and the key, for any bad setting; episode_time
                must be a whole number of the 0.1 s control cycles that every robot
                family here uses (paper Sec. III-C), and every maze and the sensor
                layout must load.
        """
        if not isinstance(values, dict):
            raise ConfigError(f"{source}: expected a mapping of task settings")
        values = dict(values)
        training = values.pop("training", None)
        if training is not None:
            values["training"] = TrainingSettings.from_dict(training, source)
        settings = build_settings(cls, values, source)
        try:
            control_steps(settings.episode_time, CONTROL_PERIOD)
        except ValueError as e:
            raise ConfigError(f"{source}: episode_time {e}") from None
        if not settings.mazes:
            raise ConfigError(f"{source}: mazes must name at least one maze")
        scale = settings.maze_scale
        if scale is not None and (
            len(scale) != len(settings.mazes) or not all(1.0 <= f <= 100.0 for f in scale)
        ):
            raise ConfigError(
                f"{source}: maze_scale must be one factor in [1, 100] per maze "
                f"({len(settings.mazes)}), got {list(scale)}"
            )
        # The files the task refers to, checked here so that an error names this source.
        for name in settings.mazes:
            try:
                load_named_maze(name)
            except ConfigError as e:
                raise ConfigError(f"{source}: mazes: {e}") from None
        layout = config_dir() / settings.sensors
        if not layout.is_file():
            raise ConfigError(
                f"{source}: sensors: no such file {layout} (relative paths are from the "
                "task file's folder)"
            )
        try:
            SensorLayout.load(layout)
        except ConfigError as e:
            raise ConfigError(f"{source}: sensors: {e}") from None
        return settings

    def as_dict(self) -> dict:
        """Plain-data form (recorded in arbitrator files); ``training``, ``maze_scale`` if set."""
        out = {
            "mazes": list(self.mazes),
            "episode_time": self.episode_time,
            "samples_per_maze": self.samples_per_maze,
            "sensors": self.sensors,
        }
        if self.training is not None:
            out["training"] = self.training.as_dict()
        if self.maze_scale is not None:
            out["maze_scale"] = list(self.maze_scale)
        return out


def task_file_values(path: str | os.PathLike) -> dict:
    """A task file's mapping with its relative paths resolved beside it.

    ``sensors`` as recorded tasks name it (relative to ``config/`` within the checkout,
    else absolute), maze files and a ``training.perturb`` set file absolute, maze and set
    names as they are; an old location (``config/`` for ``sensors``, the working directory
    for maze and set files) still works with a deprecation line
    (:func:`~evorbc_ros.settings_paths.resolve_beside`).
    """
    values = load_yaml_mapping(path)
    source = str(path)
    if isinstance(values.get("sensors"), str):
        values["sensors"] = resolve_beside(
            values["sensors"], source, "sensors", config_dir(), config_dir()
        )
    if isinstance(values.get("mazes"), list):
        values["mazes"] = [
            resolve_beside(m, source, f"mazes[{k}]", Path.cwd())
            if isinstance(m, str) and is_maze_file(m)
            else m
            for k, m in enumerate(values["mazes"])
        ]
    training = values.get("training")
    perturb = training.get("perturb") if isinstance(training, dict) else None
    if isinstance(perturb, str) and is_set_file(perturb):  # a set's name stays a name
        where = "training.perturb"
        values["training"] = {
            **training,
            "perturb": resolve_beside(perturb, source, where, Path.cwd()),
        }
    return values


def fit_task_mazes(
    settings: MazeTaskSettings,
    footprint_radius: float,
    robot: str = "the robot",
    warn: Callable[[str], None] | None = None,
) -> tuple[MazeTaskSettings, list[Maze]]:
    """The task's mazes, each scaled up to fit the robot, and the settings recording it.

    A maze whose factor ``settings.maze_scale`` records is scaled by it; any other is
    scaled by the smallest factor that fits (:func:`~sim_bridge.maze_fit.fit_scale`,
    docs/design.md section 21), and ``warn`` is called with one line naming the maze, the
    factor and why. Nothing is printed here: a run passes its reporters' ``warning``, so
    that the command line, a study and a recipe each say it their way, once. The settings
    returned record every factor (``maze_scale``) when one is not 1, else they are
    ``settings`` unchanged.

    Raises:
        ConfigError: no scale fits a maze, or a recorded scale leaves the robot's
            footprint touching a wall at the maze's nominal start (replay, the
            post-selection and the ROS bridge start there).
    """
    from sim_bridge.maze_fit import fitted_maze

    recorded = settings.maze_scale or (None,) * len(settings.mazes)
    mazes, factors = [], []
    for name, factor in zip(settings.mazes, recorded, strict=True):
        loaded = load_named_maze(name)  # its own errors name the maze already
        try:
            maze, factor_used, warning = fitted_maze(loaded, footprint_radius, robot, factor)
        except ValueError as e:
            raise ConfigError(f"mazes: {e}") from None
        if warning and factor is None and warn is not None:
            warn(warning)
        misfit = maze.start_misfit(footprint_radius, robot)
        if misfit:
            raise ConfigError(f"mazes: {misfit}")
        mazes.append(maze)
        factors.append(factor_used)
    if settings.maze_scale is None and any(f != 1.0 for f in factors):
        settings = dataclasses.replace(settings, maze_scale=tuple(factors))
    return settings, mazes


def eq5_fitness(reached, seconds, final, initial, episode_time: float) -> np.ndarray:
    """Eq. 5 per episode: ``2 - t/T`` if reached after ``t`` s, else ``1 - d_f / d_i``.

    Args:
        reached: ``(E,)`` bool; seconds: ``(E,)`` s until the target (or the whole
            episode); final, initial: ``(E,)`` m to the target; episode_time: T, s.

    """
    with np.errstate(divide="ignore", invalid="ignore"):
        missed = np.where(initial > 0, 1.0 - final / initial, 0.0)
    return np.where(reached, 2.0 - np.asarray(seconds) / episode_time, missed)


def empty_traces(episodes: int, n_cycles: int, n_outputs: int):
    """``(pose, choice, outputs)`` for ``episodes`` recorded episodes, no cycle run yet.

    Returns:
        ``pose (E, n_cycles + 1, 3)`` and ``outputs (E, n_cycles, n_outputs)`` of NaN,
        ``choice (E, n_cycles)`` of :data:`NOT_RUN`; an episode fills the cycles it runs.

    """
    pose = np.full((episodes, n_cycles + 1, 3), np.nan)
    choice = np.full((episodes, n_cycles), NOT_RUN, dtype=np.int64)
    outputs = np.full((episodes, n_cycles, n_outputs), np.nan)
    return pose, choice, outputs


class MazeTaskBase(abc.ABC):
    """A maze task's settings, mazes, sensors, start poses and eq. 5 fitness.

    A robot's maze task adds its locomotion parameters, its controllers and how its
    episodes run (the rest of :class:`~offline_evolution.task_protocol.ArbitratorTask`).

    Args:
        settings: the task.
        dt: s, the robot's control period.
        footprint_radius: m, how far a start keeps the robot's centre from walls.
        robot_name: how an error names the robot.

    """

    def __init__(
        self,
        settings: MazeTaskSettings,
        dt: float,
        footprint_radius: float,
        robot_name: str = "the robot",
    ):
        #: Warnings of building the task (a maze scaled up to fit the robot, unless the
        #: scale is the recorded one: :func:`fit_task_mazes`), for the run that made the
        #: task to tell through its reporters; the task prints nothing.
        self.warnings: list[str] = []
        settings, mazes = fit_task_mazes(
            settings, footprint_radius, robot_name, self.warnings.append
        )
        self.settings = settings
        #: The task's own mazes (``settings.mazes``), always first in :attr:`mazes`.
        self.task_mazes: tuple[Maze, ...] = tuple(mazes)
        #: The mazes episodes run in (start rows' maze column): the task's own, then the
        #: generated ones of the current draw (:meth:`generation_episodes`).
        self.mazes: list[Maze] = list(self.task_mazes)
        #: The generated mazes drawn from (:meth:`start_training`), or None.
        self.training: TrainingMazes | None = None
        self.layout = SensorLayout.load(config_dir() / settings.sensors)
        if self.layout.motion is not None:
            try:
                self.layout.motion.cycles(dt)
            except ValueError as e:
                raise ConfigError(f"sensors: {settings.sensors}: {e}") from None
        self.dt = dt
        self.n_cycles = control_steps(settings.episode_time, dt)
        self.footprint_radius = footprint_radius
        #: Called as ``progress(done, total)`` while a batch of episodes runs, from
        #: ``(0, total)`` to ``(total, total)``, by tasks whose batches take minutes (the
        #: legged robots' PyBullet episodes); None: no reports. The 4WS kernel runs a
        #: batch in one call of seconds and does not report.
        self.progress: Callable[[int, int], None] | None = None

    @property
    def n_mazes(self) -> int:
        """Number of mazes."""
        return len(self.mazes)

    @property
    @abc.abstractmethod
    def parameter_specs(self) -> tuple[ParameterSpec, ...]:
        """The robot's locomotion parameters (a standard controller's outputs)."""

    @abc.abstractmethod
    def controller(
        self, kind: str, repertoire: Repertoire | None = None, mapping: str | None = None
    ) -> Any:
        """An EvoRBC controller (repertoire and mapping) or a standard one."""

    @abc.abstractmethod
    def evaluate(
        self, networks: list, controller: Any, starts: np.ndarray, record: bool = False, world=None
    ):
        """Every network from every start row; episode ``i * len(starts) + j``.

        ``world``: a :class:`~offline_evolution.maze_task.perturbation.WorldDraw` with one
        row per start row (perturbed worlds, docs/design.md section 21), or None.
        """

    @property
    def n_standard_outputs(self) -> int:
        """Outputs of a standard-NEAT network: one per locomotion parameter."""
        return len(self.parameter_specs)

    def sample_starts(self, rng: np.random.Generator) -> np.ndarray:
        """``(n_task_mazes * samples_per_maze, 4)`` rows ``(maze, x, y, heading)``.

        The task's own mazes (``settings.mazes``), never the generated ones.
        """
        rows = []
        for k, maze in enumerate(self.task_mazes):
            poses = maze.sample_starts(rng, self.settings.samples_per_maze, self.footprint_radius)
            rows += [(k, *p) for p in poses]
        return np.array(rows, dtype=np.float64)

    def nominal_starts(self) -> np.ndarray:
        """One row ``(maze, x, y, heading)`` per task maze at its nominal start pose."""
        return np.array([(k, *m.start_pose) for k, m in enumerate(self.task_mazes)])

    # -- training on generated mazes (docs/design.md section 22) -----------------------

    def start_training(self, robot: str, seed: int, source: str = "the task") -> None:
        """Prepare a run of seed ``seed``: refuse held-out mazes, set up generated ones.

        Args:
            robot: the registered robot the generated mazes are made for.
            source: how errors name the task (its file).

        Raises:
            ConfigError: a held-out maze or seed (:func:`~offline_evolution.maze_task.
                training.check_training`), or perturbed training for a simulation that
                takes no perturbed worlds.
        """
        check_training(self.task_mazes, self.settings.training, seed, source)
        if self.settings.training is not None:
            training = TrainingMazes(self.settings.training, robot)
            if training.perturbed and not getattr(self, "perturbations_applied", ()):
                raise ConfigError(
                    f"{source}: training: perturb {training.perturbation.name}: {robot}'s "
                    "simulation takes no perturbed worlds (use none)"
                )
            from offline_evolution.maze_task.perturbation import check_damage

            try:
                check_damage(self, training.perturbation)
            except ValueError as e:
                raise ConfigError(
                    f"{source}: training: perturb {training.perturbation.name}: {robot}: {e}"
                ) from None
            self.training = training

    def use_mazes(self, generated: list[Maze]) -> None:
        """Run episodes in the task's mazes and ``generated`` (rows ``n_task_mazes`` on)."""
        self.mazes = list(self.task_mazes) + list(generated)
        self.mazes_changed(len(self.task_mazes))

    def mazes_changed(self, unchanged: int) -> None:  # noqa: B027 - optional hook
        """Hook: :attr:`mazes` changed after its first ``unchanged`` entries (4WS: repack).

        PyBullet tasks need nothing here: their jobs carry generated mazes.
        """

    def _rows(self, rng: np.random.Generator, first: int, per_maze: int) -> list[np.ndarray]:
        """Random start rows of :attr:`mazes` from ``first`` on, ``per_maze`` in each."""
        rows = []
        for k in range(first, len(self.mazes)):
            poses = self.mazes[k].sample_starts(rng, per_maze, self.footprint_radius)
            rows.append(np.column_stack([np.full(per_maze, float(k)), poses]))
        return rows

    def generation_episodes(self, rng: np.random.Generator):
        """One generation's ``(starts (S, 4), world)``, drawn only from ``rng``.

        Without ``training``: :meth:`sample_starts` and no perturbed world (the paper's
        protocol, unchanged). With it: K generated mazes (made the current ones), the
        task's mazes' starts unless ``task_mazes`` is false, S starts in each generated
        maze, then the worlds of ``perturb`` (one per row, start errors applied) or None.
        """
        if self.training is None:
            return self.sample_starts(rng), None
        t = self.training
        self.use_mazes(t.mazes(t.training_indices(rng)))
        rows = [self.sample_starts(rng)] if t.settings.task_mazes else []
        rows += self._rows(rng, len(self.task_mazes), t.settings.starts)
        starts = np.concatenate(rows)
        if not t.perturbed:
            return starts, None
        world = t.perturbation.draw(rng, len(starts))
        return world.shift_starts(starts, self.mazes, self.footprint_radius), world

    def validation_starts(self, rng: np.random.Generator, samples: int) -> np.ndarray:
        """Post-selection rows in generated validation mazes, ``samples`` in each.

        ``(post_mazes * samples, 4)``, drawn from ``rng`` after the task mazes' rows;
        ``(0, 4)`` without ``training`` (the task's own mazes only, as the paper's).
        """
        if self.training is None or not self.training.settings.post_mazes or samples < 1:
            self.use_mazes([])
            return np.zeros((0, 4))
        t = self.training
        self.use_mazes(t.mazes(t.validation_indices(rng)))
        return np.concatenate(self._rows(rng, len(self.task_mazes), samples))

    def fitness(self, reached, cycles, final, initial) -> np.ndarray:
        """Eq. 5 for each episode."""
        return eq5_fitness(reached, cycles * self.dt, final, initial, self.settings.episode_time)

    def episode_result(
        self, reached, cycles, final, initial, traces=None, fell=None, ends=None
    ) -> EpisodeResult:
        """An :class:`EpisodeResult` with eq. 5 fitness; ``traces``: ``(pose, choice, outputs)``.

        ``ends``: ``(maze (E,) int, start (E, 2), end (E, 2))``, each episode's maze row and
        its first and last positions (m); with ``training.distance: path`` a missed
        episode's fitness uses the path lengths from them (``final`` and ``initial`` stay
        the straight-line distances the result reports). ``fell`` ``(E,)`` bool: with
        ``training.fall_penalty`` a fallen episode's fitness is lowered by it.
        """
        pose, choice, outputs = traces if traces is not None else (None, None, None)
        if ends is not None and self.training is not None and self.training.by_path:
            fitness = self.fitness(reached, cycles, *self._path_lengths(*ends))
        else:
            fitness = self.fitness(reached, cycles, final, initial)
        penalty = self.training.settings.fall_penalty if self.training is not None else 0.0
        if penalty and fell is not None:
            fitness = fitness - penalty * np.asarray(fell, dtype=np.float64)
        return EpisodeResult(reached, cycles, final, initial, fitness, pose, choice, outputs, fell)

    def _path_lengths(self, maze, start, end) -> tuple[np.ndarray, np.ndarray]:
        """``(final (E,), initial (E,))`` shortest path lengths (m) to each episode's target."""
        maze = np.asarray(maze, dtype=np.int64)
        final, initial = np.empty(len(maze)), np.empty(len(maze))
        for k in np.unique(maze):
            rows = maze == k
            to_go = self.training.path_to_go
            final[rows] = to_go(self.mazes[k], end[rows, 0], end[rows, 1])
            initial[rows] = to_go(self.mazes[k], start[rows, 0], start[rows, 1])
        return final, initial

    def describe(self) -> dict | None:
        """No simulated design to record (a kinematic robot); PyBullet tasks override it."""
        return None
