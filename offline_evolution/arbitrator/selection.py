"""Choosing the controller to ship: a hall of fame and a post-evaluation.

During evolution every genome is scored on one random start per maze, so the highest
training fitness is partly luck. The hall of fame keeps the genomes with the highest
training fitness and the champions of the most recent generations; at the end each is
re-evaluated on many seeded starts per maze (plus each maze's nominal start) and the one
with the highest mean fitness is written to the arbitrator file. The paper's figure, the
highest training fitness, is reported unchanged next to it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from offline_evolution.maze_task.task import ControllerArrays, MazeTask

#: Seed stream of the post-evaluation starts, apart from every generation's.
POST_EVALUATION_STREAM = 2**31 - 1


class HallOfFame:
    """The top genomes by training fitness plus the latest generations' champions.

    Genomes are kept as plain dicts (``neat_state.genome_to_dict``) so the hall goes into
    JSON checkpoints as it is.
    """

    def __init__(self, size: int) -> None:
        self.size = size
        self.top: list[dict] = []  # highest training fitness first, unique genome keys
        self.recent: list[dict] = []  # champions of the last ``size`` generations

    def update(self, genomes: list[dict]) -> None:
        """Offer one generation's genomes (dicts with their training fitness)."""
        ranked = sorted(genomes, key=lambda g: (-g["fitness"], g["key"]))
        if ranked:
            self.recent = ([*self.recent, ranked[0]])[-self.size :]
        keys = {g["key"] for g in self.top}
        for g in ranked[: self.size]:
            if g["key"] not in keys:
                self.top.append(g)
                keys.add(g["key"])
        self.top = sorted(self.top, key=lambda g: (-g["fitness"], g["key"]))[: self.size]

    def candidates(self) -> list[dict]:
        """Every genome in the hall once (top first)."""
        seen, out = set(), []
        for g in [*self.top, *self.recent]:
            if g["key"] not in seen:
                seen.add(g["key"])
                out.append(g)
        return out

    def to_dict(self) -> dict:
        """Plain-data form for checkpoints."""
        return {"size": self.size, "top": self.top, "recent": self.recent}

    @classmethod
    def from_dict(cls, data: dict) -> HallOfFame:
        """Rebuild from :meth:`to_dict`."""
        hall = cls(int(data["size"]))
        hall.top = list(data["top"])
        hall.recent = list(data["recent"])
        return hall


@dataclass(frozen=True)
class PostEvaluation:
    """The outcome of re-evaluating the hall of fame."""

    index: int  # of the chosen candidate
    fitness: float  # its mean eq. 5 fitness over the post-evaluation episodes
    reached: float  # share of those episodes that reached the target
    candidates: int
    episodes: int  # per candidate
    all_fitness: np.ndarray  # (candidates,)

    def as_dict(self) -> dict:
        """Plain-data form for arbitrator files."""
        return {
            "fitness": self.fitness,
            "reached": self.reached,
            "candidates": self.candidates,
            "episodes_per_candidate": self.episodes,
        }


def post_evaluation_starts(task: MazeTask, seed: int, samples: int) -> np.ndarray:
    """Each maze's nominal start plus ``samples`` seeded random starts per maze."""
    rng = np.random.default_rng([seed, POST_EVALUATION_STREAM])
    rows = [task.nominal_starts()] + [task.sample_starts(rng) for _ in range(samples)]
    return np.concatenate(rows)


def post_evaluate(
    task: MazeTask, controller: ControllerArrays, networks: list, starts: np.ndarray
) -> PostEvaluation:
    """Score every network on ``starts`` and pick the highest mean fitness.

    Ties go to the earlier candidate (the hall lists the highest training fitness first).
    """
    result = task.evaluate(networks, controller, starts)
    n = len(starts)
    fitness = result.fitness.reshape(len(networks), n).mean(axis=1)
    reached = result.reached.reshape(len(networks), n).mean(axis=1)
    k = int(np.argmax(fitness))
    return PostEvaluation(k, float(fitness[k]), float(reached[k]), len(networks), n, fitness)
