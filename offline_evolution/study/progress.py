"""Progress of a study: runs done, running and left, and an ETA from measured run costs."""

from __future__ import annotations

import statistics
import sys
import time
from collections import defaultdict

from offline_evolution.study.spec import Run


class StudyProgress:
    """Counts runs and prints one line per change (at most every ``interval`` s otherwise).

    The ETA divides the remaining runs' expected cost by the number of runs that go at
    once. A run's expected cost is the median wall time of the finished runs of its own
    setting, else of its approach, else of every finished run; without any, no ETA is
    shown (a guess from the first, compile-heavy minutes would be wild).
    """

    def __init__(self, name: str, runs: list[Run], parallel: int, stream=None):
        self.name = name
        self.runs = {r.path: r for r in runs}
        self.parallel = max(1, parallel)
        self.stream = stream or sys.stderr  # the one in force now (a test may replace it)
        self.done: set = set()
        self.running: set = set()
        self.failed: set = set()
        self.cost: dict[str, list[float]] = defaultdict(list)  # setting id -> seconds
        self.started = time.monotonic()

    def finished(self, run: Run, seconds: float, fresh: bool) -> None:
        """``run`` is finished (``fresh``: by this invocation, else found finished)."""
        self.running.discard(run.path)
        self.done.add(run.path)
        self.cost[run.setting_id].append(seconds)
        if fresh:
            self.print(f"finished {run.path} in {seconds / 60:.1f} min")

    def start(self, run: Run) -> None:
        """``run`` has started (or resumed)."""
        self.running.add(run.path)

    def fail(self, run: Run, why: str) -> None:
        """``run`` failed; the study goes on with the others."""
        self.running.discard(run.path)
        self.failed.add(run.path)
        self.print(f"failed {run.path}: {why}")

    def expected(self, run: Run) -> float | None:
        """Expected wall seconds of ``run`` from the finished runs."""
        own = self.cost.get(run.setting_id)
        if own:
            return statistics.median(own)
        same = [
            s
            for sid, costs in self.cost.items()
            for s in costs
            if self._approach(sid) == run.approach
        ]
        if same:
            return statistics.median(same)
        every = [s for costs in self.cost.values() for s in costs]
        return statistics.median(every) if every else None

    def _approach(self, setting_id: str) -> str:
        for r in self.runs.values():
            if r.setting_id == setting_id:
                return r.approach
        return ""

    def eta(self) -> float | None:
        """Seconds until every run is finished, or None while nothing is measured."""
        left = [r for p, r in self.runs.items() if p not in self.done and p not in self.failed]
        costs = [self.expected(r) for r in left]
        if any(c is None for c in costs):
            return None
        return sum(costs) / min(self.parallel, max(1, len(left)))

    def line(self) -> str:
        """``study robot-types: 12 done, 2 running, 66 left (1 failed), eta 1 h 40 min``."""
        left = len(self.runs) - len(self.done) - len(self.running) - len(self.failed)
        text = f"study {self.name}: {len(self.done)} done, {len(self.running)} running, {left} left"
        if self.failed:
            text += f" ({len(self.failed)} failed)"
        eta = self.eta()
        if len(self.done) < len(self.runs):
            text += f", eta {format_duration(eta)}" if eta is not None else ", eta unknown yet"
        return text

    def print(self, event: str = "") -> None:
        """Print the progress line, after ``event`` if given."""
        prefix = f"{event}; " if event else ""
        print(f"{prefix}{self.line()}", file=self.stream, flush=True)


def format_duration(seconds: float) -> str:
    """``45 s``, ``12 min`` or ``3 h 05 min``."""
    if seconds < 60:
        return f"{seconds:.0f} s"
    minutes = round(seconds / 60)
    if minutes < 60:
        return f"{minutes} min"
    return f"{minutes // 60} h {minutes % 60:02d} min"
