"""The run and replay pictures name what they draw in a legend (issue 18, item 8).

The legend is checked through matplotlib's artists, not pixels: the entries and their keys,
and that each named thing is drawn where the run puts it (start region, the start pose
with its heading, the path coloured by time, the end point with its heading, the target).
"""

import math

import matplotlib
import numpy as np
import pytest
from matplotlib.collections import LineCollection
from matplotlib.colors import to_rgba
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, FancyArrow, Rectangle

from offline_evolution.maze_task.replay import MazeOutcome
from offline_evolution.maze_task.task import EpisodeResult, MazeTask, MazeTaskSettings
from offline_evolution.plots.replay import plot_trajectories, trajectories_figure
from sim_bridge.maze import load_named_maze
from sim_bridge.maze_plot import (
    END_COLOUR,
    START_COLOUR,
    TARGET_COLOUR,
    plot_run,
    run_figure,
)
from sim_bridge.plotting import plt

DT = 0.1  # s, control period


def entries(maze):
    return [
        "start region",
        "start pose",
        "path (colour: time)",
        "end point and heading",
        f"target (reached within {maze.target_radius:g} m)",
    ]


def rear_first_run(maze, cycles=40):
    """``(cycles + 1, 3)`` poses from the nominal start, driving rear first along +x."""
    x0, y0, _ = maze.start_pose
    k = np.arange(cycles + 1)
    return np.column_stack([x0 + 0.015 * k, y0 - 0.005 * k, np.full(cycles + 1, math.pi)])


def arrow_at(ax, x, y, heading):
    """The pose arrow drawn from ``(x, y)`` along ``heading``, or None."""
    for patch in ax.patches:
        if not isinstance(patch, FancyArrow):
            continue
        xy = patch.get_xy()
        tail = np.array([x, y])
        if np.min(np.hypot(*(xy - tail).T)) > 0.02:  # its base lies on the pose
            continue
        direction = xy.mean(axis=0) - tail
        if (
            abs(math.remainder(math.atan2(direction[1], direction[0]) - heading, 2 * math.pi))
            < 0.01
        ):
            return patch
    return None


def check_legend(fig, ax, maze, poses):
    """One legend names every drawn thing; each is drawn where ``poses`` puts it."""
    assert len(fig.legends) == 1
    legend = fig.legends[0]
    assert [t.get_text() for t in legend.get_texts()] == entries(maze)
    region, start, path, end, target = legend.legend_handles

    # Start region: the shaded box over the maze's start region, keyed by its colour.
    (x0, x1), (y0, y1) = maze.start_x, maze.start_y
    boxes = [
        p
        for p in ax.patches
        if isinstance(p, Rectangle) and np.allclose(p.get_bbox().bounds, (x0, y0, x1 - x0, y1 - y0))
    ]
    assert len(boxes) == 1
    assert isinstance(region, Rectangle)
    assert region.get_facecolor() == pytest.approx(boxes[0].get_facecolor())

    # Start and end poses: a marker on the first and last pose and an arrow along its heading.
    for key, pose, colour, marker in (
        (start, poses[0], START_COLOUR, "o"),
        (end, poses[-1], END_COLOUR, "s"),
    ):
        assert isinstance(key, Line2D)
        assert key.get_marker() == marker
        assert to_rgba(key.get_color()) == to_rgba(colour)
        dots = [
            line
            for line in ax.lines
            if line.get_marker() == marker
            and np.allclose(line.get_xydata(), [pose[:2]])
            and to_rgba(line.get_color()) == to_rgba(colour)
        ]
        assert len(dots) == 1
        arrow = arrow_at(ax, pose[0], pose[1], pose[2])
        assert arrow is not None
        assert arrow.get_facecolor() == pytest.approx(to_rgba(colour))

    # The path: one segment per control period, coloured by its time (s).
    (drawn,) = [c for c in ax.collections if isinstance(c, LineCollection)]
    assert len(drawn.get_segments()) == len(poses) - 1
    np.testing.assert_allclose(drawn.get_array(), np.arange(len(poses) - 1) * DT)
    assert isinstance(path, LineCollection)
    assert path.get_cmap().name == drawn.get_cmap().name
    assert len(np.unique(path.to_rgba(path.get_array()), axis=0)) > 1  # a gradient key

    # The target: a ring of the target radius about the target.
    rings = [
        p
        for p in ax.patches
        if isinstance(p, Circle)
        and np.allclose(p.center, maze.target)
        and p.radius == pytest.approx(maze.target_radius)
    ]
    assert len(rings) == 1
    assert isinstance(target, Circle)
    assert target.get_edgecolor() == pytest.approx(to_rgba(TARGET_COLOUR))


@pytest.mark.parametrize("name", ["obstacle", "hexapod"])
def test_run_picture_has_a_legend_of_what_it_draws(name):
    maze = load_named_maze(name)
    poses = rear_first_run(maze)
    fig = run_figure(maze, poses, "a run", dt=DT, episode_time=10.0)
    try:
        (ax,) = [a for a in fig.axes if a.get_label() != "<colorbar>"]
        check_legend(fig, ax, maze, poses)
        # No nominal start arrow competes with the run's own start pose.
        assert sum(isinstance(p, FancyArrow) for p in ax.patches) == 2
    finally:
        plt.close(fig)


def test_replay_picture_has_one_legend_for_all_rows():
    task = MazeTask(MazeTaskSettings(("gaps", "zigzag"), 10.0), "4ws-5")
    n_cycles = task.n_cycles
    pose = np.full((2, n_cycles + 1, 3), np.nan)
    cycles = np.array([n_cycles, 30])
    outcomes = []
    for e, maze in enumerate(task.mazes):
        run = rear_first_run(maze, int(cycles[e]))
        pose[e, : len(run)] = run
        outcomes.append(
            MazeOutcome(
                maze.name, e == 1, float(cycles[e] * DT), 0.5 + e, 1.0, maze.start_pose, 0.1
            )
        )
    result = EpisodeResult(
        np.array([False, True]),
        cycles,
        np.array([1.0, 0.1]),
        np.array([2.0, 2.0]),
        np.array([0.5, 1.5]),
        pose,
    )
    fig = trajectories_figure(task, outcomes, result, title="replay")
    try:
        rows = [a for a in fig.axes if a.get_label() != "<colorbar>"]
        assert len(rows) == 2
        for e, (ax, maze) in enumerate(zip(rows, task.mazes, strict=True)):
            check_legend(fig, ax, maze, pose[e, : cycles[e] + 1])
    finally:
        plt.close(fig)


def test_pictures_are_written(tmp_path):
    maze = load_named_maze("gaps")
    plot_run(maze, rear_first_run(maze), "a run", tmp_path / "run.png")
    assert (tmp_path / "run.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    task = MazeTask(MazeTaskSettings(("gaps",), 10.0), "4ws-5")
    run = rear_first_run(maze, task.n_cycles)
    result = EpisodeResult(
        np.array([False]),
        np.array([task.n_cycles]),
        np.array([1.0]),
        np.array([2.0]),
        np.array([0.5]),
        run[None],
    )
    outcome = MazeOutcome("gaps", False, 10.0, 0.5, 1.0, maze.start_pose, 0.0)
    plot_trajectories(task, [outcome], result, tmp_path / "replay.png")
    assert (tmp_path / "replay.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert matplotlib.get_backend().lower() == "agg"
