"""The MAP-Elites archive over the behaviour space (final displacement, m).

Two kinds: the paper's grid of square cells, and a centroidal Voronoi tessellation (CVT,
Vassiliades et al. 2018) with as many cells over the same square. The CVT's centroids are
computed for the left half-plane (y >= 0) and mirrored, so neither archive favours one
side of a left/right symmetric robot.
"""

from __future__ import annotations

import copy
import functools
import math

import numpy as np
from ribs.archives import ArchiveBase, CVTArchive, GridArchive, k_means_centroids

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


#: Uniform samples of the half-plane that k-means clusters into the CVT's centroids.
CVT_SAMPLES = 100_000


def cvt_layout(max_reach: float, bin_size: float, seed: int) -> dict:
    """A CVT over the same square as :func:`grid_layout`, with as many cells (to within one).

    k-means is seconds for a Table I archive: a process computes each layout once
    (a fresh copy each call, so no caller changes another's).

    The cells then have the grid's mean area, so cell counts of the two archives compare.
    k-means runs on the half-plane ``y >= 0``; the centroids and their mirror images
    ``(x, -y)`` make the archive exactly left/right symmetric.

    Returns:
        ``{"kind": "cvt", "cells": k, "low", "high", "centroids": [[x, y], ...]}``; the
        centroids are stored so a resumed run or a reader needs no k-means.

    """
    return copy.deepcopy(_cvt_layout(float(max_reach), float(bin_size), int(seed)))


@functools.lru_cache(maxsize=8)
def _cvt_layout(max_reach: float, bin_size: float, seed: int) -> dict:
    grid = grid_layout(max_reach, bin_size)
    (low, _), (high, _) = grid["low"], grid["high"]
    half = grid["dims"][0] * grid["dims"][1] // 2
    upper, _ = k_means_centroids(
        centroids=half, ranges=[(low, high), (0.0, high)], samples=CVT_SAMPLES, seed=seed
    )
    centroids = np.vstack([upper, upper * (1.0, -1.0)])
    return {
        "kind": "cvt",
        "cells": len(centroids),
        "low": grid["low"],
        "high": grid["high"],
        "centroids": centroids.tolist(),
    }


def make_archive(layout: dict, solution_dim: int, seed: int) -> ArchiveBase:
    """An empty pyribs archive for ``layout`` (:func:`grid_layout` or :func:`cvt_layout`).

    A cell takes a new solution if it is empty or the new quality is strictly higher
    (Algorithm 1, line 14): pyribs' default threshold rule with learning rate 1.
    """
    ranges = list(zip(layout["low"], layout["high"], strict=True))
    if layout["kind"] == "cvt":
        return CVTArchive(
            solution_dim=solution_dim,
            centroids=np.asarray(layout["centroids"], dtype=np.float64),
            ranges=ranges,
            seed=seed,
            extra_fields=EXTRA_FIELDS,
        )
    return GridArchive(
        solution_dim=solution_dim,
        dims=layout["dims"],
        ranges=ranges,
        seed=seed,
        extra_fields=EXTRA_FIELDS,
    )


def elites_by_cell(archive: ArchiveBase) -> dict[str, np.ndarray]:
    """All elites as arrays ordered by cell index, whatever order they were inserted in."""
    data = archive.data()
    order = np.argsort(data["index"], kind="stable")
    return {k: np.asarray(v)[order] for k, v in data.items()}
