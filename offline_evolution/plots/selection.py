"""Which primitives an arbitrator used (paper Fig. 14).

Three panels from a recorded replay: the two mapping outputs over time in the first
episode, where the outputs fell in [0, 1]^2 over all episodes, and how often each
repertoire cell's primitive was chosen (cells that hold a primitive are outlined).
"""

from __future__ import annotations

import os

import numpy as np
from matplotlib.colors import LogNorm
from matplotlib.patches import Rectangle

from evorbc_ros.repertoire import Repertoire
from offline_evolution.maze_task.task import EpisodeResult
from sim_bridge.plotting import plt, save_figure


def selection_counts(result: EpisodeResult, n_primitives: int) -> np.ndarray:
    """How many control cycles each primitive ran, over all recorded episodes."""
    chosen = result.choice[result.choice >= 0]
    return np.bincount(chosen, minlength=n_primitives)


def plot_selection(
    repertoire: Repertoire,
    mapping: str,
    result: EpisodeResult,
    path: str | os.PathLike,
    title: str = "",
) -> None:
    """Draw the three panels and save them as a PNG."""
    fig, axes = plt.subplots(1, 3, figsize=(14.0, 4.3), layout="constrained")
    # (a) outputs over time, first episode.
    n = int(result.cycles[0])
    t = np.arange(n) * 0.1
    for k, label in enumerate(("m1", "m2")):
        axes[0].plot(t, result.outputs[0, :n, k], lw=0.8, label=label)
    axes[0].set_xlabel("time (s), first maze")
    axes[0].set_ylabel("mapping output")
    axes[0].set_ylim(-0.02, 1.02)
    axes[0].legend(fontsize=8)
    axes[0].set_title("outputs over time")
    # (b) where the outputs fell.
    valid = ~np.isnan(result.outputs[..., 0])
    m = result.outputs[valid]
    axes[1].hist2d(m[:, 0], m[:, 1], bins=25, range=[[0, 1], [0, 1]], cmap="Blues", norm=LogNorm())
    axes[1].set_xlabel(
        "m1" + (" (distance: 0.5 = stop, 1 = forward)" if mapping == "polar" else " (x)")
    )
    axes[1].set_ylabel("m2" + (" (angle: 0.5 = ahead)" if mapping == "polar" else " (y)"))
    axes[1].set_title("mapping outputs (all mazes)")
    axes[1].set_aspect("equal")
    # (c) chosen primitives by repertoire cell.
    ax = axes[2]
    counts = selection_counts(result, len(repertoire))
    share = counts / max(1, counts.sum())
    b = repertoire.bin_size
    cmap = plt.get_cmap("magma_r")
    norm = LogNorm(vmin=max(share[share > 0].min(initial=1e-4), 1e-4), vmax=max(share.max(), 1e-3))
    centres = np.rint(repertoire.behaviour / b) * b  # cells are centred on multiples of b
    for (cx, cy), s in zip(centres, share, strict=True):
        face = cmap(norm(s)) if s > 0 else "none"
        ax.add_patch(
            Rectangle((cx - b / 2, cy - b / 2), b, b, facecolor=face, edgecolor="0.75", lw=0.4)
        )
    low, high = (
        repertoire.archive.get("low", [-0.5, -0.5]),
        repertoire.archive.get("high", [0.5, 0.5]),
    )
    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    used = int(np.count_nonzero(counts))
    ax.set_title(f"chosen primitives: {used} of {len(repertoire)} used")
    fig.colorbar(
        plt.cm.ScalarMappable(norm=norm, cmap=cmap),
        ax=ax,
        shrink=0.8,
        label="share of control cycles",
    )
    if title:
        fig.suptitle(title)
    save_figure(fig, path)
