"""Reporters that print a run's progress on stderr, as ``evorbc-evolve`` shows it.

The runs print nothing themselves; the command line, a study's worker process and a
recipe attach these (docs/design.md section 15, "Progress and ETA").
"""

from __future__ import annotations

import statistics
import sys
import time
from collections import deque
from collections.abc import Callable

from offline_evolution.reporters import Reporter


class GenerationPrinter(Reporter):
    """One line per generation on stderr, with an ETA once it means something.

    The first generation a process runs also compiles the simulation kernels (seconds
    where a generation then takes a fraction of one). The ETA is the median of the last
    ten generations times those left, shown from the third generation measured on: a
    median of three or more is not thrown by one such generation, nor by a slow one later
    (the machine busy, the run paused).

    Args:
        quiet: no generation lines (the resume is still said).
        total: generations of the run (set again by :meth:`search_start`).
    """

    #: Generations measured before an ETA is shown.
    MIN_MEASURED = 3

    def __init__(self, quiet: bool, total: int = 0) -> None:
        self.quiet = quiet
        self.total = total
        self.recent: deque[float] = deque(maxlen=10)  # s per generation

    def search_start(self, settings) -> None:
        """Learn the run's generations."""
        self.total = settings.generations

    def resumed(self, done: int) -> None:
        """Say that the run resumes; even with --quiet: a log (a study's run.log) keeps it."""
        print(
            f"resuming from the checkpoint: generations 1-{done} of {self.total} are done",
            file=sys.stderr,
        )

    def generation_end(self, stats, settings) -> None:
        """Print the generation's line."""
        if self.quiet:
            return
        self.recent.append(stats.seconds)
        print(
            f"generation {stats.generation + 1:>4}/{self.total}  best {stats.best:6.3f}  "
            f"mean {stats.mean:6.3f}  best so far {stats.best_so_far:6.3f}  "
            f"species {stats.species:>2}  reached {stats.best_reached}  "
            f"{stats.seconds:5.2f} s/gen  {self.eta(stats.generation + 1)}",
            file=sys.stderr,
        )

    def eta(self, done: int) -> str:
        """``eta N.N min`` for the generations left, or ``eta --`` until it is meaningful."""
        if done >= self.total:
            return "done"
        if len(self.recent) < self.MIN_MEASURED:
            return "eta   --"
        remaining = (self.total - done) * statistics.median(self.recent)
        return f"eta {remaining / 60:5.1f} min"


class PostEvaluationPrinter(Reporter):
    """The post-evaluation's episodes as lines on stderr, round by round (``EpisodeProgress``)."""

    def __init__(self) -> None:
        self.rounds = {
            False: EpisodeProgress("post-evaluation"),
            True: EpisodeProgress("post-evaluation, finalists"),
        }

    def post_evaluation(self, done: int, total: int, finalists: bool) -> None:
        """Pass the count to that round's lines."""
        self.rounds[finalists](done, total)


class IterationPrinter(Reporter):
    """A MAP-Elites progress line on stderr at most every ``interval`` s, and the last.

    The rate and ETA leave out the first batch a process runs, which also compiles the
    simulation kernels (or starts the workers): they come from the batches after it, and
    the ETA is shown once those have run for :attr:`MIN_SECONDS` (``eta --`` before).
    """

    #: Seconds of batches after the first before the ETA is shown.
    MIN_SECONDS = 2.0

    def __init__(self, interval: float = 1.0) -> None:
        self.interval = interval
        self.last = -float("inf")
        self.announced = False
        self.after_first: tuple[float, int] | None = None  # (s, evaluations) after batch 1

    def iteration_end(self, p) -> None:
        """Print the batch's line (``p``: ``map_elites.Progress``) if it is time."""
        if p.resumed_from is not None and not self.announced:
            print(f"resuming from the checkpoint at iteration {p.resumed_from}", file=sys.stderr)
        self.announced = True
        if self.after_first is None:
            self.after_first = (p.elapsed, p.evaluations)
        now = time.perf_counter()
        if now - self.last < self.interval and p.iteration < p.iterations:
            return
        self.last = now
        rate, eta = self.rate_and_eta(p)
        speed = f"{rate / 1e3:7.0f}k eval/s" if rate >= 1e4 else f"{rate:7.1f} eval/s"
        print(
            f"iteration {p.iteration:>5}/{p.iterations}  evaluations {p.evaluations:>9,}  "
            f"primitives {p.cells:>5}  mean quality {p.mean_quality:.3f}  "
            f"QD-score {p.qd_score:8.1f}  {speed}{eta}",
            file=sys.stderr,
        )

    def rate_and_eta(self, p) -> tuple[float, str]:
        """Evaluations/s and the ETA text (empty for fast runs, done in moments).

        The rate is measured after the first batch (this process's overall rate until
        then); the ETA waits for :attr:`MIN_SECONDS` of such batches.
        """
        t0, e0 = self.after_first
        seconds, done = p.elapsed - t0, p.evaluations - e0
        rate = done / seconds if seconds > 0 and done > 0 else p.rate
        if rate >= 1e4 or p.evaluations >= p.total_evaluations:
            return rate, ""
        if seconds < self.MIN_SECONDS or done <= 0:
            return rate, "  eta   --"
        return rate, f"  eta {(p.total_evaluations - p.evaluations) / rate / 60:6.1f} min"


class EpisodePrinter(Reporter):
    """A replay's or an evaluation's episodes as lines on stderr (``EpisodeProgress``)."""

    def __init__(self, label: str) -> None:
        self.lines = EpisodeProgress(label)

    def episodes_done(self, done: int, total: int) -> None:
        """Pass the count to the lines."""
        self.lines(done, total)


class WarningPrinter(Reporter):
    """``PROG: warning: ...`` on stderr for each warning of a run."""

    def __init__(self, prog: str = "evorbc-evolve") -> None:
        self.prog = prog

    def warning(self, message: str) -> None:
        """Print it."""
        print(f"{self.prog}: warning: {message}", file=sys.stderr)


class EpisodeProgress:
    """Progress of a long batch of episodes, as lines on stderr.

    Called as ``(done, total)`` (``MazeTaskBase.progress``). Says nothing for the first
    ``every`` seconds of a batch, so a batch that runs in seconds (every 4WS one) prints
    nothing; then a line at most every ``every`` seconds and one when the batch is done:
    ``post-evaluation: 340/1785 episodes (19 %), 2.1 min, eta 8.9 min``.

    Args:
        label: what the batch is.
        every: s between lines.
        clock: s, monotonic (a parameter for tests).
        stream: where lines go (default ``sys.stderr`` at the time of the call).
    """

    def __init__(
        self,
        label: str,
        every: float = 10.0,
        clock: Callable[[], float] | None = None,
        stream=None,
    ) -> None:
        self.label = label
        self.every = every
        self.clock = clock or time.monotonic
        self.stream = stream
        self.start = 0.0
        self.last = 0.0

    def __call__(self, done: int, total: int) -> None:
        """``done`` of ``total`` episodes have finished; ``done == 0`` starts a batch."""
        now = self.clock()
        if done == 0:
            self.start = self.last = now
            return
        elapsed = now - self.start
        finished = done >= total
        if elapsed < self.every or (now - self.last < self.every and not finished):
            return
        self.last = now
        tail = "done" if finished else f"eta {elapsed / done * (total - done) / 60:.1f} min"
        print(
            f"{self.label}: {done}/{total} episodes ({100 * done // total} %), "
            f"{elapsed / 60:.1f} min, {tail}",
            file=self.stream or sys.stderr,
        )
