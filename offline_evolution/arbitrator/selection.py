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

from offline_evolution.arbitrator.post_scores import PostScores, score_candidates, scores_key

if TYPE_CHECKING:  # a task pulls in its simulation; the settings loader needs only RULES
    from offline_evolution.task_protocol import ArbitratorTask

#: Seed stream of the post-evaluation starts, apart from every generation's.
POST_EVALUATION_STREAM = 2**31 - 1
#: Seed stream of the finalists' further starts (``post_finalists``), apart from both.
FINAL_STREAM = 2**31 - 2
#: Seed streams of the post-evaluation's worlds (``training: post_perturb``), first round
#: and finalists', apart from the starts' so that perturbing leaves the starts drawn alike.
POST_WORLD_STREAM = 2**31 - 3
FINAL_WORLD_STREAM = 2**31 - 4

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
    # With ``post_finalists``: how many candidates ran the further starts, and how many
    # episodes each ran in all (``fitness`` and ``reached`` are then over those).
    finalists: int = 0
    final_episodes: int = 0

    def as_dict(self) -> dict:
        """Plain-data form for arbitrator files."""
        out = {
            "fitness": self.fitness,
            "reached": self.reached,
            "candidates": self.candidates,
            "episodes_per_candidate": self.episodes,
            "rule": self.rule,
            "reached_nominal": self.reached_nominal,
            "nominal_reachers": self.nominal_reachers,
        }
        if self.finalists:  # absent otherwise, so that files without finalists read as before
            out["finalists"] = self.finalists
            out["episodes_per_finalist"] = self.final_episodes
        return out


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
    return np.concatenate([task.nominal_starts(), _draws(task, rng, samples)])


def final_starts(task: ArbitratorTask, seed: int, samples: int) -> np.ndarray:
    """The finalists' further starts: ``samples`` more seeded draws, without nominal rows.

    Laid out as :func:`post_evaluation_starts`' rows after the nominal ones (the task's
    random starts, then the generated validation mazes' last), from a stream of their own
    (:data:`FINAL_STREAM`), so none repeats a start of the first round.
    """
    return _draws(task, np.random.default_rng([seed, FINAL_STREAM]), samples)


def _draws(task: ArbitratorTask, rng: np.random.Generator, samples: int) -> np.ndarray:
    """``samples`` draws of the task's random starts, then its validation mazes' rows."""
    rows = [task.sample_starts(rng) for _ in range(samples)]
    validation = getattr(task, "validation_starts", None)
    if validation is not None:
        rows.append(validation(rng, samples))
    return np.concatenate(rows) if rows else np.zeros((0, 4))


def selection_world(task: ArbitratorTask, starts: np.ndarray, seed: int, final: bool = False):
    """``(starts, world)`` of the post-evaluation: in worlds of the training's ``perturb``.

    With ``training: post_perturb: true`` each of ``starts`` (rows ``(maze, x, y,
    heading)`` of the task's current mazes, as :func:`post_evaluation_starts` or, with
    ``final``, :func:`final_starts` left them) gets its own world of the training's set,
    drawn from the run's seed on a stream of its own, its start errors applied; the
    world is a :class:`~offline_evolution.maze_task.perturbation.WorldDraw`. Otherwise
    ``(starts, None)``: the nominal world, as every run before the setting.
    """
    training = getattr(task, "training", None)
    if training is None or not training.settings.post_perturb or not training.perturbed:
        return starts, None
    stream = FINAL_WORLD_STREAM if final else POST_WORLD_STREAM
    world = training.perturbation.draw(np.random.default_rng([seed, stream]), len(starts))
    return world.shift_starts(starts, task.mazes, task.footprint_radius), world


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
    after_batch: Callable[..., None] | None = None,
    progress: Callable[[int, int], None] | None = None,
    finalists: int = 0,
    more_starts: Callable[[], tuple[np.ndarray, int]] | None = None,
    final_scores: PostScores | None = None,
    final_progress: Callable[[int, int], None] | None = None,
    world=None,
) -> PostEvaluation:
    """Score every network on ``starts`` and pick one by ``rule`` (see :data:`RULES`).

    ``starts`` begins with the task's ``nominal_rows`` nominal starts (by default one per
    maze of a maze task) and ends with ``validation`` rows in generated validation mazes,
    as :func:`post_evaluation_starts` lays them out. The networks are scored in batches
    (:func:`~offline_evolution.arbitrator.post_scores.score_candidates`: ``scores`` holds
    the rows a resumed run saved, ``after_batch`` and ``progress`` are called as there).
    Ties go to the earlier candidate (the hall lists the highest training fitness first).
    The reported ``fitness`` is the mean over every episode whatever the rule.

    With ``finalists`` > 0 and ``more_starts``, a second round: the ``finalists`` best by
    the rule run further starts, ``more_starts()`` giving ``(starts (E2, 4), validation
    rows among them)`` (:func:`final_starts`; called only then, since drawing validation
    starts changes the task's current mazes), and the rule picks among them over both
    rounds' episodes. One round's winner among many noisy candidates is the luckiest
    more often than the best (its reach is biased upwards); the second round measures the
    few that matter on more episodes (docs/design.md section 8). The finalists keep their
    hall order, so ties still go to the earlier candidate. ``final_scores`` holds that
    round's saved rows (its key is set here), ``final_progress`` reports its episodes (by
    default ``progress``), and ``after_batch`` is called with a third argument,
    ``"finalists"``, during it.

    ``world``: the worlds of ``starts`` (:func:`selection_world`), or None for the nominal
    world; ``more_starts()`` may give the finalists' worlds as a third item.
    """
    if rule not in RULES:
        raise ValueError(f"post-evaluation rule must be one of {', '.join(RULES)}, got {rule!r}")
    scores = PostScores("") if scores is None else scores
    fitness_all, reached_all = score_candidates(
        task, controller, networks, starts, scores, after_batch, progress, world=world
    )
    if nominal_rows is None:
        nominal_rows = len(task.mazes)
    all_fitness = fitness_all.mean(axis=1)
    order, nominal = _ranking(fitness_all, reached_all, rule, nominal_rows, validation)
    k, rows = int(order[0]), np.arange(len(networks))
    top = np.sort(order[: min(finalists, len(networks))])
    if len(top) and more_starts is not None:
        extra, extra_validation, *final_world = more_starts()
        final_scores = PostScores("") if final_scores is None else final_scores
        key = final_key(scores.key, top, extra)
        if final_scores.key != key:  # rows of other finalists or other starts: run again
            final_scores.key, final_scores.fitness, final_scores.reached = key, [], []
        stage = None if after_batch is None else lambda d, t: after_batch(d, t, "finalists")
        f2, r2 = score_candidates(
            task,
            controller,
            [networks[i] for i in top],
            extra,
            final_scores,
            stage,
            progress if final_progress is None else final_progress,
            world=final_world[0] if final_world else None,
        )
        fitness_all = _join(fitness_all[top], f2, validation, extra_validation)
        reached_all = _join(reached_all[top], r2, validation, extra_validation)
        validation += extra_validation
        final_order, _ = _ranking(fitness_all, reached_all, rule, nominal_rows, validation)
        k, rows = int(top[final_order[0]]), top
    chosen = int(np.flatnonzero(rows == k)[0])
    return PostEvaluation(
        k,
        float(fitness_all[chosen].mean()),
        float(reached_all[chosen].mean()),
        len(networks),
        len(starts),
        all_fitness,
        rule,
        bool(nominal[k]),
        int(nominal.sum()),
        len(top) if more_starts is not None else 0,
        fitness_all.shape[1] if more_starts is not None and len(top) else 0,
    )


def _ranking(
    fitness: np.ndarray, reached: np.ndarray, rule: str, nominal_rows: int, validation: int
) -> tuple[np.ndarray, np.ndarray]:
    """Candidates best first by ``rule``, and which reached from every nominal start.

    ``fitness`` and ``reached`` are (candidates, episodes), the nominal starts' columns
    first and the ``validation`` columns last. Returns ``(order (candidates,) int,
    nominal (candidates,) bool)``; ties go to the earlier candidate.
    """
    candidates, n = fitness.shape
    nominal = reached[:, :nominal_rows].all(axis=1)
    base = rule.removeprefix("nominal_then_")
    eligible = nominal if base != rule and nominal.any() else np.ones_like(nominal)
    score = fitness.mean(axis=1)
    if base in ("balanced", "reach") and 0 < validation < n:
        score = _two_suite_mean(fitness, validation)
    keys = [np.arange(candidates), -score]
    if base == "reach":  # the highest reach rate first, then the better fitness score
        keys.append(
            -(_two_suite_mean(reached, validation) if 0 < validation < n else reached.mean(axis=1))
        )
    return np.lexsort((*keys, ~eligible)), nominal


def _join(first: np.ndarray, second: np.ndarray, validation: int, second_validation: int):
    """Two rounds' columns of the same candidates, validation columns last: (rows, n1 + n2)."""
    a, b = first.shape[1] - validation, second.shape[1] - second_validation
    return np.concatenate([first[:, :a], second[:, :b], first[:, a:], second[:, b:]], axis=1)


def final_key(first_key: str, finalists: np.ndarray, starts: np.ndarray) -> str:
    """What the finalists' rows are of: the first round (its key), who, and the starts.

    The first round's key names its candidates and starts, and its rows decide the
    finalists; so these with the further starts name the second round's rows.
    """
    who = [{"first_round": first_key, "finalists": [int(i) for i in finalists]}]
    return scores_key(who, starts)
