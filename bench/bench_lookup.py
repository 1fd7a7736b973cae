"""Benchmark: building the primitive lookup grid (evorbc_ros/mapping.py) for big repertoires.

For 1,000, 10,000 and 200,000 primitives spread over a 0.36 m disc (a 4WS repertoire's
shape) and a polar mapping (256 x 256 cells over [-tau, tau]^2), prints:
  * the grid build (``PrimitiveLookup.build``, median of ``--repeats``);
  * brute force, every cell centre against every primitive, the way the grid was built
    before: measured in full up to 10,000 primitives, and for 200,000 over ``--columns``
    of the 256 grid columns, scaled up (about 3 minutes in full on the reference machine);
  * whether the two tables are equal (they must be: same formula, ties to the lower index).

Run: ``.venv/bin/python bench/bench_lookup.py [--repeats 3] [--columns 8]``.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
from bench_repertoire import machine

from evorbc_ros.mapping import DEFAULT_GRID_CELLS, MappingFunction, PrimitiveLookup


def disc(n: int, rng: np.random.Generator, radius: float = 0.36) -> np.ndarray:
    """``(n, 2)`` behaviours uniform over a disc (m)."""
    r = radius * np.sqrt(rng.uniform(0, 1, n))
    a = rng.uniform(-np.pi, np.pi, n)
    return np.column_stack([r * np.cos(a), r * np.sin(a)])


def brute_force(b: np.ndarray, domain, cells: int, columns: int | None = None):
    """The former grid fill over the first ``columns`` columns; (table rows, seconds)."""
    xmin, xmax, ymin, ymax = domain
    wx, wy = (xmax - xmin) / cells, (ymax - ymin) / cells
    cx = xmin + (np.arange(cells) + 0.5) * wx
    cy = ymin + (np.arange(cells) + 0.5) * wy
    n_cols = cells if columns is None else columns
    table = np.empty((n_cols, cells), dtype=np.int64)
    start = time.perf_counter()
    for i in range(n_cols):
        d2 = (cx[i] - b[None, :, 0]) ** 2 + (cy[:, None] - b[None, :, 1]) ** 2
        table[i] = np.argmin(d2, axis=1)
    return table, time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--columns", type=int, default=8, help="brute-force columns at 200k")
    args = parser.parse_args()
    print(f"machine: {machine()}")
    rng = np.random.default_rng(1)
    cells = DEFAULT_GRID_CELLS
    print(f"{'primitives':>10} {'grid build (s)':>15} {'brute force (s)':>16} {'same table':>11}")
    for n in (1_000, 10_000, 200_000):
        b = disc(n, rng)
        domain = MappingFunction.for_behaviours("polar", b).domain()
        times = []
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            lookup = PrimitiveLookup.build(b, domain, cells)
            times.append(time.perf_counter() - t0)
        if n <= 10_000:
            table, brute = brute_force(b, domain, cells)
            same = np.array_equal(table, lookup.table)
            brute_text = f"{brute:.2f}"
        else:
            table, part = brute_force(b, domain, cells, args.columns)
            same = np.array_equal(table, lookup.table[: args.columns])
            brute_text = f"{part * cells / args.columns:.0f} (projected)"
        print(f"{n:>10,} {statistics.median(times):>15.2f} {brute_text:>16} {same!s:>11}")


if __name__ == "__main__":
    main()
