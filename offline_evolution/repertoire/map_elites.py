"""Batch MAP-Elites (paper Algorithm 1): an ask/tell loop, and a simulated robot on top.

The loop is ask -> evaluate -> tell: the emitter proposes genes (:meth:`MapElites.ask`),
something executes them for T seconds from rest and scores them, and the archive keeps the
best primitive per cell of final displacement (:meth:`MapElites.tell`). The evaluation is
the caller's, on plain arrays, as in pyribs' ``Scheduler.ask``/``tell``: a simulator of
one's own or a real robot (docs/design.md section 20). :func:`generate_repertoire` is the
thin layer that evaluates with the project's simulated robots and quality metrics. Runs
are seeded and deterministic; they checkpoint every few iterations and resume to exactly
the result of an uninterrupted run.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import ribs

from evorbc_ros.config import build_settings
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.repertoire_checks import HEADING_LIMIT, QUALITY_RANGES
from evorbc_ros.robots.primitive import GENE_HIGH, GENE_LOW, ParameterSpec
from offline_evolution.checkpoint import (
    CheckpointError,
    Interrupted,
    check_same_robot,
    load_checkpoint,
    save_checkpoint,
    settings_mismatch,
)
from offline_evolution.quality import quality_metric
from offline_evolution.repertoire.archive import (
    EXTRA_FIELDS,
    cvt_layout,
    elites_by_cell,
    grid_layout,
    make_archive,
)
from offline_evolution.repertoire.checkpoint_contents import arrays_problem, header_problem
from offline_evolution.repertoire.emitter import IsoLineDDEmitter, PaperMutationEmitter
from offline_evolution.repertoire.settings import MapElitesSettings, SettingError
from sim_bridge.robots import ROBOT_NAMES, SimulatedRobot, make_robot
from sim_bridge.robots.base import PrimitiveOutcome, control_steps

CHECKPOINT_KIND = "evorbc-map-elites-checkpoint"


@dataclass(frozen=True)
class Progress:
    """A snapshot of a running MAP-Elites run, passed to the progress callback."""

    iteration: int  # batches done after the initial batch (0 = only the initial batch)
    iterations: int
    evaluations: int
    cells: int
    mean_quality: float
    qd_score: float
    elapsed: float  # s of wall time in this process
    resumed_from: int | None = None  # iteration the run resumed from, if any
    total_evaluations: int = 0  # evaluations of the whole run
    evaluations_at_start: int = 0  # evaluations already done when this process started

    @property
    def rate(self) -> float:
        """Evaluations per second in this process."""
        done = self.evaluations - self.evaluations_at_start
        return done / self.elapsed if self.elapsed > 0 else 0.0

    @property
    def eta(self) -> float:
        """Seconds of wall time left at the current rate (inf before any rate is known)."""
        rate = self.rate
        return (self.total_evaluations - self.evaluations) / rate if rate > 0 else float("inf")


class MapElites:
    """One batch MAP-Elites run (paper Algorithm 1) with an ask/tell loop on plain arrays.

    Its state is the archive, the emitter's generator and three counters: plain arrays
    and JSON, which :meth:`save` writes and :meth:`restore` reads back (section 13).

    With your own evaluation (your simulator, or a real robot), state the locomotion
    parameters and the archive's reach instead of a robot, and drive the loop::

        run = MapElites(settings, parameters=specs, max_reach=0.5)
        while not run.finished:
            genes = run.ask()                              # (n, d) in [-1, 1]
            quality, behaviour, heading = evaluate(genes)  # yours: (n,), (n, 2) m, (n,) rad
            run.tell(genes, quality, behaviour, heading)
        run.repertoire().save("mine.json")

    Without them, the run builds the simulated robot ``settings.robot`` names and
    :meth:`step` is ask, the robot's evaluation and quality metric, then tell
    (:func:`generate_repertoire` does this to the end, with checkpoints and progress).

    Args:
        settings: budget, archive, variation and seed; ``robot``, ``metric`` and
            ``eval_time`` are recorded in the repertoire (with your own evaluation,
            ``robot`` is your robot's name and ``metric`` names the quality you compute).
        robot: the simulated robot; by default the one ``settings.robot`` names.
        workers: processes that evaluate primitives (PyBullet robots).
        parameters: your robot's locomotion parameters, one per gene (own evaluation).
        max_reach: m, an upper bound on any primitive's displacement after
            ``eval_time`` (own evaluation); the archive covers ``[-max_reach,
            max_reach]^2``, widened to whole cells with one centred on the origin.

    Raises:
        SettingError: a setting does not suit the robot (eval_time), or, with your own
            evaluation, ``parameters`` or ``max_reach`` is unusable.
        ConfigError: with your own evaluation, a setting is out of range (as a settings
            file's would be).

    """

    def __init__(
        self,
        settings: MapElitesSettings,
        robot: SimulatedRobot | None = None,
        workers: int | None = None,
        *,
        parameters: Sequence[ParameterSpec] | None = None,
        max_reach: float | None = None,
    ):
        self.settings = settings
        self.robot: SimulatedRobot | None = None
        if parameters is not None or max_reach is not None:
            if robot is not None:
                raise SettingError("robot", "is not used with your own parameters and max_reach")
            _check_own_evaluation(settings, parameters, max_reach)
            self.parameters = tuple(parameters)
            self.max_reach = float(max_reach)
        else:
            self.robot = robot or make_robot(settings.robot, workers=workers)
            try:
                control_steps(settings.eval_time, self.robot.control_period)
            except ValueError as e:
                self.close()
                raise SettingError("eval_time", f"{e} (robot {self.robot.name})") from None
            self.parameters = tuple(self.robot.parameter_specs)
            self.max_reach = self.robot.max_reach(settings.eval_time)
        self.metric = quality_metric(settings.metric)
        if settings.archive == "cvt":
            self.layout = cvt_layout(self.max_reach, settings.bin_size, settings.seed)
        else:
            self.layout = grid_layout(self.max_reach, settings.bin_size)
        self._low = np.asarray(self.layout["low"])
        self._high = np.asarray(self.layout["high"])
        self.archive = make_archive(self.layout, len(self.parameters), settings.seed)
        self.emitter = make_emitter(self.archive, settings)
        self.batches_done = 0  # pieces of the initial batch count as batches
        self.evaluations = 0
        self.discarded = 0  # primitives not added: quality NaN (fell over) or out of bounds
        self.pending = 0  # genes asked for and not yet told

    @property
    def robot_name(self) -> str:
        """The robot the repertoire is for (the simulated robot's, or ``settings.robot``)."""
        return self.robot.name if self.robot is not None else self.settings.robot

    @property
    def iteration(self) -> int:
        """Iterations (mutant batches) completed after the initial batch."""
        return max(0, self.evaluations - self.settings.initial_batch) // self.settings.batch_size

    @property
    def finished(self) -> bool:
        """True once the initial batch and every iteration have run."""
        return self.evaluations >= self.settings.evaluations

    def ask(self) -> np.ndarray:
        """The next batch of genes to evaluate: ``(n, d)`` in [-1, 1], one row a primitive.

        ``n`` is at most ``settings.batch_size``: the initial batch of random genes comes
        in pieces of that size, then each batch holds mutants of the elites. Gene ``k``
        maps linearly onto parameter ``k``'s range (:meth:`ParameterSpec.to_physical`).

        Raises:
            RuntimeError: the previous batch was not told yet (its genes would be lost to
                a checkpoint, and a resumed run would differ).

        """
        if self.pending:
            raise RuntimeError(f"tell() the {self.pending} genes asked for before asking again")
        genes = self.emitter.ask()
        self.pending = len(genes)
        return genes

    def tell(
        self,
        genes: np.ndarray,
        quality: np.ndarray | PrimitiveOutcome,
        behaviour: np.ndarray | None = None,
        heading: np.ndarray | None = None,
    ) -> None:
        """Add evaluated primitives to the archive.

        A cell takes a primitive if it is empty or the quality is strictly higher than its
        elite's. A NaN quality discards the primitive (a legged robot that fell), and so
        does a behaviour outside the archive (it is dropped, not clipped into an edge cell).

        Args:
            genes: ``(n, d)`` in [-1, 1], usually the batch :meth:`ask` returned.
            quality: ``(n,)``, higher is better; or the simulated robot's
                :class:`PrimitiveOutcome`, scored with ``settings.metric``.
            behaviour: ``(n, 2)`` m, each primitive's displacement ``(x, y)`` after
                ``eval_time`` from rest, in its start frame (x forward, y left).
            heading: ``(n,)`` rad, each primitive's final heading in the same frame, any
                winding (recorded in the repertoire and drawn in its picture).

        Raises:
            ValueError: arrays of the wrong shape, genes outside [-1, 1] or not finite, a
                quality outside ``settings.metric``'s range or a heading beyond 1000 rad
                (a repertoire file could not hold them, docs/design.md section 12).
            SettingError: the metric does not suit the robot's outcome.

        """
        if isinstance(quality, PrimitiveOutcome):
            quality, behaviour, heading = self.score(quality)
        elif behaviour is None or heading is None:
            raise ValueError("tell() needs genes, quality, behaviour and heading")
        genes, quality, behaviour, heading = _told(
            genes, quality, behaviour, heading, len(self.parameters)
        )
        _check_told_values(quality, heading, self.settings.metric)
        inside = np.all((behaviour >= self._low) & (behaviour < self._high), axis=1)
        keep = np.isfinite(quality) & inside
        self.archive.add(
            genes[keep],
            quality[keep],
            behaviour[keep],
            heading=heading[keep],
        )
        self.batches_done += 1
        self.evaluations += len(genes)
        self.discarded += int(np.sum(~keep))
        self.pending = 0

    def score(self, outcome: PrimitiveOutcome) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(quality (n,), behaviour (n, 2) m, heading (n,) rad)`` of a robot's outcome."""
        try:
            quality = self.metric(outcome)
        except ValueError as e:
            # The only metric that can refuse an outcome is circular+tilt on a robot that
            # reports no tilt: a setting that does not suit the robot.
            raise SettingError("metric", f"must suit robot {self.robot_name} ({e})") from None
        return quality, outcome.displacement, outcome.heading

    def evaluate(self, genes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The simulated robot's :meth:`score` of ``genes`` ``(n, d)`` run for ``eval_time``."""
        if self.robot is None:
            raise RuntimeError("this run has no simulated robot: evaluate the genes yourself")
        return self.score(self.robot.evaluate_primitives(genes, self.settings.eval_time))

    def step(self) -> None:
        """Run one batch with the simulated robot: ask, evaluate, then :meth:`tell`."""
        genes = self.ask()
        self.tell(genes, *self.evaluate(genes))

    def close(self) -> None:
        """Release the robot's resources (worker processes of a PyBullet robot)."""
        close = getattr(self.robot, "close", None)
        if close is not None:
            close()

    def progress(
        self, elapsed: float, resumed_from: int | None = None, evaluations_at_start: int = 0
    ) -> Progress:
        """Current figures of the run."""
        q = self.archive.data("objective")
        return Progress(
            iteration=self.iteration,
            iterations=self.settings.iterations,
            evaluations=self.evaluations,
            cells=len(self.archive),
            mean_quality=float(q.mean()) if len(q) else 0.0,
            qd_score=float(q.sum()),
            elapsed=elapsed,
            resumed_from=resumed_from,
            total_evaluations=self.settings.evaluations,
            evaluations_at_start=evaluations_at_start,
        )

    def repertoire(self) -> Repertoire:
        """The archive as a :class:`Repertoire`, primitives ordered by cell.

        Raises:
            RepertoireError: the repertoire is not valid (for instance, with your own
                evaluation, ``settings.robot`` or ``settings.metric`` is not one evorbc
                knows, or the parameters do not fit that robot).

        """
        elites = elites_by_cell(self.archive)
        s = self.settings
        return Repertoire(
            robot=self.robot_name,
            parameters=self.parameters,
            genes=elites["solution"],
            behaviour=elites["measures"],
            heading=elites["heading"],
            quality=elites["objective"],
            metric=s.metric,
            eval_time=s.eval_time,
            bin_size=s.bin_size,
            seed=s.seed,
            archive=self.layout,
            algorithm={
                "name": "MAP-Elites (batch, paper Algorithm 1)",
                "initial_batch": s.initial_batch,
                "batch_size": s.batch_size,
                "iterations": s.iterations,
                "variation": s.variation,
                # only the operator that ran: its own settings
                **(
                    {"iso_sigma": s.iso_sigma, "line_sigma": s.line_sigma}
                    if s.variation == "iso_line_dd"
                    else {
                        "mutation_probability": s.mutation_probability,
                        "mutation_sigma": s.mutation_sigma,
                    }
                ),
                "evaluations": self.evaluations,
                "discarded": self.discarded,
                "library": f"pyribs {ribs.__version__}",
                **self._simulation(),
                **self._own_evaluation(),
            },
        )

    def _simulation(self) -> dict:
        describe = getattr(self.robot, "describe", None)
        design = describe() if describe is not None else None
        # A robot with nothing to record (the paper's 4WS body) adds no key: its files
        # stay as they were.
        return {"simulation": design} if design is not None else {}

    def _own_evaluation(self) -> dict:
        """What only a run with the caller's evaluation records (its stated reach)."""
        if self.robot is not None:
            return {}
        return {"evaluation": "ask/tell by the caller", "max_reach": self.max_reach}

    # -- checkpoints -------------------------------------------------------------------

    def save(self, path: str | os.PathLike) -> None:
        """Write a checkpoint of the finished batches (plain arrays and a JSON header).

        Raises:
            RuntimeError: genes were asked for and not told yet.

        """
        if self.pending:
            raise RuntimeError(f"tell() the {self.pending} genes asked for before saving")
        elites = elites_by_cell(self.archive)
        header = {
            "kind": CHECKPOINT_KIND,
            "settings": self.settings.as_dict(),
            "batches_done": self.batches_done,
            "evaluations": self.evaluations,
            "discarded": self.discarded,
            "emitter": self.emitter.get_state(),
            # The simulated robot (PyBullet robots): another design cannot resume this run.
            "simulation": self._simulation().get("simulation"),
            **self._own_design(),
        }
        arrays = {k: elites[k] for k in ("solution", "objective", "measures", *EXTRA_FIELDS)}
        if "centroids" in self.layout:
            arrays["centroids"] = np.asarray(self.layout["centroids"])
        save_checkpoint(path, header, arrays)

    def _own_design(self) -> dict:
        """The parameters and reach a run with the caller's evaluation was stated with."""
        if self.robot is not None:
            return {}
        return {"parameters": [p.as_dict() for p in self.parameters], "max_reach": self.max_reach}

    def restore(self, path: str | os.PathLike) -> None:
        """Continue from a checkpoint written by :meth:`save` for the same settings.

        Raises:
            CheckpointError: unusable file, or written for different settings.

        """
        header, arrays = load_checkpoint(path)
        if header.get("kind") != CHECKPOINT_KIND:
            raise CheckpointError(f"{path}: not a MAP-Elites checkpoint", discardable=False)
        saved = header.get("settings")
        if not isinstance(saved, dict):
            raise CheckpointError(f"{path}: not a usable checkpoint (settings missing)")
        mismatch = settings_mismatch(saved, self.settings.as_dict()) or settings_mismatch(
            {k: header.get(k) for k in self._own_design()}, self._own_design()
        )
        if mismatch:
            raise CheckpointError(f"{path}: was written by a different run ({mismatch})")
        check_same_robot(path, header.get("simulation"), self._simulation().get("simulation"))
        if "centroids" in self.layout and not np.array_equal(
            arrays.get("centroids"), np.asarray(self.layout["centroids"])
        ):
            # k-means is seeded, but a different BLAS or scikit-learn could still move
            # the centroids; elites filed under other cells would silently change the run.
            raise CheckpointError(f"{path}: its CVT centroids differ from this run's")
        problem = header_problem(header, self.settings) or arrays_problem(
            arrays, len(self.parameters), self.layout, header["evaluations"], self.settings.metric
        )
        if problem is None:
            try:
                problem = self._refill(header, arrays)
            except (KeyError, ValueError, TypeError) as e:
                problem = str(e)
        if problem:
            raise CheckpointError(f"{path}: not a usable checkpoint ({problem})")

    def _refill(self, header: dict, arrays: dict[str, np.ndarray]) -> str | None:
        """Put a checked checkpoint's elites and counters back; a problem found, or None."""
        self.archive.clear()
        n = len(arrays["objective"])
        if n:
            self.archive.add(
                arrays["solution"],
                arrays["objective"],
                arrays["measures"],
                **{k: arrays[k] for k in EXTRA_FIELDS},
            )
        if len(self.archive) != n:
            # MAP-Elites keeps one elite per cell: two in a cell were not written by a run.
            return f"{n} elites in {len(self.archive)} cells"
        self.emitter.set_state(header["emitter"])
        self.batches_done = header["batches_done"]
        self.evaluations = header["evaluations"]
        self.discarded = header["discarded"]
        self.pending = 0
        return None


def _check_own_evaluation(
    settings: MapElitesSettings, parameters: Sequence[ParameterSpec] | None, max_reach
) -> None:
    """Refuse parameters, a reach or settings that no run could use (one line each)."""
    if parameters is None or max_reach is None:
        raise SettingError("parameters", "and max_reach are both needed for your own evaluation")
    if not parameters or not all(isinstance(p, ParameterSpec) for p in parameters):
        raise SettingError("parameters", "must be one or more ParameterSpec, one per gene")
    for k, p in enumerate(parameters):
        if not (math.isfinite(p.low) and math.isfinite(p.high) and p.low < p.high):
            raise SettingError("parameters", f"[{k}] ({p.name}) needs finite low < high")
    if isinstance(max_reach, bool) or not isinstance(max_reach, (int, float)):
        raise SettingError("max_reach", f"must be a number of metres, got {max_reach!r}")
    if not (math.isfinite(max_reach) and max_reach > 0):
        raise SettingError("max_reach", f"must be a finite number of metres > 0, got {max_reach!r}")
    if not isinstance(settings.robot, str) or not settings.robot:
        raise SettingError("robot", f"must name your robot, got {settings.robot!r}")
    # Every other setting is checked as a settings file's would be; the robot is yours,
    # so any name stands in for it in the check.
    build_settings(
        type(settings), {**settings.as_dict(), "robot": ROBOT_NAMES[0]}, "MapElitesSettings"
    )


def _told(genes, quality, behaviour, heading, d: int) -> tuple[np.ndarray, ...]:
    """The arrays given to :meth:`MapElites.tell` as float64, checked against each other."""
    genes = np.asarray(genes, dtype=np.float64)
    quality = np.asarray(quality, dtype=np.float64)
    behaviour = np.asarray(behaviour, dtype=np.float64)
    heading = np.asarray(heading, dtype=np.float64)
    n = len(genes)
    expected = {"genes": (n, d), "quality": (n,), "behaviour": (n, 2), "heading": (n,)}
    for name, array in zip(expected, (genes, quality, behaviour, heading), strict=True):
        if array.shape != expected[name]:
            raise ValueError(
                f"tell(): {name} has shape {array.shape}, expected {expected[name]} "
                f"({n} primitives, {d} parameters)"
            )
    # NaN fails both comparisons, so this also refuses genes that are not finite.
    if n and not (genes.min() >= GENE_LOW and genes.max() <= GENE_HIGH):
        raise ValueError(f"tell(): genes must be finite and lie in [{GENE_LOW}, {GENE_HIGH}]")
    return genes, quality, behaviour, heading


def _check_told_values(quality: np.ndarray, heading: np.ndarray, metric: str) -> None:
    """Refuse at :meth:`MapElites.tell` what the repertoire file would refuse at the end."""
    low, high = QUALITY_RANGES[metric]
    kept = np.isfinite(quality)  # NaN discards a primitive (a legged robot that fell)
    if kept.any() and (quality[kept].min() < low or quality[kept].max() > high):
        raise ValueError(f"tell(): quality must lie in [{low:g}, {high:g}] for metric {metric}")
    if kept.any() and not np.abs(heading[kept]).max() <= HEADING_LIMIT:
        raise ValueError(f"tell(): heading must be finite and within +-{HEADING_LIMIT:g} rad")


def make_emitter(archive, settings: MapElitesSettings) -> PaperMutationEmitter:
    """The emitter for ``settings.variation``: the paper's mutation or Iso+LineDD."""
    common = {
        "initial_batch": settings.initial_batch,
        "batch_size": settings.batch_size,
        "seed": settings.seed,
    }
    if settings.variation == "iso_line_dd":
        return IsoLineDDEmitter(
            archive, iso_sigma=settings.iso_sigma, line_sigma=settings.line_sigma, **common
        )
    return PaperMutationEmitter(
        archive,
        mutation_probability=settings.mutation_probability,
        sigma=settings.mutation_sigma,
        **common,
    )


def generate_repertoire(
    settings: MapElitesSettings,
    *,
    robot: SimulatedRobot | None = None,
    checkpoint: str | os.PathLike | None = None,
    checkpoint_every: int = 100,
    checkpoint_seconds: float = 300.0,
    progress: Callable[[Progress], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
    workers: int | None = None,
    keep_checkpoint: bool = False,
) -> Repertoire:
    """Run MAP-Elites to the end and return the repertoire.

    Args:
        settings: the run's settings (Table I defaults come from ``config/``).
        robot: the simulated robot; by default the one ``settings.robot`` names.
        checkpoint: file to resume from if it exists, and to save to every
            ``checkpoint_every`` batches or ``checkpoint_seconds`` of wall time,
            whichever comes first; removed once the run finishes (unless
            ``keep_checkpoint``).
        progress: called after every batch with a :class:`Progress`.
        should_stop: polled after every batch; if it returns True the run saves its
            checkpoint and raises :class:`Interrupted`.
        workers: processes that evaluate primitives (PyBullet robots; default: every
            core). The result does not depend on it.
        keep_checkpoint: save the finished run to ``checkpoint`` and keep it, for a caller
            that removes it only once the repertoire is safely written; the same call
            then just returns the repertoire again.

    Raises:
        CheckpointError: the checkpoint exists but belongs to another run or is corrupt.
        SettingError: a setting does not suit the robot (eval_time, metric).
        Interrupted: ``should_stop`` asked to stop.

    """
    run = MapElites(settings, robot, workers=workers)
    try:
        resumed_from = None
        if checkpoint is not None and os.path.exists(checkpoint):
            run.restore(checkpoint)
            resumed_from = run.iteration
        at_start = saved = run.evaluations
        start = last_save = time.perf_counter()
        while not run.finished:
            run.step()
            now = time.perf_counter()
            if progress is not None:
                progress(run.progress(now - start, resumed_from, at_start))
            due = checkpoint is not None and (
                run.batches_done % max(1, checkpoint_every) == 0
                or now - last_save >= checkpoint_seconds
            )
            stop = should_stop is not None and should_stop() and not run.finished
            if checkpoint is not None and (due or stop) and not run.finished:
                run.save(checkpoint)
                last_save, saved = now, run.evaluations
            if stop:
                raise Interrupted(run.iteration, None if checkpoint is None else str(checkpoint))
        if checkpoint is not None and keep_checkpoint and saved != run.evaluations:
            run.save(checkpoint)
        repertoire = run.repertoire()
        if checkpoint is not None and not keep_checkpoint and os.path.exists(checkpoint):
            os.remove(checkpoint)
        return repertoire
    finally:
        run.close()


__all__ = ["Interrupted", "MapElites", "Progress", "generate_repertoire"]
