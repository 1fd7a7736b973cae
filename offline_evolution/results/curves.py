"""Fitness curves from the per-generation histories of docs/results/histories/."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from offline_evolution.results.tables import TableError, number, read_table


def history(results: Path, run: str) -> list[dict]:
    """Run ``run``'s generations as dicts.

    Keys: ``generation`` (0-based), ``best``, ``mean`` and ``best_so_far`` (the running
    maximum of ``best``); fitness of eq. 5, dimensionless.

    A run whose history is another's start (``history_of`` in ``arbitrator-runs.csv``)
    reads that one's, cut at its own number of generations.

    Raises:
        TableError: the run or its history is not in ``results``.
    """
    runs_path = results / "arbitrator-runs.csv"
    runs = {r["run"]: r for r in read_table(runs_path, ("run", "generations", "history_of"))}
    if run not in runs:
        raise TableError(f"{runs_path}: no run {run}")
    source = runs[run]["history_of"] or run
    path = results / "histories" / f"{source}.csv"
    rows = read_table(path, ("generation", "best", "mean"))
    rows = rows[: int(number(runs[run], "generations", runs_path) or len(rows))]
    if not rows:
        raise TableError(f"{path}: no generations")
    best = np.array([number(r, "best", path) for r in rows], dtype=float)
    so_far = np.maximum.accumulate(best)
    return [
        {
            "generation": int(r["generation"]),
            "best": float(b),
            "mean": number(r, "mean", path),
            "best_so_far": float(s),
        }
        for r, b, s in zip(rows, best, so_far, strict=True)
    ]


def plot_run(results: Path, run: str, out: str | os.PathLike) -> None:
    """Draw run ``run``'s fitness curve to ``out`` (as ``evorbc-evolve arbitrator --plot``)."""
    from offline_evolution.plots.fitness import plot_fitness_history

    plot_fitness_history(history(results, run), out, title=Path(run).name)
