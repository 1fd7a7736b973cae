"""PyBullet evaluations spread over a Ray cluster's CPUs, within one run.

A legged robot's repertoire is hours of primitive evaluations on one machine, and its
arbitrator evolution hours of episodes (docs/design.md section 18). The process pools
(:class:`sim_bridge.legged.pool.SpawnedWorkers`) spread that work over one machine's cores;
with a cluster address (``--cluster ADDRESS`` or ``EVORBC_CLUSTER``) the same work goes to
Ray tasks on every node instead, each Ray worker process building its simulation once
(the pool's initialiser).

Results do not depend on the workers: every evaluation starts from the simulation's saved
rest state (primitives) or builds its episode from scratch, so which process runs an
item, and after what, changes nothing. A task lost with its node runs again on another
node, with the same results. Ray is optional (``pip install "evorbc[cluster]"``);
nothing imports it unless a cluster address is given.
"""

from __future__ import annotations

import os
import socket
import uuid
from collections.abc import Callable, Iterable, Iterator

#: The environment variable that names the cluster for a run's evaluations.
CLUSTER_VARIABLE = "EVORBC_CLUSTER"


class ClusterError(RuntimeError):
    """The cluster cannot be used: Ray is missing or the address does not answer."""


def cluster_address() -> str | None:
    """The cluster a run's evaluations go to (``EVORBC_CLUSTER``), or None for local."""
    return os.environ.get(CLUSTER_VARIABLE) or None


def probe(address: str) -> None:
    """Fail fast when a ``host:port`` address does not answer (Ray would retry for minutes).

    Raises:
        ClusterError: why, in a few words ("Connection refused").
    """
    host, sep, port = address.rpartition(":")
    if not sep or "://" in address or not port.isdigit():
        return  # "auto", "ray://...": Ray resolves those itself
    try:
        socket.create_connection((host, int(port)), timeout=5.0).close()
    except OSError as e:
        raise ClusterError(e.strerror or str(e)) from None


def _connect(address: str):
    """Ray, connected to ``address`` (once per process).

    Raises:
        ClusterError: one line naming the address.
    """
    try:
        import ray
    except ImportError:
        raise ClusterError(
            f"{CLUSTER_VARIABLE}={address} needs Ray: pip install 'evorbc[cluster]'"
        ) from None
    if not ray.is_initialized():
        try:
            probe(address)
            ray.init(address=address, log_to_driver=False, logging_level="ERROR")
        except (ClusterError, ConnectionError, RuntimeError, ValueError) as e:
            first = (str(e).strip().splitlines() or [type(e).__name__])[0]
            raise ClusterError(f"cluster {address}: cannot connect ({first})") from None
    return ray


#: This Ray worker process's initialised pool: the token of the executor whose
#: initialiser last ran here. Ray reuses a worker process for the tasks of one function,
#: so a simulation is built once per process and executor, not once per chunk.
_initialised: str | None = None


def _run_chunk(token: str, initializer: Callable, initargs: tuple, fn: Callable, items: list):
    """The Ray task: ``[fn(item) for item in items]`` after this process's initialiser."""
    global _initialised
    if _initialised != token:
        initializer(*initargs)
        _initialised = token
    return [fn(item) for item in items]


class ClusterExecutor:
    """An executor whose :meth:`map` runs as Ray tasks on a cluster.

    It has the subset of :class:`concurrent.futures.Executor` the evaluation pools use.

    Tasks rather than actors: a task lost with its node is retried on any CPU left, so the
    run goes on with fewer nodes, and a node that joins takes tasks at once. Each Ray
    worker process runs the pool's initialiser once (``_run_chunk``).

    Args:
        address: the Ray cluster (``host:port``, ``auto`` or ``ray://...``).
        initializer, initargs: run once in every Ray worker process that takes work, as a
            process pool runs them once per process.
        workers: chunks in flight at once (default: every CPU of the cluster).
        chunk: items per task.

    Raises:
        ClusterError: Ray is missing or the cluster does not answer.
    """

    #: Retries of a task lost with its node (or its worker process) before giving up.
    RETRIES = 5

    def __init__(
        self,
        address: str,
        initializer: Callable,
        initargs: tuple,
        workers: int | None = None,
        chunk: int = 1,
    ) -> None:
        ray = _connect(address)
        self._ray = ray
        self.workers = workers or max(1, int(ray.cluster_resources().get("CPU", 1)))
        self.chunk = max(1, chunk)
        self._token = uuid.uuid4().hex
        self._init = ray.put((initializer, initargs))  # sent to the cluster once
        self._task = ray.remote(num_cpus=1, max_retries=self.RETRIES)(_run_on_cluster)

    def map(self, fn: Callable, items: Iterable) -> Iterator:
        """``fn(item)`` for every item, computed on the cluster, yielded in order.

        As ``ProcessPoolExecutor.map``: each result comes as soon as it and every one
        before it have arrived, so a caller can count progress (a generator: the work is
        sent out on the first ``next``).
        """
        items = list(items)
        chunks = [items[i : i + self.chunk] for i in range(0, len(items), self.chunk)]
        results: dict = {}  # chunk index -> its values, until yielded
        pending: dict = {}
        k = done = 0
        # At most ``workers`` tasks in flight: a cap the user chose with --workers holds.
        while k < len(chunks) or pending:
            while k < len(chunks) and len(pending) < self.workers:
                pending[self._task.remote(self._token, self._init, fn, chunks[k])] = k
                k += 1
            ready, _ = self._ray.wait(list(pending), num_returns=1)
            for ref in ready:
                results[pending.pop(ref)] = self._ray.get(ref)
            while done in results:
                yield from results.pop(done)
                done += 1

    def shutdown(self, wait: bool = True, cancel_futures: bool = False) -> None:
        """Nothing to stop: tasks end with their chunk (the connection stays)."""


def _run_on_cluster(token: str, init, fn: Callable, items: list) -> list:
    """Unpack the initialiser (sent once, resolved by Ray) and run one chunk."""
    initializer, initargs = init
    return _run_chunk(token, initializer, initargs, fn, items)
