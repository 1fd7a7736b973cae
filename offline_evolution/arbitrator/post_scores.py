"""The post-evaluation's episodes in batches, kept in the checkpoint as they finish.

A legged robot's post-selection is a long run of its own: `hexapod-t90-any`'s scored
65 candidates on 52 starts of up to 90 s, 3,380 PyBullet episodes, about 14 min on two
cores. Run as one batch, an interruption lost all of it. Here the hall of fame is scored a
few candidates at a time; after each batch the caller saves the rows so far in the run's
checkpoint, and a resumed run scores only the candidates left (docs/design.md section 13).

Every episode's result depends only on its network and start, never on the batch it runs
in, so batching and resuming change nothing that is written (tested). Batches start with
one candidate and double while a batch takes under half of ``target_seconds``: a 4WS
post-evaluation, thousands of episodes a second in the batched kernel, still runs in a few
large batches; a hexapod one saves about every minute.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from offline_evolution.arbitrator.neat_state import require


def scores_key(candidates: list[dict], starts: np.ndarray, world=None) -> str:
    """What a set of post-evaluation scores is of: the candidates' genomes and the starts.

    Args:
        candidates: the hall of fame's genomes in order (``neat_state.genome_to_dict``).
        starts: (episodes, 4) the post-evaluation's starts (maze index, x m, y m, heading rad).
        world: the starts' worlds (``training: post_perturb``), or None (nominal: the key
            is the one before worlds existed). A damage set may move no start, so the
            worlds' draws are part of the key.

    Returns:
        A SHA-256 hex digest; scores saved under another key are of another post-evaluation
        (``post_samples`` or the hall changed) and are not reused.
    """
    h = hashlib.sha256(json.dumps(candidates, sort_keys=True).encode())
    starts = np.ascontiguousarray(starts, dtype=np.float64)
    h.update(repr(starts.shape).encode())
    h.update(starts.tobytes())
    if world is not None:
        h.update(np.ascontiguousarray(world.keys, dtype=np.int64).tobytes())
        for name in sorted(world.values):
            h.update(name.encode() + np.ascontiguousarray(world.values[name], float).tobytes())
    return h.hexdigest()


@dataclass
class PostScores:
    """The post-evaluation rows done so far: one per candidate, in hall order.

    ``fitness`` rows hold each episode's eq. 5 fitness, ``reached`` rows whether it reached
    the target; every row has one column per start.
    """

    key: str
    fitness: list[list[float]] = field(default_factory=list)
    reached: list[list[bool]] = field(default_factory=list)

    def to_dict(self) -> dict:
        """Plain-data form (JSON checkpoints; floats round-trip exactly)."""
        return {"key": self.key, "fitness": self.fitness, "reached": self.reached}

    @classmethod
    def from_dict(cls, data: dict, where: str = "post_scores.") -> PostScores:
        """Read :meth:`to_dict`'s form back, checking its shape and values.

        Raises:
            ValueError: rows of unequal length, non-finite fitness or non-boolean reaches
                (named by ``where``).
        """
        key = require(data, "key", str, where)
        fitness = require(data, "fitness", list, where)
        reached = require(data, "reached", list, where)
        rows = {len(r) if isinstance(r, list) else -1 for r in fitness + reached}
        if len(fitness) != len(reached) or len(rows) > 1 or -1 in rows:
            raise ValueError(f"{where}fitness and reached must be rows of equal length")
        # bool is an int subclass: true where a fitness belongs is a damaged file.
        if not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
            for row in fitness
            for v in row
        ):
            raise ValueError(f"{where}fitness must hold finite numbers")
        if not all(isinstance(v, bool) for row in reached for v in row):
            raise ValueError(f"{where}reached must hold true or false")
        return cls(key, [[float(v) for v in row] for row in fitness], [list(r) for r in reached])


def score_candidates(
    task,
    controller,
    networks: list,
    starts: np.ndarray,
    scores: PostScores,
    after_batch: Callable[[int, int], None] | None = None,
    progress: Callable[[int, int], None] | None = None,
    target_seconds: float = 60.0,
    clock: Callable[[], float] = time.perf_counter,
    world=None,
) -> tuple[np.ndarray, np.ndarray]:
    """Score the candidates ``scores`` does not hold yet, a batch at a time.

    Args:
        task: an ``ArbitratorTask``; a task with a ``progress`` attribute (the legged
            maze tasks) reports its episodes through ``progress`` meanwhile.
        controller: the task's controller for the networks.
        networks: one per candidate, in hall order.
        starts: (episodes, 4) every candidate's starts.
        scores: the rows done so far (by a run this one resumes); extended in place.
        after_batch: called as ``(candidates done, candidates)`` after each batch, when
            ``scores`` holds the batch (the run saves its checkpoint here, and may raise
            ``Interrupted`` to stop).
        progress: called as ``(done, total)`` over the episodes this call runs.
        target_seconds: s, batches grow while one takes under half of this.
        clock: s, monotonic (a parameter for tests).
        world: the starts' worlds (a ``WorldDraw``, one row per start), or None: nominal.

    Returns:
        ``(fitness, reached)``, each (candidates, episodes), float64 and bool.
    """
    n = len(starts)
    if len(scores.fitness) > len(networks) or any(len(r) != n for r in scores.fitness):
        scores.fitness.clear(), scores.reached.clear()  # not rows of these starts: run again
    total = (len(networks) - len(scores.fitness)) * n
    reports = progress is not None and hasattr(task, "progress")
    if reports:  # a task the caller gave keeps its own reporter afterwards
        before = task.progress
    size, offset = 1, 0
    try:
        while len(scores.fitness) < len(networks):
            k = len(scores.fitness)
            batch = networks[k : k + size]
            if reports:
                task.progress = _shifted(progress, offset, total)
            t0 = clock()
            if world is None:  # tasks of the caller's own take no world
                result = task.evaluate(batch, controller, starts)
            else:
                result = task.evaluate(batch, controller, starts, world=world)
            seconds = clock() - t0
            scores.fitness.extend(np.asarray(result.fitness, float).reshape(-1, n).tolist())
            scores.reached.extend(np.asarray(result.reached, bool).reshape(-1, n).tolist())
            offset += len(batch) * n
            if after_batch is not None:
                after_batch(len(scores.fitness), len(networks))
            if seconds < target_seconds / 2:
                size *= 2
    finally:
        if reports:
            task.progress = before
    return np.array(scores.fitness, dtype=np.float64), np.array(scores.reached, dtype=bool)


def _shifted(progress: Callable[[int, int], None], offset: int, total: int):
    """A batch's ``(done, batch size)`` reports as ``(offset + done, total)``.

    A batch's start is reported only for the first batch, so the whole run is timed as one.
    """

    def report(done: int, _: int) -> None:
        if done or not offset:
            progress(offset + done, total)

    return report
