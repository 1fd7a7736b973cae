"""The embedded study runner: runs as plain processes on this machine.

Each run is one ``evorbc-evolve`` process (two for EvoRBC: repertoire, then arbitrator)
with ``threads`` numba threads; ``jobs`` runs go at once. Plain processes rather than a
local Ray instance: a run already is a process with its own checkpoint, so Ray would add
its start-up time (seconds), its memory (a few hundred MB for the raylet and GCS) and an
optional dependency to every laptop run, and give nothing a process pool does not (see
docs/study.md). Ray is used when a cluster address is given (:mod:`.cluster`).
"""

from __future__ import annotations

import concurrent.futures as cf

from offline_evolution.study.progress import StudyProgress
from offline_evolution.study.run import (
    RunError,
    RunInterrupted,
    RunRecord,
    execute,
    interrupt_all,
)
from offline_evolution.study.spec import Run


class StudyInterrupted(Exception):
    """The study was stopped; unfinished runs keep their checkpoints."""


def run_local(runs: list[Run], results, jobs: int, threads: int, progress: StudyProgress) -> int:
    """Run every unfinished run, ``jobs`` at a time.

    Returns:
        The number of runs that failed (the others are finished).

    Raises:
        StudyInterrupted: after Ctrl-C/SIGTERM, once every running command has saved its
            checkpoint.
    """
    failed = 0
    interrupted = False
    with cf.ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {}
        for run in runs:
            futures[pool.submit(_one, run, results, threads, progress)] = run
        try:
            for future in cf.as_completed(futures):
                try:
                    future.result()
                except RunInterrupted:
                    interrupted = True
                except RunError as e:
                    failed += 1
                    progress.fail(futures[future], str(e))
        except KeyboardInterrupt:
            interrupted = True
            for f in futures:
                f.cancel()
            interrupt_all()
            progress.print("stopping: the running commands save their checkpoints")
            cf.wait(futures)
    if interrupted:
        raise StudyInterrupted
    return failed


def _one(run: Run, results, threads: int, progress: StudyProgress) -> RunRecord:
    progress.start(run)
    record = execute(run, results, threads)
    progress.finished(run, record.seconds, fresh=True)
    return record
