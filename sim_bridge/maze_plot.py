"""Maze pictures in the style of the paper's Fig. 7 (left).

Walls are drawn as their true boxes (:mod:`sim_bridge.geometry`), with the start region, the
nominal start pose and the target; axes are in metres in the maze frame (x towards the
target, y up). :func:`draw_maze` draws onto a given axes so that robot trajectories can be
drawn on top of it.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence

import numpy as np
from matplotlib.collections import PatchCollection
from matplotlib.patches import Circle, Polygon, Rectangle

from sim_bridge.geometry import CX, CY, EX, EY, HALF_LENGTH, HALF_THICKNESS
from sim_bridge.maze import Maze
from sim_bridge.plotting import plt, save_figure

WALL_COLOUR = "0.25"
START_COLOUR = "tab:blue"
TARGET_COLOUR = "tab:red"


def wall_outlines(maze: Maze) -> np.ndarray:
    """``(m, 4, 2)`` corners of each wall box, in order around the box (m)."""
    b = maze.boxes
    along = b[:, [EX, EY]] * b[:, HALF_LENGTH, None]
    across = np.stack([-b[:, EY], b[:, EX]], axis=1) * b[:, HALF_THICKNESS, None]
    centre = b[:, [CX, CY]]
    return np.stack(
        [
            centre + along + across,
            centre + along - across,
            centre - along - across,
            centre - along + across,
        ],
        axis=1,
    )


def draw_maze(ax, maze: Maze) -> None:
    """Draw ``maze`` on ``ax``: walls, start region, nominal start pose and target."""
    # A thin edge in the wall colour keeps 0.01 m walls visible when a whole maze is only a
    # few inches wide.
    walls = PatchCollection(
        [Polygon(corners, closed=True) for corners in wall_outlines(maze)],
        facecolor=WALL_COLOUR,
        edgecolor=WALL_COLOUR,
        linewidth=0.6,
        snap=False,  # pixel snapping would draw equal walls one or two pixels wide
        zorder=2,
    )
    ax.add_collection(walls)
    (x0, x1), (y0, y1) = maze.start_x, maze.start_y
    ax.add_patch(
        Rectangle(
            (x0, y0),
            x1 - x0,
            y1 - y0,
            facecolor=START_COLOUR,
            alpha=0.15,
            edgecolor="none",
            zorder=0,
        )
    )
    sx, sy, heading = maze.start_pose
    arrow = 0.3  # m, long enough to read the heading at maze scale
    ax.arrow(
        sx,
        sy,
        arrow * math.cos(heading),
        arrow * math.sin(heading),
        width=0.015,
        head_width=0.08,
        head_length=0.08,
        length_includes_head=True,
        color=START_COLOUR,
        zorder=3,
    )
    ax.add_patch(
        Circle(
            maze.target,
            maze.target_radius,
            fill=False,
            edgecolor=TARGET_COLOUR,
            linewidth=1.2,
            zorder=3,
        )
    )
    ax.plot(*maze.target, "o", color=TARGET_COLOUR, markersize=3, zorder=3)
    bx0, by0, bx1, by1 = maze.bounds()
    pad = 0.1  # m, keeps the outer walls apart from the axes frame
    ax.set_xlim(bx0 - pad, bx1 + pad)
    ax.set_ylim(by0 - pad, by1 + pad)
    ax.set_aspect("equal")
    ax.spines[["top", "right"]].set_visible(False)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")


def plot_mazes(mazes: Sequence[Maze], path: str | os.PathLike) -> None:
    """Save all ``mazes`` stacked one per row in one picture at ``path`` (atomically)."""
    if not mazes:
        raise ValueError("plot_mazes needs at least one maze")
    width = max(m.size()[0] for m in mazes)
    row = max(m.size()[1] for m in mazes) / width * 10.0 + 0.9  # inches: maze, title, labels
    fig, axes = plt.subplots(
        len(mazes), 1, figsize=(10.0, row * len(mazes)), squeeze=False, layout="constrained"
    )
    for ax, maze in zip(axes[:, 0], mazes, strict=True):
        draw_maze(ax, maze)
        w, h = maze.size()
        ax.set_title(f"{maze.name} ({w:.2f} x {h:.2f} m)", fontsize=10)
    save_figure(fig, path)


def plot_run(
    maze: Maze,
    trajectory: np.ndarray,
    title: str,
    path: str | os.PathLike,
    dt: float = 0.1,
    episode_time: float = 120.0,
) -> None:
    """One robot's path over its maze (colour = time), saved at ``path``."""
    from matplotlib.collections import LineCollection

    xy = np.asarray(trajectory, dtype=np.float64)[:, :2]
    w, h = maze.size()
    fig, ax = plt.subplots(figsize=(11.0, 11.0 * h / w + 1.2), layout="constrained")
    draw_maze(ax, maze)
    norm = plt.Normalize(0.0, episode_time)
    lines = LineCollection(
        np.stack([xy[:-1], xy[1:]], axis=1), cmap="viridis", norm=norm, linewidths=1.8, zorder=3
    )
    lines.set_array(np.arange(len(xy) - 1) * dt)
    ax.add_collection(lines)
    ax.plot(*xy[0], "o", color="tab:green", ms=5, zorder=5)
    ax.plot(*xy[-1], "s", color="black", ms=4, zorder=5)
    fig.colorbar(
        plt.cm.ScalarMappable(norm=norm, cmap="viridis"), ax=ax, shrink=0.8, label="time (s)"
    )
    ax.set_title(title, fontsize=10)
    save_figure(fig, path)
