"""Maze pictures in the style of the paper's Fig. 7 (left), and robot runs drawn over them.

Walls are drawn as their true boxes (:mod:`sim_bridge.geometry`), with the start region, the
nominal start pose and the target; axes are in metres in the maze frame (x towards the
target, y up). :func:`draw_maze` draws onto a given axes so that robot trajectories can be
drawn on top of it; :func:`draw_episode` draws one run (its path coloured by time, its start
and end poses) and returns the artists that :func:`add_episode_legend` names in a legend.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence

import numpy as np
from matplotlib.collections import LineCollection, PatchCollection
from matplotlib.legend_handler import HandlerBase, HandlerPatch, HandlerTuple
from matplotlib.patches import Circle, FancyArrow, Polygon, Rectangle

from sim_bridge.geometry import CX, CY, EX, EY, HALF_LENGTH, HALF_THICKNESS
from sim_bridge.maze import Maze
from sim_bridge.plotting import plt, save_figure

WALL_COLOUR = "0.25"
START_COLOUR = "tab:blue"
END_COLOUR = "black"
TARGET_COLOUR = "tab:red"
PATH_CMAP = "viridis"
#: m, length of a pose arrow: long enough to read the heading at maze scale.
ARROW_LENGTH = 0.3


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


def draw_pose(ax, x: float, y: float, heading: float, colour, marker: str | None = None):
    """A pose: an arrow from ``(x, y)`` (m) along ``heading`` (rad), and a marker at its tail.

    Returns:
        The artists, ``(marker, arrow)`` or ``(arrow,)`` without a marker; a legend shows
        them as one entry.
    """
    arrow = ax.arrow(
        x,
        y,
        ARROW_LENGTH * math.cos(heading),
        ARROW_LENGTH * math.sin(heading),
        width=0.015,
        head_width=0.08,
        head_length=0.08,
        length_includes_head=True,
        color=colour,
        zorder=5,
    )
    if marker is None:
        return (arrow,)
    (dot,) = ax.plot(x, y, marker, color=colour, ms=5, zorder=6)
    return dot, arrow


def target_label(maze: Maze) -> str:
    """The legend's name for the target circle, with the distance that counts as reached."""
    return f"target (reached within {maze.target_radius:g} m)"


def draw_maze(ax, maze: Maze, nominal_start: bool = True) -> dict:
    """Draw ``maze`` on ``ax``: walls, start region, nominal start pose and target.

    Args:
        nominal_start: draw the maze's nominal start pose (an arrow). A run's picture
            leaves it out and draws the pose the run really started from instead.

    Returns:
        The artists by legend label: ``start region``, :func:`target_label` and, if
        drawn, ``nominal start pose``.
    """
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
    region = ax.add_patch(
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
    artists = {"start region": region}
    if nominal_start:
        artists["nominal start pose"] = draw_pose(ax, *maze.start_pose, START_COLOUR)
    ring = ax.add_patch(
        Circle(
            maze.target,
            maze.target_radius,
            fill=False,
            edgecolor=TARGET_COLOUR,
            linewidth=1.2,
            zorder=3,
        )
    )
    (centre,) = ax.plot(*maze.target, "o", color=TARGET_COLOUR, markersize=3, zorder=3)
    artists[target_label(maze)] = (ring, centre)
    bx0, by0, bx1, by1 = maze.bounds()
    pad = 0.1  # m, keeps the outer walls apart from the axes frame
    ax.set_xlim(bx0 - pad, bx1 + pad)
    ax.set_ylim(by0 - pad, by1 + pad)
    ax.set_aspect("equal")
    ax.spines[["top", "right"]].set_visible(False)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    return artists


def draw_episode(
    ax, maze: Maze, poses: np.ndarray, dt: float, norm, cmap=PATH_CMAP, linewidth: float = 1.8
) -> dict:
    """Draw one run over its maze: the path coloured by time, the start and end poses.

    Args:
        poses: ``(n, 3)`` poses ``(x m, y m, heading rad)`` one control period apart, maze
            frame.
        dt: control period (s): pose ``k`` is at ``k * dt`` s.
        norm: the colour scale of time (s), shared with the picture's colour bar.

    Returns:
        The artists by legend label (see :func:`add_episode_legend`).
    """
    poses = np.asarray(poses, dtype=np.float64)
    maze_artists = draw_maze(ax, maze, nominal_start=False)
    xy = poses[:, :2]
    path = LineCollection(
        np.stack([xy[:-1], xy[1:]], axis=1), cmap=cmap, norm=norm, linewidths=linewidth, zorder=4
    )
    path.set_array(np.arange(len(xy) - 1) * dt)
    ax.add_collection(path)

    return {
        "start region": maze_artists["start region"],
        "start pose": draw_pose(ax, *poses[0], START_COLOUR, "o"),
        "path (colour: time)": path,
        "end point and heading": draw_pose(ax, *poses[-1], END_COLOUR, "s"),
        target_label(maze): maze_artists[target_label(maze)],
    }


class _GradientLine(HandlerBase):
    """Legend key of a time-coloured path: a short line through the whole colour map."""

    def create_artists(
        self, legend, orig_handle, xdescent, ydescent, width, height, fontsize, trans
    ):
        n = 12
        x = np.linspace(-xdescent, width - xdescent, n + 1)
        y = np.full(n + 1, 0.5 * height - ydescent)
        key = LineCollection(
            np.stack([np.column_stack([x[:-1], y[:-1]]), np.column_stack([x[1:], y[1:]])], axis=1),
            cmap=orig_handle.get_cmap(),
            linewidths=orig_handle.get_linewidth()[0],
            transform=trans,
        )
        key.set_array(np.linspace(0.0, 1.0, n))
        return [key]


def _arrow_key(legend, orig_handle, xdescent, ydescent, width, height, fontsize):
    """Legend key of a pose arrow: an arrow across the key box, pointing right."""
    return FancyArrow(
        -xdescent,
        0.5 * height - ydescent,
        width,
        0.0,
        width=0.2 * height,
        head_width=0.7 * height,
        head_length=0.35 * width,
        length_includes_head=True,
    )


def _circle_key(legend, orig_handle, xdescent, ydescent, width, height, fontsize):
    """Legend key of the target: a ring in the key box."""
    return Circle((0.5 * width - xdescent, 0.5 * height - ydescent), 0.5 * height)


#: How the legend draws the artists of :func:`draw_episode` (arrows, rings, time-coloured
#: paths, and a marker with its arrow as one key).
HANDLER_MAP = {
    FancyArrow: HandlerPatch(patch_func=_arrow_key),
    Circle: HandlerPatch(patch_func=_circle_key),
    LineCollection: _GradientLine(),
    tuple: HandlerTuple(ndivide=None),
}


def add_episode_legend(fig, artists: dict, loc: str = "outside lower center"):
    """A figure legend naming the artists of :func:`draw_episode` (or :func:`draw_maze`)."""
    return fig.legend(
        list(artists.values()),
        list(artists),
        loc=loc,
        ncols=len(artists),
        handler_map=HANDLER_MAP,
        fontsize=8,
        frameon=False,
        handlelength=2.5,
    )


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


def run_figure(
    maze: Maze,
    trajectory: np.ndarray,
    title: str,
    dt: float = 0.1,
    episode_time: float = 120.0,
):
    """The picture of one run: its path over its maze (colour = time) with a legend.

    Args:
        trajectory: ``(n, 3)`` poses ``(x m, y m, heading rad)``, one per control period
            ``dt`` (s), maze frame.
        episode_time: the end of the time colour scale (s).

    Returns:
        The matplotlib figure (the caller saves or shows it).
    """
    w, h = maze.size()
    fig, ax = plt.subplots(figsize=(11.0, 11.0 * h / w + 1.5), layout="constrained")
    norm = plt.Normalize(0.0, episode_time)
    artists = draw_episode(ax, maze, trajectory, dt, norm)
    fig.colorbar(
        plt.cm.ScalarMappable(norm=norm, cmap=PATH_CMAP), ax=ax, shrink=0.8, label="time (s)"
    )
    ax.set_title(title, fontsize=10)
    add_episode_legend(fig, artists)
    return fig


def plot_run(
    maze: Maze,
    trajectory: np.ndarray,
    title: str,
    path: str | os.PathLike,
    dt: float = 0.1,
    episode_time: float = 120.0,
) -> None:
    """Save :func:`run_figure` at ``path`` (atomically)."""
    save_figure(run_figure(maze, trajectory, title, dt, episode_time), path)
