"""Batch MAP-Elites (paper Algorithm 1) over a simulated robot's primitives.

The loop is ask -> evaluate -> add: the emitter proposes genes, the robot executes them
for T seconds from rest, the quality metric scores the outcome, and the archive keeps the
best primitive per cell of final displacement. Runs are seeded and deterministic; they
checkpoint every few iterations and resume to exactly the result of an uninterrupted run.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import ribs

from evorbc_ros.repertoire import Repertoire
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
from sim_bridge.robots import SimulatedRobot, make_robot
from sim_bridge.robots.base import control_steps

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
    """One MAP-Elites run: archive, emitter and the iteration counter."""

    def __init__(
        self,
        settings: MapElitesSettings,
        robot: SimulatedRobot | None = None,
        workers: int | None = None,
    ):
        self.settings = settings
        self.robot = robot or make_robot(settings.robot, workers=workers)
        try:
            control_steps(settings.eval_time, self.robot.control_period)
        except ValueError as e:
            self.close()
            raise SettingError("eval_time", f"{e} (robot {self.robot.name})") from None
        self.metric = quality_metric(settings.metric)
        reach = self.robot.max_reach(settings.eval_time)
        if settings.archive == "cvt":
            self.layout = cvt_layout(reach, settings.bin_size, settings.seed)
        else:
            self.layout = grid_layout(reach, settings.bin_size)
        d = len(self.robot.parameter_specs)
        self.archive = make_archive(self.layout, d, settings.seed)
        self.emitter = make_emitter(self.archive, settings)
        self.batches_done = 0  # pieces of the initial batch count as batches
        self.evaluations = 0
        self.discarded = 0  # primitives not added: quality NaN (fell over) or out of bounds

    @property
    def iteration(self) -> int:
        """Iterations (mutant batches) completed after the initial batch."""
        return max(0, self.evaluations - self.settings.initial_batch) // self.settings.batch_size

    @property
    def finished(self) -> bool:
        """True once the initial batch and every iteration have run."""
        return self.evaluations >= self.settings.evaluations

    def step(self) -> None:
        """Run one batch: ask, evaluate, then :meth:`tell`."""
        genes = self.emitter.ask()
        self.tell(genes, self.robot.evaluate_primitives(genes, self.settings.eval_time))

    def tell(self, genes: np.ndarray, outcome) -> None:
        """Score a batch's outcome and add the primitives that count to the archive."""
        try:
            quality = self.metric(outcome)
        except ValueError as e:
            # The only metric that can refuse an outcome is circular+tilt on a robot that
            # reports no tilt: a setting that does not suit the robot.
            raise SettingError("metric", f"must suit robot {self.robot.name} ({e})") from None
        behaviour = outcome.displacement
        low, high = np.asarray(self.layout["low"]), np.asarray(self.layout["high"])
        # NaN quality: discarded by the metric (a legged robot fell over). A behaviour
        # outside the archive would be clipped into an edge cell: drop it instead.
        inside = np.all((behaviour >= low) & (behaviour < high), axis=1)
        keep = np.isfinite(quality) & inside
        self.archive.add(
            genes[keep],
            quality[keep],
            behaviour[keep],
            heading=outcome.heading[keep],
        )
        self.batches_done += 1
        self.evaluations += len(genes)
        self.discarded += int(np.sum(~keep))

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
        """The archive as a :class:`Repertoire`, primitives ordered by cell."""
        elites = elites_by_cell(self.archive)
        s = self.settings
        return Repertoire(
            robot=self.robot.name,
            parameters=self.robot.parameter_specs,
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
            },
        )

    def _simulation(self) -> dict:
        describe = getattr(self.robot, "describe", None)
        return {"simulation": describe()} if describe is not None else {}

    # -- checkpoints -------------------------------------------------------------------

    def save(self, path: str | os.PathLike) -> None:
        """Write a checkpoint of the finished batches."""
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
        }
        arrays = {k: elites[k] for k in ("solution", "objective", "measures", *EXTRA_FIELDS)}
        if "centroids" in self.layout:
            arrays["centroids"] = np.asarray(self.layout["centroids"])
        save_checkpoint(path, header, arrays)

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
        mismatch = settings_mismatch(saved, self.settings.as_dict())
        if mismatch:
            raise CheckpointError(f"{path}: was written by a different run ({mismatch})")
        check_same_robot(path, header.get("simulation"), self._simulation().get("simulation"))
        if "centroids" in self.layout and not np.array_equal(
            arrays.get("centroids"), np.asarray(self.layout["centroids"])
        ):
            # k-means is seeded, but a different BLAS or scikit-learn could still move
            # the centroids; elites filed under other cells would silently change the run.
            raise CheckpointError(f"{path}: its CVT centroids differ from this run's")
        d = len(self.robot.parameter_specs)
        problem = header_problem(header, self.settings) or arrays_problem(
            arrays, d, self.layout, header["evaluations"]
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
        return None


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
