"""Legged primitive evaluations spread over worker processes, one PyBullet client each.

Every primitive starts from the same saved rest state and Bullet is deterministic with
``deterministicOverlappingPairs=1``, so an evaluation's outcome does not depend on which
worker ran it or what ran before: results are identical for any number of workers.

Workers are started with ``spawn`` (PyBullet clients and numba's threads do not survive a
fork) and ignore SIGINT, so Ctrl-C reaches only the parent, which decides whether to stop
after the current batch.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from sim_bridge.cluster_pool import cluster_address
from sim_bridge.legged.evaluate import evaluate_genes
from sim_bridge.legged.physics import LeggedSim

#: Primitives per task sent to a worker: large enough that the round trip (~1 ms) is
#: small against ~30 ms per primitive, small enough to balance primitives that stop early.
CHUNK = 20

_worker_sim: LeggedSim | None = None


def _init_worker(make_sim: Callable[[], LeggedSim]) -> None:
    global _worker_sim
    ignore_sigint()
    _worker_sim = make_sim()


def _work(args) -> np.ndarray:
    genes, eval_time, control_period, max_tilt = args
    return evaluate_genes(_worker_sim, genes, eval_time, control_period, max_tilt)


def available_cores() -> int:
    """CPU cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


class SpawnedWorkers:
    """A lazily started ``spawn`` process pool plus an optional in-process fallback.

    Subclasses set ``workers`` and ``_local`` (anything with ``close()``) and call
    :meth:`_pool` to get the executor the first time work is spread out.
    """

    workers: int = 1
    #: Ray actors on a cluster (None: one per cluster CPU); see :meth:`_pool`.
    cluster_workers: int | None = None
    _executor: ProcessPoolExecutor | None = None
    _local = None

    def _pool(self, initializer, initargs: tuple) -> ProcessPoolExecutor:
        """The executor, started on first use with ``initializer(*initargs)`` per worker.

        With a cluster address (``EVORBC_CLUSTER``) the workers are Ray actors on the
        cluster instead of processes here (:mod:`sim_bridge.cluster_pool`); results are
        the same either way.
        """
        address = cluster_address()
        if self._executor is None and address:
            from sim_bridge.cluster_pool import ClusterExecutor

            self._executor = ClusterExecutor(address, initializer, initargs, self.cluster_workers)
        if self._executor is None:
            self._executor = ProcessPoolExecutor(
                self.workers,
                mp_context=multiprocessing.get_context("spawn"),
                initializer=initializer,
                initargs=initargs,
            )
        return self._executor

    def in_process(self) -> bool:
        """Whether work runs here: one worker and no cluster (``EVORBC_CLUSTER``)."""
        return self.workers == 1 and not cluster_address()

    def close(self) -> None:
        """Stop the workers and the in-process simulation."""
        if self._executor is not None:
            self._executor.shutdown(wait=True, cancel_futures=True)
            self._executor = None
        if self._local is not None:
            self._local.close()
            self._local = None

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def ignore_sigint() -> None:
    """Worker initialiser step: Ctrl-C is the parent's to handle, between batches."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


class EvaluationPool(SpawnedWorkers):
    """Evaluates batches of primitives on ``workers`` processes (1: in this process).

    Args:
        make_sim: builds the simulation, once per worker; picklable (a class or a
            ``functools.partial`` of one), as it is sent to the spawned workers.
        workers: processes (default: every core).

    Use as a context manager, or call :meth:`close`.
    """

    def __init__(self, make_sim: Callable[[], LeggedSim], workers: int | None = None) -> None:
        self.make_sim = make_sim
        self.workers = max(1, workers or available_cores())
        self.cluster_workers = workers

    def evaluate(
        self, genes: np.ndarray, eval_time: float, control_period: float, max_tilt: float
    ) -> np.ndarray:
        """Outcome rows of :func:`~sim_bridge.legged.evaluate.evaluate_genes`, in order."""
        genes = np.atleast_2d(np.asarray(genes, dtype=np.float64))
        if len(genes) == 0:
            return np.empty((0, 6))
        if self.in_process():
            if self._local is None:
                self._local = self.make_sim()
            return evaluate_genes(self._local, genes, eval_time, control_period, max_tilt)
        executor = self._pool(_init_worker, (self.make_sim,))
        chunks = [
            (genes[i : i + CHUNK], eval_time, control_period, max_tilt)
            for i in range(0, len(genes), CHUNK)
        ]
        return np.concatenate(list(executor.map(_work, chunks)))
