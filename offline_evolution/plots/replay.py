"""Trajectories of a replay drawn over the mazes (one row per maze)."""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np
from matplotlib.collections import LineCollection

from offline_evolution.maze_task.task import EpisodeResult, MazeTask
from sim_bridge.maze_plot import draw_maze
from sim_bridge.plotting import plt, save_figure


def plot_trajectories(
    task: MazeTask,
    outcomes: Sequence,
    result: EpisodeResult,
    path: str | os.PathLike,
    title: str = "",
) -> None:
    """Each episode's path (colour = time) over its maze, with start, end and result."""
    n = len(outcomes)
    mazes = {m.name: m for m in task.mazes}
    # Rows are as tall as the widest-for-its-height maze needs to fill about 10 in of the
    # 12 in width (the rest is labels and the colour bar): the 11 x 1.4 m 4WS mazes keep
    # 2.1 in rows, the 8 x 2 m hexapod maze gets taller ones instead of a narrow strip.
    aspect = max(w / h for w, h in (mazes[o.maze].size() for o in outcomes))
    row = max(2.1, 10.0 / aspect + 0.6)
    fig, axes = plt.subplots(
        n, 1, figsize=(12.0, row * n + 0.4), squeeze=False, layout="constrained"
    )
    cmap = plt.get_cmap("viridis")
    for e, (ax, o) in enumerate(zip(axes[:, 0], outcomes, strict=True)):
        maze = mazes[o.maze]
        draw_maze(ax, maze)
        cycles = int(result.cycles[e])
        xy = result.pose[e, : cycles + 1, :2]
        segments = np.stack([xy[:-1], xy[1:]], axis=1)
        lines = LineCollection(
            segments, cmap=cmap, linewidths=1.6, norm=plt.Normalize(0.0, task.settings.episode_time)
        )
        lines.set_array(np.arange(cycles) * task.dt)
        ax.add_collection(lines)
        ax.plot(*xy[0], "o", color="tab:green", ms=5, zorder=5)
        ax.plot(*xy[-1], "s", color="black", ms=4, zorder=5)
        verdict = (
            f"reached in {o.time:.1f} s"
            if o.reached
            else f"not reached, {o.final_distance:.2f} m left"
        )
        ax.set_title(f"{o.maze}: {verdict}, fitness {o.fitness:.3f}", fontsize=10)
    fig.colorbar(
        plt.cm.ScalarMappable(norm=plt.Normalize(0, task.settings.episode_time), cmap=cmap),
        ax=list(axes[:, 0]),
        shrink=0.6,
        label="time (s)",
    )
    if title:
        fig.suptitle(title)
    save_figure(fig, path)
