"""Figures that compare repertoires: coverage, QD-score and left/right symmetry.

Symmetry is measured on the paper's square grid whatever the archive was: behaviours
``(x, y)`` (m, start frame, x forward, y left) fall into cells of ``bin_size`` centred on
the origin, and a cell counts as mirrored when the cell of ``(x, -y)`` is also filled. A
left/right symmetric robot can in principle fill mirror-image cells, so a low figure means
that the search under-explored one side (the paper's Fig. 16 repertoire is lopsided).
"""

from __future__ import annotations

import numpy as np

from evorbc_ros.repertoire import Repertoire


def repertoire_stats(rep: Repertoire, bin_size: float | None = None) -> dict[str, float]:
    """Count, quality, QD-score and symmetry of a repertoire.

    Args:
        rep: the repertoire.
        bin_size: grid cell side (m) for the symmetry figure; default the repertoire's.

    Returns:
        ``count``, ``mean_quality``, ``sd_quality``, ``qd_score`` (sum of qualities),
        ``cells`` (grid cells filled), ``mirrored`` (share of filled off-axis cells whose
        mirror cell is filled), ``left`` and ``right`` (primitives ending more than half a
        cell to the left or right).

    """
    size = bin_size or rep.bin_size
    cells = {tuple(c) for c in np.round(rep.behaviour / size).astype(int)}
    off_axis = [c for c in cells if c[1] != 0]
    mirrored = sum((x, -y) in cells for x, y in off_axis)
    y = rep.behaviour[:, 1]
    q = rep.quality
    return {
        "count": len(rep),
        "mean_quality": float(q.mean()) if len(q) else 0.0,
        "sd_quality": float(q.std()) if len(q) else 0.0,
        "qd_score": float(q.sum()),
        "cells": len(cells),
        "mirrored": mirrored / len(off_axis) if off_axis else 1.0,
        "left": int(np.sum(y > size / 2)),
        "right": int(np.sum(y < -size / 2)),
    }
