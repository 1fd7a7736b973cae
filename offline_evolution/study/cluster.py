"""Studies on a Ray cluster: one Ray task per run, retried from its checkpoint if lost.

Every node runs runs with the same evorbc installation and sees the results folder at the
same path (a shared filesystem, as on any cluster): a run's checkpoints live in its
folder, so a task retried on another node after its node died resumes where the lost one
last saved. A task asks for ``threads`` CPUs, the numba threads its commands use. Ray is
an optional dependency (``pip install "evorbc[cluster]"``); nothing else imports it.
"""

from __future__ import annotations

import time
from pathlib import Path

from offline_evolution.study.local import StudyInterrupted
from offline_evolution.study.progress import StudyProgress
from offline_evolution.study.run import RunError, RunInterrupted, RunRecord, execute
from offline_evolution.study.spec import Run
from sim_bridge.cluster_pool import ClusterError, probe

#: Seconds between progress lines while nothing finishes.
PROGRESS_EVERY = 60.0


def _execute_on_node(
    run: Run, results: str, threads: int, cluster: str | None
) -> tuple[float, dict]:
    """The Ray task: run or resume ``run``; returns its wall seconds and summary."""
    record: RunRecord = execute(run, Path(results), threads, cluster)
    return record.seconds, record.summary


def connect(address: str):
    """Connect to the Ray cluster at ``address``.

    Raises:
        RunError: Ray is not installed or the cluster cannot be reached (one line).
    """
    try:
        import ray
    except ImportError:
        raise RunError(
            "--address needs Ray: pip install 'evorbc[cluster]' (or ray==2.60.0)"
        ) from None
    _probe(address)
    try:
        ray.init(address=address, log_to_driver=False, logging_level="ERROR")
    except (ConnectionError, RuntimeError, ValueError) as e:
        first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        raise RunError(
            f"--address {address}: cannot connect to the Ray cluster ({first})"
        ) from None
    return ray


def _probe(address: str) -> None:
    """Fail fast when a ``host:port`` address does not answer (Ray would retry for minutes).

    Raises:
        RunError: naming the address.
    """
    try:
        probe(address)
    except ClusterError as e:
        raise RunError(f"--address {address}: cannot connect to the Ray cluster ({e})") from None


def run_on_ray(
    runs: list[Run],
    results: Path,
    address: str,
    threads: int,
    retries: int,
    progress: StudyProgress,
    spread: int | None = None,
) -> int:
    """Run every run as a Ray task on the cluster at ``address``.

    Each task asks for ``threads`` CPUs. With ``spread`` (runs at once), a PyBullet
    robot's simulations go to the whole cluster instead (``--cluster``, one Ray task per
    chunk): a run's own task then asks for no CPU, as it only waits for its chunks, and
    ``spread`` runs go at once.

    Returns:
        The number of runs that failed (their ``run.log`` says why).

    Raises:
        StudyInterrupted: after Ctrl-C, once the running tasks have saved their checkpoints.
    """
    ray = connect(address)
    try:
        capacity = spread or max(1, int(ray.cluster_resources().get("CPU", 1)) // threads)
        progress.parallel = capacity
        task = ray.remote(
            num_cpus=0 if spread else threads, max_retries=retries, retry_exceptions=False
        )(_execute_on_node)
        folder = str(results.resolve())
        cluster = address if spread else None
        # Without spread Ray queues every task by its CPUs (a node that joins takes some
        # at once); a spread run asks for none, so no more than ``spread`` are handed out.
        submitted = runs[:capacity] if spread else runs
        pending = {task.remote(run, folder, threads, cluster): run for run in submitted}
        for run in runs[:capacity]:
            progress.start(run)
        queue = list(runs[capacity:])
        failed = 0
        last = time.monotonic()
        try:
            while pending:
                ready, _ = ray.wait(list(pending), num_returns=1, timeout=PROGRESS_EVERY)
                if not ready:
                    if time.monotonic() - last >= PROGRESS_EVERY:
                        progress.print()
                        last = time.monotonic()
                    continue
                ref = ready[0]
                run = pending.pop(ref)
                if queue:  # Ray starts the next queued task in the freed slot
                    nxt = queue.pop(0)
                    progress.start(nxt)
                    if spread:
                        pending[task.remote(nxt, folder, threads, cluster)] = nxt
                try:
                    seconds, _ = ray.get(ref)
                    progress.finished(run, seconds, fresh=True)
                except ray.exceptions.RayTaskError as e:
                    cause = e.cause if isinstance(e.cause, Exception) else e
                    if isinstance(cause, RunInterrupted):
                        raise KeyboardInterrupt from None
                    failed += 1
                    progress.fail(run, str(cause).strip().splitlines()[-1])
                except ray.exceptions.RayError as e:  # lost more often than --retries
                    failed += 1
                    progress.fail(run, f"lost ({type(e).__name__}) after {retries} retries")
                last = time.monotonic()
        except KeyboardInterrupt:
            progress.print("stopping: the running runs save their checkpoints")
            for ref in pending:
                ray.cancel(ref)  # KeyboardInterrupt in the task: its command checkpoints
            ray.wait(list(pending), num_returns=len(pending), timeout=120)
            raise StudyInterrupted from None
        return failed
    finally:
        ray.shutdown()
