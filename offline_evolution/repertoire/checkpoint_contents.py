"""Checks of a MAP-Elites checkpoint's contents before a run resumes from it.

A checkpoint whose settings match this run's can still hold data no run writes (edited by
hand, or damaged): NaN genes, genes outside [-1, 1], behaviours outside the archive,
counters that do not add up. Resumed, such a run would fail only at its very end, or
finish with a wrong repertoire; so each problem is named when the checkpoint is loaded.
"""

from __future__ import annotations

import numpy as np

from evorbc_ros.repertoire_checks import HEADING_LIMIT, QUALITY_RANGES
from evorbc_ros.robots.primitive import GENE_HIGH, GENE_LOW
from offline_evolution.repertoire.settings import MapElitesSettings


def _count(header: dict, key: str, high: int) -> str | None:
    value = header.get(key)
    # bool is an int subclass; true/false is no count.
    if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value <= high:
        return f"{key} must be a whole number from 0 to {high}, got {value!r}"
    return None


def header_problem(header: dict, settings: MapElitesSettings) -> str | None:
    """The first problem with a checkpoint header's counters and emitter state, or None."""
    evaluations = header.get("evaluations")
    problem = (
        _count(header, "evaluations", settings.evaluations)
        or _count(header, "batches_done", settings.evaluations)
        or _count(header, "discarded", evaluations)
    )
    if problem:
        return problem
    emitter = header.get("emitter")
    if not isinstance(emitter, dict) or not isinstance(emitter.get("rng"), dict):
        return "emitter must hold the state of its random generator"
    return _count(emitter, "initial_remaining", settings.initial_batch)


def arrays_problem(
    arrays: dict[str, np.ndarray], n_genes: int, layout: dict, evaluations: int, metric: str
) -> str | None:
    """The first problem with a checkpoint's elites, or None.

    Args:
        arrays: ``solution (n, n_genes)``, ``objective (n,)``, ``measures (n, 2)`` (m) and
            ``heading (n,)`` (rad), as :meth:`MapElites.save` writes them.
        layout: the run's archive layout; every behaviour must lie inside it.
        evaluations: the header's count; there cannot be more elites than evaluations.
        metric: the run's quality metric; every objective must lie in its range, and every
            heading within ``HEADING_LIMIT`` (the repertoire written at the end must load).

    """
    for name in ("solution", "objective", "measures", "heading"):
        if name not in arrays:
            return f"{name} is missing"
        # A run writes float64 here: complex, integer or string arrays are no checkpoint's.
        if arrays[name].dtype.kind != "f":
            return f"{name} must hold real numbers (float), got {arrays[name].dtype}"
    n = len(arrays["objective"]) if arrays["objective"].ndim == 1 else -1
    expected = {"solution": (n, n_genes), "objective": (n,), "measures": (n, 2), "heading": (n,)}
    for name, shape in expected.items():
        if arrays[name].shape != shape:
            return f"{name} has shape {arrays[name].shape}, expected {shape}"
        if not np.all(np.isfinite(arrays[name])):
            return f"{name} contains NaN or infinity"
    if n > evaluations:
        return f"{n} elites but only {evaluations} evaluations"
    genes, behaviour = arrays["solution"], arrays["measures"]
    if n and (genes.min() < GENE_LOW or genes.max() > GENE_HIGH):
        return f"solution (genes) must lie in [{GENE_LOW}, {GENE_HIGH}]"
    q_low, q_high = QUALITY_RANGES[metric]
    quality = arrays["objective"]
    if n and (quality.min() < q_low or quality.max() > q_high):
        return f"objective (quality) must lie in [{q_low:g}, {q_high:g}], the range of {metric}"
    if n and np.abs(arrays["heading"]).max() > HEADING_LIMIT:
        return f"heading must lie within {HEADING_LIMIT:g} rad"
    low, high = np.asarray(layout["low"]), np.asarray(layout["high"])
    if not np.all((behaviour >= low) & (behaviour < high)):
        return "measures (behaviour) must lie inside the archive"
    return None
