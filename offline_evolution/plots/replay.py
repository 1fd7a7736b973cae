"""Trajectories of a replay drawn over the mazes (one row per maze), with a legend."""

from __future__ import annotations

import os
from collections.abc import Sequence

from offline_evolution.maze_task.task import EpisodeResult, MazeTask
from sim_bridge.maze_plot import PATH_CMAP, add_episode_legend, draw_episode
from sim_bridge.plotting import plt, save_figure
from sim_bridge.verdict import episode_line


def trajectories_figure(task: MazeTask, outcomes: Sequence, result: EpisodeResult, title: str = ""):
    """Each episode's path (colour = time) over its maze, with start, end and result.

    Args:
        outcomes: one :class:`~offline_evolution.maze_task.replay.MazeOutcome` per episode.
        result: the recorded replay (``result.pose``: ``(E, n_cycles + 1, 3)`` poses).

    Returns:
        The matplotlib figure (the caller saves or shows it).
    """
    n = len(outcomes)
    mazes = {m.name: m for m in task.mazes}
    # Rows are as tall as the widest-for-its-height maze needs to fill about 10 in of the
    # 12 in width (the rest is labels and the colour bar): the 11 x 1.4 m 4WS mazes keep
    # 2.1 in rows, the 8 x 2 m hexapod maze gets taller ones instead of a narrow strip.
    # The legend takes another 0.4 in at the bottom.
    aspect = max(w / h for w, h in (mazes[o.maze].size() for o in outcomes))
    row = max(2.1, 10.0 / aspect + 0.6)
    fig, axes = plt.subplots(
        n, 1, figsize=(12.0, row * n + 0.8), squeeze=False, layout="constrained"
    )
    norm = plt.Normalize(0.0, task.settings.episode_time)
    legend = {}
    for e, (ax, o) in enumerate(zip(axes[:, 0], outcomes, strict=True)):
        cycles = int(result.cycles[e])
        artists = draw_episode(
            ax, mazes[o.maze], result.pose[e, : cycles + 1], task.dt, norm, linewidth=1.6
        )
        legend = legend or artists  # every row draws the same kinds of things
        ax.set_title(episode_line(o.maze, o.as_dict()), fontsize=10)  # as evorbc-sim says it
    fig.colorbar(
        plt.cm.ScalarMappable(norm=norm, cmap=PATH_CMAP),
        ax=list(axes[:, 0]),
        shrink=0.6,
        label="time (s)",
    )
    add_episode_legend(fig, legend)
    if title:
        fig.suptitle(title)
    return fig


def plot_trajectories(
    task: MazeTask,
    outcomes: Sequence,
    result: EpisodeResult,
    path: str | os.PathLike,
    title: str = "",
) -> None:
    """Save :func:`trajectories_figure` at ``path`` (atomically)."""
    save_figure(trajectories_figure(task, outcomes, result, title), path)
