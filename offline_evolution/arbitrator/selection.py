"""Choosing the controller to ship: a hall of fame and a post-evaluation.

During evolution every genome is scored on one random start per maze, so the highest
training fitness is partly luck. The hall of fame keeps the genomes with the highest
training fitness and the champions of the most recent generations; at the end each is
re-evaluated on many seeded starts per maze (plus each maze's nominal start) and one is
written to the arbitrator file by a rule (:data:`RULES`). The paper's figure, the highest
training fitness, is reported unchanged next to it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from offline_evolution.arbitrator.post_scores import PostScores, score_candidates

if TYPE_CHECKING:  # a task pulls in its simulation; the settings loader needs only RULES
    from offline_evolution.task_protocol import ArbitratorTask

#: Seed stream of the post-evaluation starts, apart from every generation's.
POST_EVALUATION_STREAM = 2**31 - 1

#: How the post-evaluation picks the controller to write:
#: ``mean``: the highest mean fitness over all post-evaluation episodes;
#: ``nominal_then_mean``: the highest mean among the candidates that reach the target from
#: every maze's nominal start (where a demo starts the robot), or by ``mean`` when none does;
#: ``balanced``: the highest mean of two means, over the task's own mazes' episodes and over
#: its generated validation mazes' episodes, so that neither suite outweighs the other by its
#: number of episodes (equal to ``mean`` for a task without validation mazes);
#: ``nominal_then_balanced``: ``balanced`` among the candidates that reach the target from
#: every nominal start of the task's own mazes, or ``balanced`` when none does;
#: ``reach``: the highest mean of two reach rates (shares of episodes that reach the
#: target), over the task's own mazes and over its validation mazes, ties broken by
#: ``balanced`` (without validation mazes: the share of all episodes, ties by ``mean``); the
#: shipped generalising controllers' targets are reach rates (docs/design.md section 8);
#: ``nominal_then_reach``: ``reach`` among the candidates that reach the target from every
#: nominal start, or ``reach`` when none does.
RULES = (
    "mean",
    "nominal_then_mean",
    "balanced",
    "nominal_then_balanced",
    "reach",
    "nominal_then_reach",
)


class HallOfFame:
    """Genomes kept for the post-evaluation.

    They are the top genomes by training fitness, the latest generations' champions, the
    genomes seen to reach the target from every maze's nominal start, and, when the run
    takes them, snapshots: the champion of every N-th generation, so that the
    post-evaluation can pick a genome from any part of a long run (a run that trains on
    fresh generated mazes can drift towards its fixed mazes late in the run; docs/design.md
    section 8). Genomes are
    kept as plain dicts (``neat_state.genome_to_dict``) so the hall goes into JSON
    checkpoints as it is.
    """

    def __init__(self, size: int) -> None:
        self.size = size
        self.top: list[dict] = []  # highest training fitness first, unique genome keys
        self.recent: list[dict] = []  # champions of the last ``size`` generations
        # Reached the target from every nominal start; highest "nominal_fitness" first.
        self.nominal: list[dict] = []
        self.snapshots: list[dict] = []  # every N-th generation's champion, oldest first

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

    def add_nominal(self, genome: dict) -> None:
        """Keep a genome that reached the target from every nominal start.

        ``genome`` carries its training ``fitness`` and its mean ``nominal_fitness`` over
        those starts; the ``size`` best by the latter are kept.
        """
        if any(g["key"] == genome["key"] for g in self.nominal):
            return
        ranked = sorted([*self.nominal, genome], key=lambda g: (-g["nominal_fitness"], g["key"]))
        self.nominal = ranked[: self.size]

    def snapshot(self, genome: dict) -> None:
        """Keep a generation's champion for good (``snapshot_every``)."""
        if all(g["key"] != genome["key"] for g in self.snapshots):
            self.snapshots.append(genome)

    def candidates(self) -> list[dict]:
        """Every genome in the hall once (top first, snapshots last)."""
        seen, out = set(), []
        for g in [*self.top, *self.recent, *self.nominal, *self.snapshots]:
            if g["key"] not in seen:
                seen.add(g["key"])
                out.append(g)
        return out

    def to_dict(self) -> dict:
        """Plain-data form for checkpoints."""
        out = {"size": self.size, "top": self.top, "recent": self.recent, "nominal": self.nominal}
        if self.snapshots:  # absent otherwise, so that runs without snapshots write as before
            out["snapshots"] = self.snapshots
        return out

    @classmethod
    def from_dict(cls, data: dict) -> HallOfFame:
        """Rebuild from :meth:`to_dict` (older checkpoints lack the nominal list or snapshots)."""
        hall = cls(int(data["size"]))
        hall.top = list(data["top"])
        hall.recent = list(data["recent"])
        hall.nominal = list(data.get("nominal", []))
        hall.snapshots = list(data.get("snapshots", []))
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
    rule: str = "mean"  # one of RULES
    reached_nominal: bool = False  # the chosen one reached the target from every nominal start
    nominal_reachers: int = 0  # candidates that reached it from every nominal start

    def as_dict(self) -> dict:
        """Plain-data form for arbitrator files."""
        return {
            "fitness": self.fitness,
            "reached": self.reached,
            "candidates": self.candidates,
            "episodes_per_candidate": self.episodes,
            "rule": self.rule,
            "reached_nominal": self.reached_nominal,
            "nominal_reachers": self.nominal_reachers,
        }


def _two_suite_mean(per_episode: np.ndarray, validation: int) -> np.ndarray:
    """The two suites' means weighed equally, one per candidate row: shape (candidates,).

    ``per_episode`` (candidates, episodes) ends with ``validation`` columns in validation
    mazes; the rest are the task's own mazes. Neither suite counts by its number of episodes.
    """
    n = per_episode.shape[1]
    own, held = per_episode[:, : n - validation], per_episode[:, n - validation :]
    return 0.5 * (own.mean(axis=1) + held.mean(axis=1))


def post_evaluation_starts(task: ArbitratorTask, seed: int, samples: int) -> np.ndarray:
    """The task's nominal starts, then ``samples`` seeded draws of its random starts.

    A maze task that trains on generated mazes adds ``samples`` starts in each of its
    generated validation mazes (never the held-out set; docs/design.md section 22) and
    makes them its current mazes; they are the last :func:`validation_rows` rows.
    """
    rng = np.random.default_rng([seed, POST_EVALUATION_STREAM])
    rows = [task.nominal_starts()] + [task.sample_starts(rng) for _ in range(samples)]
    validation = getattr(task, "validation_starts", None)
    if validation is not None:
        rows.append(validation(rng, samples))
    return np.concatenate(rows)


def validation_rows(task: ArbitratorTask, samples: int) -> int:
    """How many of :func:`post_evaluation_starts`' rows lie in generated validation mazes."""
    training = getattr(task, "training", None)
    if training is None or samples < 1:
        return 0
    return training.settings.post_mazes * samples


def post_evaluate(
    task: ArbitratorTask,
    controller,
    networks: list,
    starts: np.ndarray,
    rule: str = "mean",
    nominal_rows: int | None = None,
    validation: int = 0,
    scores: PostScores | None = None,
    after_batch: Callable[[int, int], None] | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> PostEvaluation:
    """Score every network on ``starts`` and pick one by ``rule`` (see :data:`RULES`).

    ``starts`` begins with the task's ``nominal_rows`` nominal starts (by default one per
    maze of a maze task) and ends with ``validation`` rows in generated validation mazes,
    as :func:`post_evaluation_starts` lays them out. The networks are scored in batches
    (:func:`~offline_evolution.arbitrator.post_scores.score_candidates`: ``scores`` holds
    the rows a resumed run saved, ``after_batch`` and ``progress`` are called as there).
    Ties go to the earlier candidate (the hall lists the highest training fitness first).
    The reported ``fitness`` is the mean over every episode whatever the rule.
    """
    if rule not in RULES:
        raise ValueError(f"post-evaluation rule must be one of {', '.join(RULES)}, got {rule!r}")
    fitness_all, reached_all = score_candidates(
        task,
        controller,
        networks,
        starts,
        PostScores("") if scores is None else scores,
        after_batch,
        progress,
    )
    if nominal_rows is None:
        nominal_rows = len(task.mazes)
    candidates, n = fitness_all.shape
    fitness = fitness_all.mean(axis=1)
    reached = reached_all.mean(axis=1)
    nominal = reached_all[:, :nominal_rows].all(axis=1)
    base = rule.removeprefix("nominal_then_")
    eligible = nominal if base != rule and nominal.any() else np.ones_like(nominal)
    score = fitness
    if base in ("balanced", "reach") and 0 < validation < n:
        score = _two_suite_mean(fitness_all, validation)
    if base == "reach":
        rate = _two_suite_mean(reached_all, validation) if 0 < validation < n else reached
        # Eligible first, then the highest reach rate, then the better fitness score; ties
        # go to the earlier candidate.
        order = np.lexsort((np.arange(candidates), -score, -rate, ~eligible))
        k = int(order[0])
    else:
        k = int(np.argmax(np.where(eligible, score, -np.inf)))
    return PostEvaluation(
        k,
        float(fitness[k]),
        float(reached[k]),
        candidates,
        n,
        fitness,
        rule,
        bool(nominal[k]),
        int(nominal.sum()),
    )
