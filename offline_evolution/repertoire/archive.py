"""The MAP-Elites archive over the behaviour space (final displacement, m)."""

from __future__ import annotations

import math

import numpy as np
from ribs.archives import GridArchive

#: Per-primitive data the archive keeps besides solution, objective and measures.
EXTRA_FIELDS = {"heading": ((), np.float64)}


def grid_layout(max_reach: float, bin_size: float) -> dict:
    """Square cells of ``bin_size`` m covering ``[-max_reach, max_reach]^2``.

    One cell is centred on the origin, so the grid is symmetric about both axes: a robot
    that can turn either way fills mirror-image cells, and "stay put" has its own cell.

    Returns:
        ``{"kind": "grid", "dims": [n, n], "low": [l, l], "high": [h, h]}``.

    """
    half_cells = max(0, math.ceil(max_reach / bin_size - 0.5))
    half = (half_cells + 0.5) * bin_size
    n = 2 * half_cells + 1
    return {"kind": "grid", "dims": [n, n], "low": [-half, -half], "high": [half, half]}


def make_archive(layout: dict, solution_dim: int, seed: int) -> GridArchive:
    """An empty pyribs archive for ``layout`` (see :func:`grid_layout`).

    A cell takes a new solution if it is empty or the new quality is strictly higher
    (Algorithm 1, line 14): pyribs' default threshold rule with learning rate 1.
    """
    return GridArchive(
        solution_dim=solution_dim,
        dims=layout["dims"],
        ranges=list(zip(layout["low"], layout["high"], strict=True)),
        seed=seed,
        extra_fields=EXTRA_FIELDS,
    )


def elites_by_cell(archive: GridArchive) -> dict[str, np.ndarray]:
    """All elites as arrays ordered by cell index, whatever order they were inserted in."""
    data = archive.data()
    order = np.argsort(data["index"], kind="stable")
    return {k: np.asarray(v)[order] for k, v in data.items()}
