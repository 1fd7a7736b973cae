"""The maze task for the hexapod: episodes in PyBullet on worker processes (parent side).

Settings, mazes, start poses and eq. 5 fitness are every maze task's
(:class:`~offline_evolution.maze_task.base.MazeTaskBase`); this module adds episodes in
PyBullet (:mod:`~offline_evolution.maze_task.hexapod_episode`) and implements the task
protocol (:class:`~offline_evolution.task_protocol.ArbitratorTask`). Episodes are
independent and start from a restored rest state, so results do not depend on the number
of workers or on which worker ran an episode.
"""

from __future__ import annotations

import numpy as np

from evorbc_ros.config import ConfigError
from evorbc_ros.network import NetworkSpec
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.hexapod import HexapodGeometry, parameter_specs
from evorbc_ros.robots.primitive import ParameterSpec
from offline_evolution.maze_task.base import MazeTaskBase, MazeTaskSettings, empty_traces
from offline_evolution.maze_task.hexapod_episode import (
    EpisodeRunner,
    HexapodController,
    HexapodWorld,
)
from offline_evolution.task_protocol import EpisodeResult
from sim_bridge.hexapod.physics import PhysicsSettings
from sim_bridge.hexapod.pool import SpawnedWorkers, available_cores, ignore_sigint
from sim_bridge.hexapod.scanner import Scanner
from sim_bridge.robots.hexapod import describe_simulation

_runner: EpisodeRunner | None = None


def _init_worker(world: HexapodWorld) -> None:
    global _runner
    ignore_sigint()
    _runner = EpisodeRunner(world)


def _run(runner: EpisodeRunner, job) -> dict:
    network, controller, maze, start, record, world = job
    return runner.run(NetworkSpec.from_dict(network), controller, maze, start, record, world)


def _episode(job) -> dict:
    return _run(_runner, job)


class HexapodMazeTask(MazeTaskBase, SpawnedWorkers):
    """The maze task for the hexapod (``config/tasks/maze-hexapod.yaml``)."""

    #: Its simulation's kind, for what a perturbation set can change (docs/design.md
    #: section 21).
    perturbation_family = "pybullet-legged"

    def __init__(
        self,
        settings: MazeTaskSettings,
        workers: int | None = None,
        geometry: HexapodGeometry | None = None,
        physics: PhysicsSettings | None = None,
    ):
        self.geometry = geometry or HexapodGeometry()
        self.physics = physics or PhysicsSettings()
        super().__init__(settings, self.geometry.control_period, self.geometry.footprint_radius)
        if self.layout.rangefinders is None:
            raise ConfigError(f"{settings.sensors}: the hexapod's laser needs rangefinders")
        try:  # here, not first in a worker, so that the error names the file
            Scanner.from_layout(self.layout.rangefinders)
        except ValueError as e:
            raise ConfigError(f"{settings.sensors}: {e}") from None
        self.world = HexapodWorld(
            tuple(self.mazes), self.layout, self.geometry, self.physics, self.n_cycles
        )
        self.workers = max(1, workers or available_cores())
        self.cluster_workers = workers

    def describe(self) -> dict:
        """The simulated robot (geometry and physics), as repertoire files record it."""
        return describe_simulation(self.geometry, self.physics)

    @property
    def parameter_specs(self) -> tuple[ParameterSpec, ...]:
        """The robot's locomotion parameters (a standard controller's outputs, 37)."""
        return parameter_specs()

    #: The controller, episode runner and worker functions of this task's episodes.
    controller_type = HexapodController
    runner_type = EpisodeRunner
    worker_init = staticmethod(_init_worker)
    worker_episode = staticmethod(_episode)

    def controller(
        self, kind: str, repertoire: Repertoire | None = None, mapping: str | None = None
    ) -> HexapodController:
        """An EvoRBC controller (repertoire and mapping) or a standard one."""
        make = self.controller_type
        if kind == "evorbc":
            key = f"evorbc:{mapping}:{repertoire.fingerprint()}"
            return make("evorbc", mapping, repertoire.genes, repertoire.behaviour, key)
        return make("standard", key="standard")

    def evaluate(
        self,
        networks: list[NetworkSpec],
        controller: HexapodController,
        starts: np.ndarray,
        record: bool = False,
        world=None,
    ) -> EpisodeResult:
        """Every network from every start row; episode ``i * len(starts) + j``.

        ``world``: a :class:`~offline_evolution.maze_task.perturbation.WorldDraw` with one
        row per start (its start errors already applied to ``starts``), or None.
        """
        rows = [world.row(k) if world is not None else None for k in range(len(starts))]
        jobs = [
            (
                net.to_dict(),
                controller,
                self._job_maze(row[0]),
                tuple(map(float, row[1:4])),
                record,
                w,
            )
            for net in networks
            for row, w in zip(starts, rows, strict=True)
        ]
        results = self._map(jobs)
        reached = np.array([r["reached"] for r in results], dtype=bool)
        cycles = np.array([r["cycles"] for r in results], dtype=np.int64)
        final = np.array([r["final_distance"] for r in results])
        initial = np.array([r["initial_distance"] for r in results])
        fell = np.array([r["fell"] for r in results], dtype=bool)
        traces = _padded_traces(results, self.n_cycles) if record else None
        return self.episode_result(reached, cycles, final, initial, traces, fell)

    def _job_maze(self, column: float):
        """How a job names maze ``column``: by index or, if generated, the maze itself.

        The workers hold the task's own mazes; generated ones are new every generation
        (docs/design.md section 22), so their jobs carry them.
        """
        k = int(column)
        return k if k < len(self.task_mazes) else self.mazes[k]

    def _map(self, jobs: list) -> list[dict]:
        if self.in_process() or len(jobs) == 1:
            if self._local is None:
                self._local = self.runner_type(self.world)
            return [_run(self._local, job) for job in jobs]
        return list(self._pool(self.worker_init, (self.world,)).map(self.worker_episode, jobs))


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
