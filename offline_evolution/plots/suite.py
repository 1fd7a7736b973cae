"""A suite of mazes in one picture: small panels in a grid, with robot paths if given."""

from __future__ import annotations

import math
import os
from collections.abc import Sequence

import numpy as np

from sim_bridge.maze import Maze
from sim_bridge.maze_plot import draw_maze
from sim_bridge.plotting import FIGURE_DPI, plt, save_figure

REACHED_COLOUR = "tab:green"
MISSED_COLOUR = "tab:orange"
#: Panels drawn at most: a picture of hundreds of mazes would be unreadable and huge.
MAX_PANELS = 60


def suite_figure(
    mazes: Sequence[Maze],
    titles: Sequence[str] | None = None,
    paths: Sequence[Sequence[np.ndarray]] | None = None,
    reached: Sequence[Sequence[bool]] | None = None,
    title: str = "",
):
    """Each maze in a panel of a grid; optionally each maze's episode paths.

    Args:
        mazes: the suite (the first :data:`MAX_PANELS` are drawn).
        titles: one per maze (default: the maze's name).
        paths: per maze, the ``(n, 2+)`` poses (m, maze frame) of each of its episodes.
        reached: per maze and episode, whether it reached the target (green, else orange).

    Returns:
        The matplotlib figure (the caller saves it).
    """
    mazes = list(mazes)[:MAX_PANELS]
    w, h = np.max([m.size() for m in mazes], axis=0)
    cols = max(1, min(len(mazes), round(math.sqrt(len(mazes) * h / w * 3.0)) or 1))
    rows = math.ceil(len(mazes) / cols)
    panel_w = 16.0 / cols  # in
    fig, axes = plt.subplots(
        rows,
        cols,
        figsize=(16.0, rows * (panel_w * h / w + 0.45) + 0.4),
        squeeze=False,
        layout="constrained",
    )
    for k, ax in enumerate(axes.flat):
        if k >= len(mazes):
            ax.set_axis_off()
            continue
        maze = mazes[k]
        draw_maze(ax, maze, nominal_start=False)
        for e, pose in enumerate(paths[k] if paths is not None else ()):
            ok = reached is not None and reached[k][e]
            ax.plot(
                pose[:, 0],
                pose[:, 1],
                color=REACHED_COLOUR if ok else MISSED_COLOUR,
                linewidth=0.6,
                alpha=0.7,
                zorder=4,
            )
        ax.set_title(titles[k] if titles else maze.name, fontsize=7)
        ax.set_xlabel("")
        ax.set_ylabel("")
        ax.tick_params(labelsize=5)
    if title:
        fig.suptitle(title, fontsize=10)
    return fig


def plot_suite(mazes, path: str | os.PathLike, **kwargs) -> None:
    """Save :func:`suite_figure` at ``path`` (atomically)."""
    save_figure(suite_figure(mazes, **kwargs), path, dpi=FIGURE_DPI)
