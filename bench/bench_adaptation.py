"""Benchmark: onboard adaptation's cost per control cycle (docs/design.md section 24).

Drives :class:`~evorbc_ros.adaptation.online.OnlineAdaptation` (the work the controller
adds per cycle when adapting: the pose, the settled-cycle rule, an observation's refit when
one is due, and the match of the mapping's point against the corrected outcomes) through
``--cycles`` cycles, for synthetic repertoires of 100, 1,000 and 10,000 primitives (outcomes
uniform over a 0.36 m disc and +-3 rad, the shape of a 4WS repertoire) and for the largest
shipped repertoire, and prints p50 and p99 of the cost per cycle in ms, in two regimes:

* ``driving``: each primitive held a random 1-12 cycles (the shipped 4ws-5 controller
  switches in 71 % of its cycles, docs/design/adaptation.md), odometry moving as the
  primitive's settled arc, default settings (an observation per 5 settled cycles at most);
* ``worst``: every cycle takes an observation of a primitive not yet in the full ring of
  32 (a new kernel row, the 32 x 32 solve, every primitive's correction), then matches.

Each regime runs with the wheeled default settings and with the legged default
(``LEGGED_SETTINGS``: whole executions of at least 5 held cycles observed, a running mean
of up to 10 observations a primitive, docs/design/adaptation.md).

Both with the plain functions (numpy, as onboard) and the numba-compiled ones (as the
offline kernels would call them). One core: the process is pinned to one CPU and BLAS and
numba use one thread. Times are the thread's CPU time (``time.thread_time``), not wall
time: on a shared machine wall time counts the other processes' time slices.

    python bench/bench_adaptation.py [--cycles 2000] [--seed 1]
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse
import itertools
import math
import time

import numpy as np
from bench_repertoire import machine

from evorbc_ros.adaptation import AdaptationSettings, OnlineAdaptation, cycles
from evorbc_ros.adaptation.model import LEGGED_SETTINGS, OutcomeModel, outcome_table
from evorbc_ros.adaptation.motion import extend_arc
from evorbc_ros.defaults import default_repertoire
from evorbc_ros.repertoire import Repertoire

T = 2.0
SHIPPED = ("4ws-5", "hexapod", "a1")


def synthetic(n: int, rng: np.random.Generator) -> np.ndarray:
    """``(n, 3)`` outcomes: ``(dx, dy)`` uniform over a 0.36 m disc, heading in +-3 rad."""
    r = 0.36 * np.sqrt(rng.uniform(0, 1, n))
    a = rng.uniform(-np.pi, np.pi, n)
    return np.column_stack([r * np.cos(a), r * np.sin(a), rng.uniform(-3, 3, n)])


def worst(outcomes, settings, functions, cycles, rng, hold_max) -> np.ndarray:
    """Seconds per cycle when every cycle refits with a full ring."""
    model = OutcomeModel(outcomes, settings, functions=functions)
    n = len(outcomes)
    for i in rng.choice(n, settings.capacity, replace=False):
        model.observe(int(i), outcomes[i] * 0.9)
    out = np.empty(cycles)
    for t in range(cycles):
        i = int(rng.integers(n))
        while i in model.slots:
            i = int(rng.integers(n))
        seen = outcomes[i] * 0.9
        px, py = rng.uniform(-0.36, 0.36, 2)
        start = time.thread_time()
        model.observe(i, seen)
        model.nearest(px, py)
        out[t] = time.thread_time() - start
    return out


def run(outcomes, settings, functions, cycles, rng, hold_max) -> np.ndarray:
    """Seconds per cycle of the adaptation work over ``cycles`` cycles."""
    adapt = OnlineAdaptation(outcomes, T, settings, functions=functions)
    n = len(outcomes)
    x = y = h = 0.0
    index, left = 0, 0
    out = np.empty(cycles)
    for t in range(cycles):
        if left == 0:
            index, left = int(rng.integers(n)), int(rng.integers(1, hold_max + 1))
        left -= 1
        px, py = rng.uniform(-0.36, 0.36, 2)  # the mapping's point
        start = time.thread_time()
        adapt.put_pose(t * 100_000_000, x, y, h)
        adapt.before_choice()
        chosen = adapt.choose(px, py, index)
        adapt.after_choice(index)
        out[t] = time.thread_time() - start
        del chosen  # the network's choice drives this run, so that primitives are held
        dx, dy, dh = extend_arc(*outcomes[index], T, 0.1)  # a settled cycle, 10 % short
        x += 0.9 * (math.cos(h) * dx - math.sin(h) * dy)
        y += 0.9 * (math.sin(h) * dx + math.cos(h) * dy)
        h += 0.9 * dh
    return out


def main() -> None:
    """Print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cycles", type=int, default=2000)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})
    import numba as nb

    compiled = cycles.compiled(nb.njit)
    sizes = {name: len(Repertoire.load(default_repertoire(name))) for name in SHIPPED}
    largest = max(sizes, key=sizes.get)
    rep = Repertoire.load(default_repertoire(largest))
    cases = [(f"{n} synthetic", synthetic(n, np.random.default_rng(n))) for n in (100, 1000)]
    shipped = outcome_table(rep.behaviour, rep.heading)
    cases.append((f"{len(rep)} ({largest}, largest shipped)", shipped))
    cases.append(("10000 synthetic", synthetic(10_000, np.random.default_rng(10_000))))
    regimes = {"driving": run, "worst": worst}
    defaults = {"wheeled": AdaptationSettings(), "legged": LEGGED_SETTINGS}
    print(f"machine: {machine()}, one core; {args.cycles} cycles per row; ms per cycle")
    print(f"{'repertoire':34s} {'settings':8s} {'regime':8s} {'plain p50':>10s} {'p99':>7s} "
          f"{'max':>7s} {'numba p50':>10s} {'p99':>7s}")  # fmt: skip
    for label, outcomes in cases:
        for (kind, settings), (regime, measure) in itertools.product(
            defaults.items(), regimes.items()
        ):
            row = []
            for functions in (None, compiled):
                measure(outcomes, settings, functions, 50, np.random.default_rng(0), 12)  # warm
                rng = np.random.default_rng(args.seed)
                times = measure(outcomes, settings, functions, args.cycles, rng, 12) * 1e3
                row.append(times)
            plain, jitted = row
            print(
                f"{label:34s} {kind:8s} {regime:8s} {np.median(plain):10.3f} "
                f"{np.quantile(plain, 0.99):7.3f} {plain.max():7.3f} "
                f"{np.median(jitted):10.3f} {np.quantile(jitted, 0.99):7.3f}"
            )


if __name__ == "__main__":
    main()
