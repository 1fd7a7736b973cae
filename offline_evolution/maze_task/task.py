"""The maze task of the kinematic robots: controllers as arrays and the compiled kernel.

The kinematic robots are the 4WS ones and the differential-drive ones.

Settings, mazes, start poses and eq. 5 fitness are every maze task's
(:mod:`offline_evolution.maze_task.base`); episodes run in one parallel compiled kernel
(:mod:`offline_evolution.maze_task.kernel`, docs/design.md section 16).
"""

from __future__ import annotations

from collections import OrderedDict
from typing import NamedTuple

import numba
import numpy as np

from evorbc_ros.controller_kinds import ControllerKind, controller_kind
from evorbc_ros.mapping import MappingFunction, PrimitiveLookup
from evorbc_ros.repertoire import Repertoire
from offline_evolution.arbitrator.compiled import NetworkPack, pack_networks
from offline_evolution.maze_task.base import (
    CONTROL_PERIOD,
    MazeTaskBase,
    MazeTaskSettings,
    empty_traces,
    eq5_fitness,
)
from offline_evolution.maze_task.kernel import (
    EVORBC,
    STANDARD,
    Adapting,
    Traces,
    WorldDraws,
    run_episodes,
)
from offline_evolution.maze_task.perturbation import KINEMATIC
from offline_evolution.maze_task.world import MazePiece, combine_pieces, maze_piece
from offline_evolution.task_protocol import EpisodeResult
from sim_bridge.damage import FOUR_WS_DAMAGE
from sim_bridge.diff_drive.robot import DiffDriveRobot
from sim_bridge.four_ws.motion import MotionLimits
from sim_bridge.four_ws.robot import FourWSRobot
from sim_bridge.sensors import compile_layout

#: A robot whose compiled motion model the episode kernel runs.
KinematicRobot = FourWSRobot | DiffDriveRobot

#: Generated mazes whose packed walls and grids a task keeps (as many as the training
#: draw keeps of the mazes themselves, :data:`offline_evolution.maze_task.training.CACHE`).
_PIECES = 512

#: Episodes handed to a worker thread at a time: small enough to balance episodes that end
#: early (target reached) against ones that run the full 120 s.
_CHUNK = 4

# Re-exported: callers and files written before the split import them from here.
__all__ = [
    "CONTROL_PERIOD",
    "ControllerArrays",
    "EpisodeResult",
    "MazeTask",
    "MazeTaskSettings",
    "eq5_fitness",
    "evorbc_controller",
    "make_task",
    "standard_controller",
]


class ControllerArrays(NamedTuple):
    """How network outputs become commands, as arrays for the kernel.

    A command has ``w`` entries, the robot's (a 4WS robot: speed and four angles, 5; a
    differential-drive robot: linear and angular speed, 2).
    """

    mode: int
    map_kind: int
    map_params: np.ndarray  # (4,) MappingFunction.params (an array: numba's parfors take no
    # tuples inside tuples)
    lookup_origin: np.ndarray  # (2,)
    lookup_cell: np.ndarray  # (2,)
    lookup_table: np.ndarray  # (nx, ny) int64
    primitive_commands: np.ndarray  # (n_primitives, w)
    gene_matrix: np.ndarray  # (n_genes, w)
    command_scale: np.ndarray  # (w,)
    # m: the speed (entry 0) goes through (speed / r) x r, as onboard via wheel rad/s; 0:
    # none (docs/design.md section 2).
    speed_wheel_radius: float


def evorbc_controller(
    repertoire: Repertoire, mapping: str, robot: KinematicRobot, grid_cells: int = 256
) -> ControllerArrays:
    """Arrays of an EvoRBC controller: mapping, lookup grid and each primitive's command."""
    fn = MappingFunction.for_behaviours(mapping, repertoire.behaviour)
    lookup = PrimitiveLookup.build(repertoire.behaviour, fn.domain(), grid_cells)
    commands = robot.commands(repertoire.genes)
    width = len(robot.command_scale)
    return ControllerArrays(
        EVORBC,
        fn.kind,
        np.array(fn.params, dtype=np.float64),
        np.array(lookup.origin),
        np.array(lookup.cell),
        lookup.table,
        np.ascontiguousarray(commands),
        np.zeros((1, width)),
        np.zeros(width),
        float(robot.speed_wheel_radius),
    )


def standard_controller(robot: KinematicRobot) -> ControllerArrays:
    """Arrays of a standard-NEAT controller: outputs are the robot's genes."""
    width = len(robot.command_scale)
    return ControllerArrays(
        STANDARD,
        0,
        np.zeros(4),
        np.zeros(2),
        np.ones(2),
        np.zeros((1, 1), dtype=np.int64),
        np.zeros((1, width)),
        np.ascontiguousarray(robot.gene_matrix, dtype=np.float64),
        np.asarray(robot.command_scale, dtype=np.float64),
        float(robot.speed_wheel_radius),
    )


class MazeTask(MazeTaskBase):
    """The maze task for one kinematic robot: mazes, sensors and the compiled kernel.

    Args:
        settings: the task.
        robot: a registered robot's name, or its simulated robot (a
            :class:`~sim_bridge.four_ws.robot.FourWSRobot` or
            :class:`~sim_bridge.diff_drive.robot.DiffDriveRobot`: their compiled motion
            model runs in the kernel).

    """

    #: What of a perturbation set its simulation applies (the kinematic model: no
    #: friction, mass or servos; docs/design.md section 21).
    perturbations_applied = KINEMATIC

    def __init__(self, settings: MazeTaskSettings, robot: str | KinematicRobot):
        if isinstance(robot, str):
            from sim_bridge.robots import make_robot

            robot = make_robot(robot)
        self.robot = robot
        #: The kinds of damage its simulation applies (docs/perturbations.md): a 4WS
        #: robot's wheels one by one; a differential drive's none.
        self.damage_applied = FOUR_WS_DAMAGE if isinstance(robot.limits, MotionLimits) else ()
        super().__init__(settings, robot.control_period, robot.footprint_radius, robot.name)
        self.sensors = compile_layout(self.layout, robot.control_period)
        # Walls a ray or the footprint can touch from a cell: sensor reach plus a step and
        # a margin (m).
        self.reach = self.sensors.reach() + 0.1
        self._pieces = [maze_piece(m, self.reach) for m in self.mazes]
        self._generated_pieces: OrderedDict[str, MazePiece] = OrderedDict()
        self.pack = combine_pieces(self._pieces)
        #: An EvoRBC controller's onboard adaptation in every episode (:meth:`adapt`), or
        #: None: the evolved choices.
        self.adapting: Adapting | None = None

    def adapt(self, adapting: Adapting | None) -> None:
        """Run EvoRBC episodes adapting, each from the prior; None: not.

        ``adapting``: :func:`~offline_evolution.maze_task.adapting.adapting` of the
        controller's repertoire.
        """
        self.adapting = adapting

    def mazes_changed(self, unchanged: int) -> None:
        """Repack for a new set of mazes: only mazes not packed before get new grids.

        The pack's arrays keep their types (only their lengths change), so the compiled
        kernel runs on it without compiling again (docs/design.md section 22).
        """
        pieces = self._pieces[:unchanged]
        for maze in self.mazes[unchanged:]:
            piece = self._generated_pieces.get(maze.name)
            if piece is None:
                piece = maze_piece(maze, self.reach)
                self._generated_pieces[maze.name] = piece
                if len(self._generated_pieces) > _PIECES:
                    self._generated_pieces.popitem(last=False)
            else:
                self._generated_pieces.move_to_end(maze.name)
            pieces.append(piece)
        self.pack = combine_pieces(pieces)

    @property
    def parameter_specs(self) -> tuple:
        """The robot's locomotion parameters (a standard controller's outputs)."""
        return self.robot.parameter_specs

    def run(
        self,
        networks: NetworkPack,
        controller: ControllerArrays,
        genomes: np.ndarray,
        starts: np.ndarray,
        record: bool = False,
        world=None,
    ) -> EpisodeResult:
        """Run every genome index in ``genomes`` from every start row in ``starts``.

        Episodes are ordered genome-major: episode ``i * len(starts) + j`` is genome
        ``genomes[i]`` from start ``j``. ``world``: a
        :class:`~offline_evolution.maze_task.perturbation.WorldDraw` with one row per start
        (its start errors already applied to ``starts``), or None for the nominal world.
        """
        genomes = np.asarray(genomes, dtype=np.int64)
        n_starts = len(starts)
        genome = np.repeat(genomes, n_starts)
        maze = np.tile(starts[:, 0].astype(np.int64), len(genomes))
        start = np.ascontiguousarray(np.tile(starts[:, 1:4], (len(genomes), 1)))
        n_ep = len(genome)
        if record:
            pose, choice, outputs = empty_traces(n_ep, self.n_cycles, networks.n_outputs)
        else:
            pose = np.zeros((1, 1, 3))
            choice = np.zeros((1, 1), dtype=np.int64)
            outputs = np.zeros((1, 1, 1))
        if world is not None:
            params = np.tile(world.kernel_arrays(self.sensors.max_range), (len(genomes), 1))
            keys = np.tile(world.keys, len(genomes))
        else:
            params, keys = np.zeros((1, 7)), np.zeros(1, dtype=np.int64)
        adapt = None
        if self.adapting is not None and controller.mode == EVORBC:
            adapt = self.adapting
            n = len(controller.primitive_commands)
            if len(adapt.recorded) != n:
                raise ValueError(
                    f"adaptation of {len(adapt.recorded)} primitives, controller of {n}"
                )
        with numba.parallel_chunksize(_CHUNK):
            reached, cycles, final, initial, end = run_episodes(
                genome,
                maze,
                start,
                self.n_cycles,
                networks,
                self.pack,
                self.sensors,
                controller,
                self.robot.limits,
                Traces(bool(record), pose, choice, outputs),
                WorldDraws(world is not None, params, keys),
                adapt,
            )
        traces = (pose, choice, outputs) if record else None
        ends = (maze, start[:, :2], end)
        return self.episode_result(reached, cycles, final, initial, traces, ends=ends)

    # -- the task protocol (offline_evolution.task_protocol) -----------------------

    def controller(
        self,
        kind: ControllerKind | str,
        repertoire: Repertoire | None = None,
        mapping: str | None = None,
    ) -> ControllerArrays:
        """An EvoRBC controller (repertoire and mapping) or a standard one."""
        kind = controller_kind(kind)
        if kind.uses_repertoire:
            return evorbc_controller(repertoire, mapping, self.robot)
        return standard_controller(self.robot)

    def evaluate(
        self,
        networks: list,
        controller: ControllerArrays,
        starts: np.ndarray,
        record: bool = False,
        world=None,
    ) -> EpisodeResult:
        """Every network (:class:`~evorbc_ros.network.NetworkSpec`) from every start row.

        Episode ``i * len(starts) + j`` is network ``i`` from start ``j``; ``world``: see
        :meth:`run`.
        """
        pack = pack_networks(networks)
        return self.run(pack, controller, np.arange(len(networks)), starts, record, world)

    def describe(self) -> dict | None:
        """The robot's design as files record it (None: the paper's 4WS body)."""
        return self.robot.describe()

    def close(self) -> None:
        """Nothing to release: the kernel runs in this process."""


def make_task(settings: MazeTaskSettings, robot: str, workers: int | None = None):
    """The maze task for ``robot``: its family's task factory (:mod:`.adapters`).

    Args:
        workers: processes that run episodes (PyBullet robots; default: every core).

    Raises:
        evorbc_ros.robots.registry.UnknownRobot: naming the known robots.
    """
    from evorbc_ros.robots.registry import lookup
    from offline_evolution.maze_task.adapters import make_task as family_task

    return family_task(lookup(robot), settings, workers)
