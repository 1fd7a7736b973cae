"""Benchmark: loading large repertoire files and compiling long networks is linear.

Prints, for this machine:
  * the load time of a valid 4ws-5 repertoire of 25k, 50k, 100k and 200k primitives (one
    per cell of a grid archive), best of 3, and how much of it the checks of what the
    numbers mean take (docs/design.md section 12);
  * the compile time of a feed-forward chain of 2,500 to 10,000 hidden nodes (the
    needed-node walk and Kahn's order, both linear).

Run: ``.venv/bin/python -P bench/bench_file_loads.py``.
"""

from __future__ import annotations

import itertools
import math
import os
import platform
import tempfile
import time

import numpy as np

from evorbc_ros.network import ConnectionSpec, NetworkSpec, NodeSpec
from evorbc_ros.repertoire import Repertoire, _problem
from evorbc_ros.robots import registry

SIZES = (25_000, 50_000, 100_000, 200_000)
CHAINS = (2_500, 5_000, 10_000)


def machine() -> str:
    """CPU model and core count."""
    try:
        with open("/proc/cpuinfo") as f:
            names = [line.split(":", 1)[1].strip() for line in f if line.startswith("model name")]
    except OSError:
        names = []
    cpu = names[0] if names else platform.machine()
    return f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}"


def repertoire(n: int, seed: int = 0) -> Repertoire:
    """A valid 4ws-5 repertoire of ``n`` primitives, one in each of ``n`` grid cells."""
    rng = np.random.default_rng(seed)
    bin_size = 0.01  # m
    half_cells = math.ceil((math.sqrt(n) - 1) / 2)
    side = 2 * half_cells + 1
    half = (half_cells + 0.5) * bin_size
    cells = rng.choice(side * side, size=n, replace=False)
    centre = np.column_stack([cells // side, cells % side]) + 0.5
    behaviour = -half + centre * bin_size + rng.uniform(-0.4, 0.4, (n, 2)) * bin_size
    robot = registry.lookup("4ws-5")
    return Repertoire(
        robot="4ws-5",
        parameters=robot.parameters,
        genes=rng.uniform(-1, 1, (n, robot.n_parameters)),
        behaviour=behaviour,
        heading=rng.uniform(-3, 3, n),
        quality=rng.uniform(0, 1, n),
        metric="circular",
        eval_time=2.0,
        bin_size=bin_size,
        seed=seed,
        archive={"kind": "grid", "dims": [side, side], "low": [-half] * 2, "high": [half] * 2},
    )


def best_of(k: int, f) -> float:
    """The shortest of ``k`` wall times of ``f()`` (s)."""
    times = []
    for _ in range(k):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return min(times)


def chain(n: int) -> NetworkSpec:
    """A feed-forward chain input -> n hidden identity nodes -> output."""
    nodes = [NodeSpec(k, 0.0, 1.0, "identity", "sum") for k in (0, *range(1, n + 1))]
    link = [-1, *range(1, n + 1), 0]
    conns = [ConnectionSpec(a, b, 1.0) for a, b in itertools.pairwise(link)]
    return NetworkSpec((-1,), (0,), tuple(nodes), tuple(conns))


def main() -> None:
    """Print both tables."""
    print(f"machine: {machine()}\n")
    print("| primitives | file (MB) | load (s) | checks (ms) | load per primitive (us) |")
    print("|---:|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as folder:
        for n in SIZES:
            rep = repertoire(n)
            path = os.path.join(folder, f"r{n}.json")
            rep.save(path)
            load = best_of(3, lambda path=path: Repertoire.load(path))
            checks = best_of(3, lambda rep=rep: _problem(rep))
            mb = os.path.getsize(path) / 1e6
            print(f"| {n:,} | {mb:.1f} | {load:.2f} | {checks * 1e3:.1f} | {load / n * 1e6:.1f} |")
    print("\n| chain nodes | compile (ms) |")
    print("|---:|---:|")
    for n in CHAINS:
        spec = chain(n)
        print(f"| {n:,} | {best_of(3, spec.compile) * 1e3:.1f} |")


if __name__ == "__main__":
    main()
