"""The maze task: settings, controllers as arrays, episodes and eq. 5 fitness.

A controller's fitness in one episode is (paper eq. 5, docs/design.md section 4)::

    2 - t / T          if the target was reached after t seconds (T = episode_time)
    1 - d_f / d_i      otherwise (final over initial distance to the target)

and its fitness for selection is the mean over the task's episodes (one per maze by
default, new random starts each generation).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import NamedTuple

import numba
import numpy as np

from evorbc_ros.config import ConfigError, build_settings, config_dir, load_yaml_mapping, setting
from evorbc_ros.mapping import MappingFunction, PrimitiveLookup
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.sensors import SensorLayout
from offline_evolution.arbitrator.compiled import NetworkPack, pack_networks
from offline_evolution.maze_task.kernel import EVORBC, STANDARD, run_episodes
from offline_evolution.maze_task.world import pack_mazes
from sim_bridge.maze import load_named_maze
from sim_bridge.robots.base import control_steps
from sim_bridge.robots.four_ws import FourWSRobot
from sim_bridge.sensors import compile_layout

#: Episodes handed to a worker thread at a time: small enough to balance episodes that end
#: early (target reached) against ones that run the full 120 s.
_CHUNK = 4


#: s between the arbitrator's decisions, for the 4WS robots and the hexapod alike.
CONTROL_PERIOD = 0.1


@dataclass(frozen=True)
class MazeTaskSettings:
    """What defines the task (``config/tasks/*.yaml``)."""

    mazes: tuple[str, ...] = setting(doc="maze names or files")
    episode_time: float = setting(120.0, doc="episode length T (s)", minimum=0.1)
    samples_per_maze: int = setting(1, doc="random starts per maze per evaluation", minimum=1)
    sensors: str = setting("sensors/4ws.yaml", doc="sensor layout file, relative to config/")

    @classmethod
    def load(cls, path: str | os.PathLike) -> MazeTaskSettings:
        """Settings from a task file (``config/tasks/*.yaml``).

        Raises:
            ConfigError: naming the file and the key, for any bad setting (see
                :meth:`from_dict`).
        """
        return cls.from_dict(load_yaml_mapping(path), str(path))

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
        settings = build_settings(cls, values, source)
        try:
            control_steps(settings.episode_time, CONTROL_PERIOD)
        except ValueError as e:
            raise ConfigError(f"{source}: episode_time {e}") from None
        if not settings.mazes:
            raise ConfigError(f"{source}: mazes must name at least one maze")
        # The files the task refers to, checked here so that an error names this source.
        for name in settings.mazes:
            try:
                load_named_maze(name)
            except ConfigError as e:
                raise ConfigError(f"{source}: mazes: {e}") from None
        layout = config_dir() / settings.sensors
        if not layout.is_file():
            raise ConfigError(
                f"{source}: sensors: no such file {layout} (the path is relative to config/)"
            )
        try:
            SensorLayout.load(layout)
        except ConfigError as e:
            raise ConfigError(f"{source}: sensors: {e}") from None
        return settings

    def as_dict(self) -> dict:
        """Plain-data form (recorded in arbitrator files)."""
        return {
            "mazes": list(self.mazes),
            "episode_time": self.episode_time,
            "samples_per_maze": self.samples_per_maze,
            "sensors": self.sensors,
        }


class ControllerArrays(NamedTuple):
    """How network outputs become wheel commands, as arrays for the kernel."""

    mode: int
    map_kind: int
    map_params: np.ndarray  # (4,) MappingFunction.params (an array: numba's parfors take no
    # tuples inside tuples)
    lookup_origin: np.ndarray  # (2,)
    lookup_cell: np.ndarray  # (2,)
    lookup_table: np.ndarray  # (nx, ny) int64
    primitive_commands: np.ndarray  # (n_primitives, 5)
    gene_matrix: np.ndarray  # (n_genes, 5)
    command_scale: np.ndarray  # (5,)


def evorbc_controller(
    repertoire: Repertoire, mapping: str, robot: FourWSRobot, grid_cells: int = 256
) -> ControllerArrays:
    """Arrays of an EvoRBC controller: mapping, lookup grid and each primitive's command."""
    fn = MappingFunction.for_behaviours(mapping, repertoire.behaviour)
    lookup = PrimitiveLookup.build(repertoire.behaviour, fn.domain(), grid_cells)
    commands = robot.type.commands(repertoire.genes, robot.geometry)
    return ControllerArrays(
        EVORBC,
        fn.kind,
        np.array(fn.params, dtype=np.float64),
        np.array(lookup.origin),
        np.array(lookup.cell),
        lookup.table,
        np.ascontiguousarray(commands),
        np.zeros((1, 5)),
        np.zeros(5),
    )


def standard_controller(robot: FourWSRobot) -> ControllerArrays:
    """Arrays of a standard-NEAT controller: outputs are the robot's genes."""
    g = robot.geometry
    scale = np.array([g.max_speed] + [g.max_wheel_angle] * 4)
    return ControllerArrays(
        STANDARD,
        0,
        np.zeros(4),
        np.zeros(2),
        np.ones(2),
        np.zeros((1, 1), dtype=np.int64),
        np.zeros((1, 5)),
        np.ascontiguousarray(robot.type.gene_matrix),
        scale,
    )


class EpisodeResult(NamedTuple):
    """Per-episode outcome (arrays of length E) and, if recorded, traces."""

    reached: np.ndarray  # bool
    cycles: np.ndarray  # int, control cycles run (to the target, or all)
    final_distance: np.ndarray  # m
    initial_distance: np.ndarray  # m
    fitness: np.ndarray  # eq. 5
    pose: np.ndarray | None = None  # (E, n_cycles + 1, 3) x, y, heading per cycle
    choice: np.ndarray | None = None  # (E, n_cycles) primitive index (-1: standard)
    outputs: np.ndarray | None = None  # (E, n_cycles, n_outputs) network outputs
    fell: np.ndarray | None = None  # bool, the robot fell over (legged robots only)


def eq5_fitness(reached, seconds, final, initial, episode_time: float) -> np.ndarray:
    """Eq. 5 per episode: ``2 - t/T`` if reached after ``t`` s, else ``1 - d_f / d_i``."""
    with np.errstate(divide="ignore", invalid="ignore"):
        missed = np.where(initial > 0, 1.0 - final / initial, 0.0)
    return np.where(reached, 2.0 - np.asarray(seconds) / episode_time, missed)


class MazeTask:
    """The maze task for one 4WS robot: mazes, sensors and the compiled kernel."""

    def __init__(self, settings: MazeTaskSettings, robot: str):
        self.settings = settings
        self.robot = FourWSRobot(robot)
        self.mazes = [load_named_maze(name) for name in settings.mazes]
        self.layout = SensorLayout.load(config_dir() / settings.sensors)
        self.sensors = compile_layout(self.layout)
        self.dt = self.robot.control_period
        self.n_cycles = control_steps(settings.episode_time, self.dt)
        # Walls a ray or the footprint can touch from a cell: sensor reach plus a step and
        # a margin (m).
        self.pack = pack_mazes(self.mazes, reach=self.sensors.reach() + 0.1)

    @property
    def n_mazes(self) -> int:
        """Number of mazes."""
        return len(self.mazes)

    def sample_starts(self, rng: np.random.Generator) -> np.ndarray:
        """``(n_mazes * samples_per_maze, 4)`` rows ``(maze, x, y, heading)``."""
        rows = []
        for k, maze in enumerate(self.mazes):
            poses = maze.sample_starts(
                rng, self.settings.samples_per_maze, self.robot.geometry.footprint_radius
            )
            rows += [(k, *p) for p in poses]
        return np.array(rows, dtype=np.float64)

    def nominal_starts(self) -> np.ndarray:
        """One row ``(maze, x, y, heading)`` per maze at its nominal start pose."""
        return np.array([(k, *m.start_pose) for k, m in enumerate(self.mazes)])

    def run(
        self,
        networks: NetworkPack,
        controller: ControllerArrays,
        genomes: np.ndarray,
        starts: np.ndarray,
        record: bool = False,
    ) -> EpisodeResult:
        """Run every genome index in ``genomes`` from every start row in ``starts``.

        Episodes are ordered genome-major: episode ``i * len(starts) + j`` is genome
        ``genomes[i]`` from start ``j``.
        """
        genomes = np.asarray(genomes, dtype=np.int64)
        n_starts = len(starts)
        genome = np.repeat(genomes, n_starts)
        maze = np.tile(starts[:, 0].astype(np.int64), len(genomes))
        start = np.ascontiguousarray(np.tile(starts[:, 1:4], (len(genomes), 1)))
        n_ep = len(genome)
        if record:
            pose = np.full((n_ep, self.n_cycles + 1, 3), np.nan)
            choice = np.full((n_ep, self.n_cycles), -2, dtype=np.int64)
            outputs = np.full((n_ep, self.n_cycles, networks.n_outputs), np.nan)
        else:
            pose = np.zeros((1, 1, 3))
            choice = np.zeros((1, 1), dtype=np.int64)
            outputs = np.zeros((1, 1, 1))
        with numba.parallel_chunksize(_CHUNK):
            reached, cycles, final, initial = run_episodes(
                genome,
                maze,
                start,
                self.n_cycles,
                networks,
                self.pack,
                self.sensors,
                controller,
                self.robot.limits,
                record,
                pose,
                choice,
                outputs,
            )
        fitness = self.fitness(reached, cycles, final, initial)
        if not record:
            return EpisodeResult(reached, cycles, final, initial, fitness)
        return EpisodeResult(reached, cycles, final, initial, fitness, pose, choice, outputs)

    def fitness(self, reached, cycles, final, initial) -> np.ndarray:
        """Eq. 5 for each episode."""
        return eq5_fitness(reached, cycles * self.dt, final, initial, self.settings.episode_time)

    # -- the interface shared with the hexapod's task ------------------------------

    def describe(self) -> None:
        """No simulated design to record: the 4WS robots are kinematic.

        (The hexapod's task returns its geometry and physics.)
        """
        return None

    @property
    def parameter_specs(self) -> tuple:
        """The robot's locomotion parameters (a standard controller's outputs)."""
        return self.robot.parameter_specs

    @property
    def n_standard_outputs(self) -> int:
        """Outputs of a standard-NEAT network: one per locomotion parameter."""
        return self.robot.type.n_parameters

    def controller(
        self, kind: str, repertoire: Repertoire | None = None, mapping: str | None = None
    ) -> ControllerArrays:
        """An EvoRBC controller (repertoire and mapping) or a standard one."""
        if kind == "evorbc":
            return evorbc_controller(repertoire, mapping, self.robot)
        return standard_controller(self.robot)

    def evaluate(
        self,
        networks: list,
        controller: ControllerArrays,
        starts: np.ndarray,
        record: bool = False,
    ) -> EpisodeResult:
        """Every network (:class:`~evorbc_ros.network.NetworkSpec`) from every start row.

        Episode ``i * len(starts) + j`` is network ``i`` from start ``j``.
        """
        pack = pack_networks(networks)
        return self.run(pack, controller, np.arange(len(networks)), starts, record)

    def close(self) -> None:
        """Nothing to release: the kernel runs in this process."""


def make_task(settings: MazeTaskSettings, robot: str, workers: int | None = None):
    """The maze task for ``robot``: its registration's ``task`` factory.

    Args:
        workers: processes that run episodes (PyBullet robots; default: every core).

    Raises:
        evorbc_ros.robots.registry.UnknownRobot: naming the known robots.
    """
    from evorbc_ros.robots.registry import lookup

    return lookup(robot).make_task(settings, workers)
