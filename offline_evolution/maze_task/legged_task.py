"""The maze task for any legged robot from a URDF plus a settings file (parent side).

Settings, mazes, start poses and eq. 5 fitness are every maze task's
(:class:`~offline_evolution.maze_task.base.MazeTaskBase`); this module adds episodes in
PyBullet on worker processes (:mod:`sim_bridge.legged.episode`) for the robot its settings
file describes (``config/robots/*.yaml``, docs/legged.md), in perturbed worlds too
(docs/design.md section 21), and implements the task protocol
(:class:`~offline_evolution.task_protocol.ArbitratorTask`). The hexapod's task
(:mod:`~offline_evolution.maze_task.hexapod_task`) is this one with the hexapod. Episodes
are independent and start from a restored rest state, so results do not depend on the
number of workers or on which worker ran an episode.
"""

from __future__ import annotations

import numpy as np

from evorbc_ros.adaptation import outcome_table
from evorbc_ros.config import ConfigError
from evorbc_ros.controller_kinds import ControllerKind, controller_kind
from evorbc_ros.network import NetworkSpec
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.primitive import ParameterSpec
from offline_evolution.maze_task.base import MazeTaskBase, MazeTaskSettings, empty_traces
from offline_evolution.maze_task.perturbation import PYBULLET_LEGGED
from offline_evolution.task_protocol import EpisodeResult
from sim_bridge.damage import LEGGED_DAMAGE
from sim_bridge.legged.episode import (
    EpisodeRunner,
    LeggedAdaptation,
    LeggedController,
    LeggedWorld,
)
from sim_bridge.legged.pool import SpawnedWorkers, available_cores, ignore_sigint
from sim_bridge.legged.scanner import Scanner
from sim_bridge.legged.settings import LeggedRobotSettings, load_robot_settings

_runner: EpisodeRunner | None = None


def _init_worker(world: LeggedWorld) -> None:
    global _runner
    ignore_sigint()
    _runner = EpisodeRunner(world)


def _run(runner: EpisodeRunner, job) -> dict:
    network, controller, maze, start, record, world, adapt = job
    net = NetworkSpec.from_dict(network)
    return runner.run(net, controller, maze, start, record, world, adapt)


def _episode(job) -> dict:
    return _run(_runner, job)


class LeggedMazeTask(MazeTaskBase, SpawnedWorkers):
    """The maze task of the legged robot ``robot`` describes (its ``settings`` file).

    Args:
        settings: the maze task's settings (mazes, episode time, samples, sensors).
        robot: the legged robot, or the path of its settings file.
        workers: PyBullet worker processes (default: every core).

    Raises:
        ConfigError: naming the file: the robot's settings, or a sensor layout without
            rangefinders or whose rays no LaserScan can hold.

    """

    #: What of a perturbation set its simulation applies (docs/design.md section 21).
    perturbations_applied = PYBULLET_LEGGED
    #: The kinds of damage it applies (docs/perturbations.md).
    damage_applied = LEGGED_DAMAGE

    def __init__(
        self,
        settings: MazeTaskSettings,
        robot: LeggedRobotSettings | str,
        workers: int | None = None,
    ):
        if not isinstance(robot, LeggedRobotSettings):
            robot = load_robot_settings(robot)
        self.robot = robot
        #: The legs a damage set can hit, by foot link (docs/perturbations.md).
        self.damage_legs = tuple(robot.foot_links)
        if robot.footprint_radius is None:
            raise ConfigError(f"{robot.source}: footprint_radius: needed for the maze task")
        super().__init__(settings, robot.control_period, robot.footprint_radius, robot.name)
        if self.layout.rangefinders is None:
            raise ConfigError(f"{settings.sensors}: the {robot.name}'s laser needs rangefinders")
        try:  # here, not first in a worker, so that the error names the file
            Scanner.from_layout(self.layout.rangefinders)
        except ValueError as e:
            raise ConfigError(f"{settings.sensors}: {e}") from None
        self.world = LeggedWorld(tuple(self.mazes), self.layout, robot, self.n_cycles)
        self.workers = max(1, workers or available_cores())
        self.cluster_workers = workers
        #: EvoRBC episodes adapt with this (:meth:`adapt`), or not (None).
        self.adapting: LeggedAdaptation | None = None
        #: Per episode of the last :meth:`evaluate` while adapting: observations taken.
        self.observations: list[int] = []

    def adapting_for(self, repertoire: Repertoire, settings, expected=None) -> LeggedAdaptation:
        """What :meth:`adapt` takes for an EvoRBC controller of ``repertoire``.

        As :meth:`evorbc_ros.arbitration.Controller.enable_adaptation` builds its model:
        the recorded outcomes over the repertoire's evaluation time; ``settings``
        (:class:`~evorbc_ros.adaptation.AdaptationSettings`), ``expected`` ``(n, 3)`` or
        None (the recorded outcomes).
        """
        recorded = outcome_table(repertoire.behaviour, repertoire.heading)
        return LeggedAdaptation(recorded, float(repertoire.eval_time), settings, expected)

    def adapt(self, adapting: LeggedAdaptation | None) -> None:
        """Run EvoRBC episodes adapting onboard, each from the prior; None: not."""
        self.adapting = adapting

    def describe(self) -> dict:
        """The simulated robot, as repertoire files record it."""
        return self.robot.describe()

    @property
    def parameter_specs(self) -> tuple[ParameterSpec, ...]:
        """The robot's locomotion parameters (a standard controller's outputs)."""
        return self.robot.gait.parameter_specs()

    def controller(
        self,
        kind: ControllerKind | str,
        repertoire: Repertoire | None = None,
        mapping: str | None = None,
    ) -> LeggedController:
        """An EvoRBC controller (repertoire and mapping) or a standard one."""
        kind = controller_kind(kind)
        if kind.uses_repertoire:
            key = f"evorbc:{mapping}:{repertoire.fingerprint()}"
            return LeggedController(kind, mapping, repertoire.genes, repertoire.behaviour, key)
        return LeggedController(kind, key=kind.name)

    def evaluate(
        self,
        networks: list[NetworkSpec],
        controller: LeggedController,
        starts: np.ndarray,
        record: bool = False,
        world=None,
    ) -> EpisodeResult:
        """Every network from every start row; episode ``i * len(starts) + j``.

        ``world``: a :class:`~offline_evolution.maze_task.perturbation.WorldDraw` with one
        row per start (its start errors already applied to ``starts``), or None.
        """
        rows = [world.row(k) if world is not None else None for k in range(len(starts))]
        adapt = self.adapting if controller.kind.uses_repertoire else None
        if adapt is not None and len(adapt.recorded) != len(controller.genes):
            raise ValueError(
                f"adaptation of {len(adapt.recorded)} primitives, "
                f"controller of {len(controller.genes)}"
            )
        jobs = [
            (
                net.to_dict(),
                controller,
                self._job_maze(row[0]),
                tuple(map(float, row[1:4])),
                record,
                w,
                adapt,
            )
            for net in networks
            for row, w in zip(starts, rows, strict=True)
        ]
        results = self._map(jobs)
        self.observations = [r["observations"] for r in results] if adapt is not None else []
        reached = np.array([r["reached"] for r in results], dtype=bool)
        cycles = np.array([r["cycles"] for r in results], dtype=np.int64)
        final = np.array([r["final_distance"] for r in results])
        initial = np.array([r["initial_distance"] for r in results])
        fell = np.array([r["fell"] for r in results], dtype=bool)
        traces = _padded_traces(results, self.n_cycles) if record else None
        maze = np.tile(starts[:, 0].astype(np.int64), len(networks))
        start_xy = np.array([r["start_xy"] for r in results]).reshape(-1, 2)
        end_xy = np.array([r["end_xy"] for r in results]).reshape(-1, 2)
        ends = (maze, start_xy, end_xy)
        return self.episode_result(reached, cycles, final, initial, traces, fell, ends)

    def _job_maze(self, column: float):
        """How a job names maze ``column``: by index or, if generated, the maze itself.

        The workers hold the task's own mazes; generated ones are new every generation
        (docs/design.md section 22), so their jobs carry them.
        """
        k = int(column)
        return k if k < len(self.task_mazes) else self.mazes[k]

    def _map(self, jobs: list) -> list[dict]:
        if self.progress is not None:
            self.progress(0, len(jobs))  # before any work, so the batch is timed from here
        if self.in_process() or len(jobs) == 1:
            if self._local is None:
                self._local = EpisodeRunner(self.world)
            results = (_run(self._local, job) for job in jobs)
        else:
            results = self._pool(_init_worker, (self.world,)).map(_episode, jobs)
        if self.progress is None:
            return list(results)
        # The executors yield results in job order as they finish, so counting them as
        # they come reports the batch's progress without changing what it returns.
        out = []
        for result in results:
            out.append(result)
            self.progress(len(out), len(jobs))
        return out


def _padded_traces(results: list[dict], n_cycles: int):
    """Per-episode traces padded like the 4WS kernel's (:func:`empty_traces`)."""
    n_out = max((r["outputs"].shape[1] for r in results if r["outputs"].size), default=1)
    pose, choice, outputs = empty_traces(len(results), n_cycles, n_out)
    for e, r in enumerate(results):
        k = len(r["choice"])
        pose[e, : k + 1] = r["pose"]
        choice[e, :k] = r["choice"]
        if k:
            outputs[e, :k] = r["outputs"]
    return pose, choice, outputs


def legged_task(robot, settings: MazeTaskSettings, workers: int | None = None) -> LeggedMazeTask:
    """A legged registration's maze task (the ``legged`` family's ``task``): its model's."""
    return LeggedMazeTask(settings, str(robot.model.path()), workers=workers)


__all__ = ["LeggedMazeTask", "legged_task"]
