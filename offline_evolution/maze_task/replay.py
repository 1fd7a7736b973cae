"""Replays: run one controller in the mazes, record what it did, report per maze."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.mapping import NO_PRIMITIVE
from evorbc_ros.repertoire import Repertoire
from offline_evolution.maze_task.base import NOT_RUN, MazeTaskBase
from offline_evolution.task_protocol import EpisodeResult


@dataclass(frozen=True)
class MazeOutcome:
    """What happened in one maze."""

    maze: str
    reached: bool
    time: float  # s until the target was reached or the robot fell, or the full episode
    fitness: float  # eq. 5
    final_distance: float  # m, to the target
    start: tuple[float, float, float]  # x m, y m, heading rad
    switches_per_cycle: float  # how often the chosen primitive changed (EvoRBC)
    fell: bool = False  # the robot fell over (legged robots), which ended the episode
    # Cycles with no primitive (the network's outputs were not finite): the robot stood.
    stopped_cycles: int = 0

    def as_dict(self) -> dict:
        """Plain-data form (``replay --json``)."""
        return {
            "maze": self.maze,
            "reached": self.reached,
            "time": round(self.time, 3),
            "fitness": self.fitness,
            "final_distance": self.final_distance,
            "start": list(self.start),
            "switches_per_cycle": self.switches_per_cycle,
            "fell": self.fell,
            "stopped_cycles": self.stopped_cycles,
        }


def cycles_run(result: EpisodeResult, e: int) -> int:
    """The control cycles recorded episode ``e`` ran: to the target, the fall or the end.

    A fall ends an episode although eq. 5 scores it over the whole episode (its
    ``cycles`` stays ``n_cycles``); its time is that of the cycles run, as the bridge
    reports it ("fell over after 11.7 s").
    """
    if result.fell is not None and result.fell[e]:
        return int(np.sum(result.choice[e] != NOT_RUN))
    return int(result.cycles[e])


def replay(
    arbitrator: ArbitratorFile,
    task: MazeTaskBase,
    starts: np.ndarray,
    repertoire: Repertoire | None = None,
) -> tuple[list[MazeOutcome], EpisodeResult]:
    """Run ``arbitrator`` from each ``starts`` row ``(maze, x, y, heading)``, recording.

    ``task`` is either maze task (the 4WS robots' or the hexapod's).

    Raises:
        ValueError: the network takes another number of inputs than the task's sensor
            layout gives (the episodes would read inputs that are not there).
    """
    n_net, n_task = len(arbitrator.network.input_keys), task.layout.n_inputs
    if n_net != n_task:
        raise ValueError(
            f"the arbitrator's network takes {n_net} inputs, the task's sensor layout gives "
            f"{n_task}: make the task with the arbitrator's sensors"
        )
    controller = task.controller(arbitrator.kind, repertoire, arbitrator.mapping)
    result = task.evaluate([arbitrator.network], controller, starts, record=True)
    outcomes = []
    for e, row in enumerate(starts):
        fell = bool(result.fell[e]) if result.fell is not None else False
        n = cycles_run(result, e)
        choice = result.choice[e, :n]
        switches = float(np.mean(choice[1:] != choice[:-1])) if n > 1 else 0.0
        if arbitrator.kind.uses_repertoire:
            stopped = int(np.sum(choice == NO_PRIMITIVE))
        else:  # a standard controller has no primitive index: its outputs tell
            stopped = int(np.sum(~np.all(np.isfinite(result.outputs[e, :n]), axis=1)))
        outcomes.append(
            MazeOutcome(
                maze=task.mazes[int(row[0])].name,
                reached=bool(result.reached[e]),
                time=n * task.dt,
                fitness=float(result.fitness[e]),
                final_distance=float(result.final_distance[e]),
                start=(float(row[1]), float(row[2]), float(row[3])),
                switches_per_cycle=switches if arbitrator.kind.uses_repertoire else 0.0,
                fell=fell,
                stopped_cycles=stopped,
            )
        )
    return outcomes, result


def summarise_outcomes(outcomes: list[MazeOutcome]) -> list[dict]:
    """Per-maze figures over several episodes, mazes in first-seen order.

    Each row: episodes, how many reached the target and how many fell, the mean fitness and
    the mean time (s) of the episodes that reached the target (None if none did).
    """
    by_maze: dict[str, list[MazeOutcome]] = {}
    for o in outcomes:
        by_maze.setdefault(o.maze, []).append(o)
    rows = []
    for maze, group in by_maze.items():
        times = [o.time for o in group if o.reached]
        rows.append(
            {
                "maze": maze,
                "episodes": len(group),
                "reached": sum(o.reached for o in group),
                "fell": sum(o.fell for o in group),
                "mean_fitness": float(np.mean([o.fitness for o in group])),
                "mean_time_reached": float(np.mean(times)) if times else None,
            }
        )
    return rows
