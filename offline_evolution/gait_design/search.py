"""The gait design search: seeded, resumable, from a settings file (docs/legged.md).

Stages, each design scored by :mod:`offline_evolution.gait_design.objective` on the same
random primitives (common random numbers, so that designs differ by design, not by luck):

1. the settings file's own design ("current");
2. a scrambled Sobol sample of the design space (``budget.sobol`` designs);
3. local refinement: each step perturbs the best design so far in the unit cube
   (Gaussian, standard deviation 0.2 shrinking to 0.03), ``budget.refine`` designs;
4. validation: the best ``budget.validate`` designs and the current one, measured again on
   fresh primitives; the best of them by this second score is chosen, so that the choice
   is not the luckiest of many noisy scores. With ``budget.trial_evaluations``, each
   grows a trial repertoire (:mod:`offline_evolution.gait_design.trial`) whose primitives,
   not random gaits, are chained for the switching measure: a repertoire's gaits are
   faster, and fall more when switched.

Every scored design is appended to a JSON checkpoint, written atomically; a rerun with
the same file, seed and budget replays it and scores only what is missing, so the result
is the same as an uninterrupted run's.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.stats import qmc

from evorbc_ros.atomic_io import atomic_write_text
from offline_evolution.checkpoint import (
    CheckpointError,
    Interrupted,
    discard_checkpoint,
    load_json_checkpoint,
    settings_mismatch,
)
from offline_evolution.gait_design.maze_needs import MazeNeeds
from offline_evolution.gait_design.objective import Budget, score
from offline_evolution.gait_design.space import DesignSpace, key
from offline_evolution.gait_design.trial import trial_repertoire
from sim_bridge.legged.gait_measures import (
    DesignMeasures,
    measure_design,
    reference_rows,
    survival,
    switching_falls,
)

KIND = "design-gait"
VERSION = 3  # 2: switching among walls over a maze episode, speed against the maze;
# 3: validation's switching on a trial repertoire


@dataclass(frozen=True)
class Scored:
    """One scored design."""

    stage: str  # current, sobol, refine or validate
    values: dict
    measures: DesignMeasures
    score: float
    seconds: float  # wall time it took (0 when read from the checkpoint)
    cpu_seconds: float = 0.0  # this process's CPU time it took

    def as_dict(self) -> dict:
        """Plain data for the checkpoint."""
        return {
            "stage": self.stage,
            "values": self.values,
            "measures": self.measures.as_dict(),
            "score": self.score,
        }


@dataclass(frozen=True)
class SearchResult:
    """What the search chose, and from what."""

    chosen: dict  # values
    chosen_search: Scored  # its score on the search's primitives
    chosen_validation: Scored  # its score on fresh primitives
    current_search: Scored
    current_validation: Scored
    best_searched: Scored  # the best design of stages 2-3 on the search's primitives
    candidates: list[Scored]


class DesignSearch:
    """One search over ``space`` (see the module docstring).

    Args:
        space: the design space of the settings file.
        text: the settings file's text (the checkpoint records its digest).
        budget, seed: what to measure and how many designs; the seed of everything random.
        needs: what the robot's mazes ask (its room, episode time, required speed).
        checkpoint: the JSON checkpoint file.
        progress: called with one line per design scored.
        should_stop: polled between designs; True saves the checkpoint and stops with
            :class:`Interrupted`.
        every: designs scored between checkpoints.

    """

    def __init__(
        self,
        space: DesignSpace,
        text: str,
        budget: Budget,
        seed: int,
        needs: MazeNeeds,
        checkpoint: Path,
        progress: Callable[[str], None] = lambda line: None,
        should_stop: Callable[[], bool] = lambda: False,
        every: int = 1,
    ) -> None:
        self.space, self.budget, self.seed, self.needs = space, budget, seed, needs
        self.room = needs.room_boxes()
        self.checkpoint = Path(checkpoint)
        self.progress, self.should_stop, self.every = progress, should_stop, every
        self.header = {
            "kind": KIND,
            "version": VERSION,
            "settings_sha256": hashlib.sha256(text.encode()).hexdigest(),
            "seed": seed,
            "budget": budget.as_dict(),
            "maze": needs.as_dict(),
        }
        n = space.settings.gait.n_parameters
        self.genes = {
            "search": np.random.default_rng([seed, 0]).uniform(-1.0, 1.0, (budget.gaits, n)),
            "validate": np.random.default_rng([seed, 1]).uniform(-1.0, 1.0, (budget.gaits, n)),
        }
        self._references: dict[tuple[str, str], np.ndarray] = {}
        self.saved: list[dict] = []
        self.done: list[Scored] = []

    # -- the checkpoint ------------------------------------------------------------

    def load(self, restart: bool) -> None:
        """Read the checkpoint (or, with ``restart``, discard it).

        Raises:
            CheckpointError: not this kind of checkpoint, or another search's.

        """
        if restart:
            discard_checkpoint(self.checkpoint, KIND, "design-gait checkpoint")
            return
        if not self.checkpoint.exists():
            return
        data = load_json_checkpoint(self.checkpoint)
        if data.get("kind") != KIND:
            raise CheckpointError(
                f"{self.checkpoint}: not a design-gait checkpoint", discardable=False
            )
        header = {k: data.get(k) for k in self.header}
        mismatch = settings_mismatch(header, self.header)
        if mismatch:
            raise CheckpointError(f"{self.checkpoint}: another search's ({mismatch})")
        candidates = data.get("candidates")
        if not isinstance(candidates, list):
            raise CheckpointError(f"{self.checkpoint}: candidates: expected a list")
        self.saved = candidates

    def _save(self) -> None:
        body = {**self.header, "candidates": [s.as_dict() for s in self.done]}
        atomic_write_text(self.checkpoint, json.dumps(body, indent=1) + "\n")

    # -- scoring ---------------------------------------------------------------------

    def _reference(self, values: dict, which: str) -> np.ndarray:
        # The reference does not depend on the design's rate: a design differing only
        # there reuses it.
        k = (key({**values, "rate_hz": 0.0}), which)
        if k not in self._references:
            genes = self.genes[which][: self.budget.accuracy]
            self._references[k] = reference_rows(self.space.design(values), genes)
        return self._references[k]

    def scored(self, stage: str, values: dict) -> Scored:
        """Score ``values`` (or read its score from the checkpoint); report and save it."""
        if self.should_stop():
            if len(self.done) > len(self.saved):
                self._save()
            raise Interrupted(len(self.done), str(self.checkpoint))
        i = len(self.done)
        which = "validate" if stage == "validate" else "search"
        if i < len(self.saved):
            entry = self.saved[i]
            if entry.get("stage") != stage or entry.get("values") != values:
                raise CheckpointError(
                    f"{self.checkpoint}: design {i + 1} differs from this search's"
                )
            try:
                measures = DesignMeasures.from_dict(entry["measures"])
            except (KeyError, TypeError):
                raise CheckpointError(f"{self.checkpoint}: design {i + 1}: bad measures") from None
            result = Scored(stage, values, measures, float(entry["score"]), 0.0)
        else:
            start, cpu = time.perf_counter(), time.process_time()
            design = self.space.design(values)
            b = self.budget
            measures = measure_design(
                design,
                self.genes[which],
                b.accuracy,
                b.episodes,
                b.episode_time,
                self.seed + (1 if which == "validate" else 0),
                self._reference(values, which),
                self.room,
                self.needs.episode_time,
            )
            if stage == "validate" and b.trial_evaluations:
                measures = self._trial_switching(design, measures)
            s = score(measures, values["rate_hz"], self.needs.required_speed)
            wall, cpu = time.perf_counter() - start, time.process_time() - cpu
            result = Scored(stage, values, measures, s, wall, cpu)
        self.done.append(result)
        if i >= len(self.saved) and len(self.done) % self.every == 0:
            self._save()
        self.progress(self._line(result))
        return result

    def _trial_switching(self, design, measures: DesignMeasures) -> DesignMeasures:
        """``measures`` with switching measured on a trial repertoire of ``design``."""
        b = self.budget
        trial = trial_repertoire(design, b.trial_evaluations, self.seed + 2)
        falls, exposure = switching_falls(
            design,
            trial.genes,
            trial.x > 0.0,
            b.trial_episodes,
            self.needs.episode_time,
            [self.seed, 3],  # a stream of its own, as the genes' (no other seed's stream)
            self.room,
        )
        return dataclasses.replace(
            measures,
            switching=survival(falls, exposure, self.needs.episode_time),
            falls=falls,
            exposure=exposure,
            trial_primitives=len(trial.genes),
            trial_reach=trial.reach,
        )

    def _line(self, r: Scored) -> str:
        v, m = r.values, r.measures
        scales = ", ".join(f"{g} x{s:.2f}" for g, s in v["scale"].items())
        error = f"{100 * m.endpoint_error:.1f} cm" if np.isfinite(m.endpoint_error) else "-"
        when = (
            f"{r.seconds:.1f} s, CPU {r.cpu_seconds:.1f} s" if r.seconds else "from the checkpoint"
        )
        trial = (
            f" among a trial repertoire's {m.trial_primitives} primitives, median "
            f"{m.trial_reach:.2f} m"
            if m.trial_primitives
            else ""
        )
        return (
            f"design {len(self.done)} ({r.stage}): gain {v['gain']:g}/s, "
            f"{v['frequency_hz']:g} Hz gait, {v['rate_hz']:g} Hz physics, ranges {scales}: "
            f"upright {m.upright:.0%}, switching {m.switching:.0%} ({m.falls} falls in "
            f"{m.exposure:.0f} s{trial}), error {error}, reach {m.reach:.2f} m, speed "
            f"{m.speed:.2f} m/s, {m.ms_per_evaluation:.0f} ms/eval -> score {r.score:.3f} "
            f"[{when}]"
        )

    # -- the search ------------------------------------------------------------------

    def run(self) -> SearchResult:
        """Run (or resume) the search; the result of :class:`SearchResult`."""
        space, b = self.space, self.budget
        current = self.scored("current", space.current())
        seen = {key(current.values): current}
        sobol = qmc.Sobol(space.dimensions, scramble=True, seed=self.seed)
        for u in sobol.random(b.sobol):
            values = space.from_unit(u)
            if key(values) not in seen:
                seen[key(values)] = self.scored("sobol", values)
        rng = np.random.default_rng([self.seed, 2])
        for r in range(b.refine):
            best = max(seen.values(), key=lambda s: s.score)
            sigma = 0.03 + 0.17 * (1.0 - r / max(b.refine - 1, 1))
            for _ in range(10):  # a design already scored is drawn again
                u = space.to_unit(best.values) + rng.normal(0.0, sigma, space.dimensions)
                values = space.from_unit(u)
                if key(values) not in seen:
                    seen[key(values)] = self.scored("refine", values)
                    break
        searched = [s for s in seen.values() if s.stage != "current"]
        ranked = sorted(seen.values(), key=lambda s: -s.score)
        finalists = [s for s in ranked if s.stage != "current"][: b.validate]
        validated = {key(current.values): self.scored("validate", current.values)}
        for s in finalists:
            validated[key(s.values)] = self.scored("validate", s.values)
        best_key = max(validated, key=lambda k: validated[k].score)  # first of equals
        return SearchResult(
            chosen=validated[best_key].values,
            chosen_search=seen[best_key],
            chosen_validation=validated[best_key],
            current_search=current,
            current_validation=validated[key(current.values)],
            best_searched=max(searched, key=lambda s: s.score) if searched else current,
            candidates=list(self.done),
        )
