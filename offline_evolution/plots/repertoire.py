"""Repertoire pictures in the style of the paper's Fig. 8.

Each primitive is a circle at its final displacement with a line along its final heading,
coloured by quality; axes are in metres in the start frame (x forward, y left).
"""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np
from matplotlib.collections import EllipseCollection, LineCollection

from evorbc_ros.repertoire import Repertoire
from offline_evolution.quality import METRICS
from sim_bridge.plotting import plt, save_figure


def quality_norm(repertoire: Repertoire):
    """Colour scale from 0 to the metric's highest possible quality."""
    top = METRICS[repertoire.metric][1] if repertoire.metric in METRICS else None
    return plt.Normalize(0.0, top or max(1.0, float(repertoire.quality.max(initial=1.0))))


def draw_repertoire(ax, r: Repertoire, norm, cmap=None) -> None:
    """Draw the cell grid and one marker per primitive of ``r`` on ``ax``."""
    cmap = cmap or plt.get_cmap("viridis")
    low = r.archive.get("low", [-0.5, -0.5])
    high = r.archive.get("high", [0.5, 0.5])
    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
    ax.set_aspect("equal")
    # Faint cell edges make the bin size visible.
    ax.vlines(
        np.arange(low[0], high[0] + 1e-9, r.bin_size),
        low[1],
        high[1],
        color="0.92",
        lw=0.4,
        zorder=0,
    )
    ax.hlines(
        np.arange(low[1], high[1] + 1e-9, r.bin_size),
        low[0],
        high[0],
        color="0.92",
        lw=0.4,
        zorder=0,
    )
    ax.axhline(0.0, color="0.75", lw=0.6, zorder=0)
    ax.axvline(0.0, color="0.75", lw=0.6, zorder=0)
    if not len(r):
        return
    colours = cmap(norm(r.quality))
    size = 0.45 * r.bin_size  # marker diameter, m
    ax.add_collection(
        EllipseCollection(
            widths=size,
            heights=size,
            angles=0.0,
            units="xy",
            offsets=r.behaviour,
            offset_transform=ax.transData,
            facecolors="none",
            edgecolors=colours,
            linewidths=1.0,
        )
    )
    tips = r.behaviour + 0.5 * r.bin_size * np.column_stack([np.cos(r.heading), np.sin(r.heading)])
    ax.add_collection(
        LineCollection(np.stack([r.behaviour, tips], axis=1), colors=colours, linewidths=1.0)
    )


def caption(r: Repertoire) -> str:
    """One line with the count and quality of a repertoire."""
    s = r.summary()
    return (
        f"{s['count']} primitives, mean quality {s['mean_quality']:.3f} "
        f"\u00b1 {s['sd_quality']:.3f}, QD-score {s['qd_score']:.1f}, seed {r.seed}"
    )


def plot_repertoire(repertoire: Repertoire, path: str | os.PathLike, title: str | None = None):
    """Draw ``repertoire`` and save it as a PNG at ``path``."""
    r = repertoire
    fig, ax = plt.subplots(figsize=(6.4, 6.0))
    norm = quality_norm(r)
    draw_repertoire(ax, r, norm)
    fig.colorbar(
        plt.cm.ScalarMappable(norm=norm, cmap="viridis"),
        ax=ax,
        shrink=0.8,
        label=f"quality ({r.metric})",
    )
    ax.set_xlabel("x displacement (m), forward")
    ax.set_ylabel("y displacement (m), left")
    ax.set_title(title or f"{r.robot} repertoire, T = {r.eval_time:g} s, bin {r.bin_size:g} m")
    fig.text(0.5, 0.015, caption(r), ha="center", fontsize=9)
    fig.subplots_adjust(bottom=0.11, top=0.93)
    save_figure(fig, path)


def plot_repertoire_panels(
    repertoires: Sequence[Repertoire], path: str | os.PathLike, titles: Sequence[str] | None = None
) -> None:
    """Several repertoires side by side on one colour scale (like Fig. 8, top)."""
    n = len(repertoires)
    fig, axes = plt.subplots(
        1, n, figsize=(3.3 * n + 1.0, 3.9), squeeze=False, layout="constrained"
    )
    norm = quality_norm(repertoires[0])
    for k, (ax, r) in enumerate(zip(axes[0], repertoires, strict=True)):
        draw_repertoire(ax, r, norm)
        s = r.summary()
        name = titles[k] if titles else r.robot
        ax.set_title(
            f"{name}\n{s['count']} primitives, mean quality {s['mean_quality']:.3f}", fontsize=10
        )
        ax.set_xlabel("x (m)")
    axes[0][0].set_ylabel("y (m)")
    fig.colorbar(
        plt.cm.ScalarMappable(norm=norm, cmap="viridis"),
        ax=list(axes[0]),
        shrink=0.9,
        label=f"quality ({repertoires[0].metric})",
    )
    save_figure(fig, path)
