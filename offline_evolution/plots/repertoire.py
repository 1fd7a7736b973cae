"""Repertoire picture in the style of the paper's Fig. 8.

Each primitive is a circle at its final displacement with a line along its final heading,
coloured by quality; axes are in metres in the start frame (x forward, y left).
"""

from __future__ import annotations

import os

import numpy as np
from matplotlib.collections import EllipseCollection, LineCollection

from evorbc_ros.repertoire import Repertoire
from offline_evolution.plots.common import plt, save_figure
from offline_evolution.quality import METRICS


def plot_repertoire(repertoire: Repertoire, path: str | os.PathLike, title: str | None = None):
    """Draw ``repertoire`` and save it as a PNG at ``path``."""
    r = repertoire
    fig, ax = plt.subplots(figsize=(6.4, 6.8))
    low = r.archive.get("low", [-0.5, -0.5])
    high = r.archive.get("high", [0.5, 0.5])
    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
    ax.set_aspect("equal")
    # Cell grid, faint, so the bin size is visible.
    edges_x = np.arange(low[0], high[0] + 1e-9, r.bin_size)
    edges_y = np.arange(low[1], high[1] + 1e-9, r.bin_size)
    ax.vlines(edges_x, low[1], high[1], color="0.92", lw=0.4, zorder=0)
    ax.hlines(edges_y, low[0], high[0], color="0.92", lw=0.4, zorder=0)
    ax.axhline(0.0, color="0.75", lw=0.6, zorder=0)
    ax.axvline(0.0, color="0.75", lw=0.6, zorder=0)

    q_max = METRICS.get(r.metric, (None, max(1.0, float(r.quality.max(initial=1.0)))))[1]
    cmap = plt.get_cmap("viridis")
    norm = plt.Normalize(0.0, q_max)
    if len(r):
        size = 0.45 * r.bin_size
        circles = EllipseCollection(
            widths=size,
            heights=size,
            angles=0.0,
            units="xy",
            offsets=r.behaviour,
            offset_transform=ax.transData,
            facecolors="none",
            edgecolors=cmap(norm(r.quality)),
            linewidths=1.0,
        )
        ax.add_collection(circles)
        tips = r.behaviour + 0.5 * r.bin_size * np.column_stack(
            [np.cos(r.heading), np.sin(r.heading)]
        )
        ax.add_collection(
            LineCollection(
                np.stack([r.behaviour, tips], axis=1), colors=cmap(norm(r.quality)), linewidths=1.0
            )
        )
    mappable = plt.cm.ScalarMappable(norm=norm, cmap=cmap)
    fig.colorbar(mappable, ax=ax, shrink=0.8, label=f"quality ({r.metric})")
    ax.set_xlabel("x displacement (m), forward")
    ax.set_ylabel("y displacement (m), left")
    ax.set_title(title or f"{r.robot} repertoire, T = {r.eval_time:g} s, bin {r.bin_size:g} m")
    s = r.summary()
    fig.text(
        0.5,
        0.02,
        f"{s['count']} primitives, mean quality {s['mean_quality']:.3f} "
        f"\u00b1 {s['sd_quality']:.3f}, QD-score {s['qd_score']:.1f}, seed {r.seed}",
        ha="center",
        fontsize=9,
    )
    save_figure(fig, path)
