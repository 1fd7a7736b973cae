"""Pictures of onboard adaptation (docs/design/adaptation.md).

:func:`paths_figure`: a damaged robot's paths in one maze, the same starts and worlds
without and with adaptation. :func:`outcome_map_figure`: an adapted episode's corrected
outcome map against the recorded one, in the behaviour space (the primitive's ``(dx, dy)``
over ``T`` in its start frame, x forward, y left). :func:`draw_pictures` chooses the maze
and the episode and saves both (``bench/adaptation_heldout.py --pictures DIR``).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from sim_bridge.maze_plot import draw_maze
from sim_bridge.plotting import FIGURE_DPI, plt, save_figure

from .suite import MISSED_COLOUR, REACHED_COLOUR

PATHS_PNG = "adaptation-paths.png"
MAP_PNG = "adaptation-outcome-map.png"
ERROR_PNG = "adaptation-error-over-time.png"


def paths_figure(maze, off_paths, off_reached, on_paths, on_reached, title: str = ""):
    """Two panels of ``maze``: the episodes' paths without and with adaptation.

    Args:
        off_paths, on_paths: per episode ``(k, 2+)`` poses (m, maze frame).
        off_reached, on_reached: per episode, reached the target (green) or not (orange).
    """
    w, h = maze.size()
    wide = w > 2 * h  # a long maze: one panel above the other
    rows, cols = (2, 1) if wide else (1, 2)
    fig, axes = plt.subplots(rows, cols, figsize=(9.0, rows * 9.0 / cols * h / w + 1.0),
                             layout="constrained")  # fmt: skip
    axes = axes.ravel()
    for ax, paths, reached, name in (
        (axes[0], off_paths, off_reached, "without adaptation"),
        (axes[1], on_paths, on_reached, "with adaptation"),
    ):
        draw_maze(ax, maze, nominal_start=False)
        for pose, ok in zip(paths, reached, strict=True):
            ax.plot(pose[:, 0], pose[:, 1], color=REACHED_COLOUR if ok else MISSED_COLOUR,
                    linewidth=0.7, alpha=0.8, zorder=4)  # fmt: skip
            ax.plot(pose[0, 0], pose[0, 1], "k.", markersize=3, zorder=5)
        ax.set_title(f"{name}: {sum(reached)}/{len(reached)} reached", fontsize=9)
        ax.tick_params(labelsize=6)
    if title:
        fig.suptitle(title, fontsize=9)
    return fig


def outcome_map_figure(recorded: np.ndarray, corrected: np.ndarray, observed, title: str = ""):
    """The behaviour space: each primitive's recorded ``(dx, dy)``, arrowed to its corrected one.

    ``recorded``, ``corrected``: ``(n, 3)`` outcomes (m, m, rad over ``T``); ``observed``:
    indices of the primitives whose observations the model holds (circled).
    """
    fig, ax = plt.subplots(figsize=(6.0, 5.2), layout="constrained")
    ax.plot(recorded[:, 0], recorded[:, 1], ".", color="0.6", markersize=4,
            label="recorded outcome")  # fmt: skip
    d = corrected[:, :2] - recorded[:, :2]
    moved = np.hypot(d[:, 0], d[:, 1]) > 1e-6
    ax.quiver(recorded[moved, 0], recorded[moved, 1], d[moved, 0], d[moved, 1],
              angles="xy", scale_units="xy", scale=1.0, width=0.003, color="tab:orange",
              label="correction (to the corrected outcome)")  # fmt: skip
    seen = np.asarray(sorted(observed), dtype=np.int64)
    if len(seen):
        ax.plot(corrected[seen, 0], corrected[seen, 1], "o", mfc="none", color="tab:blue",
                markersize=6, label=f"observed primitives ({len(seen)})")  # fmt: skip
    ax.set_xlabel("dx over T (m, forward)")
    ax.set_ylabel("dy over T (m, left)")
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    if title:
        ax.set_title(title, fontsize=8)
    return fig


def error_over_time_figure(windows, sets: list[dict], intact: list[float] | None):
    """Per set, the execution error over elapsed time without and with adaptation.

    Args:
        windows: ``((t0, t1), ...)`` s, the windows the errors are means over.
        sets: per set ``{"set": name, "execution_error": {"off": [...], "on": [...],
            "best": [...]}}`` (one value per window, share of the repertoire's extent).
        intact: the intact robot's error without adaptation per window, drawn in each
            panel (None: not measured).
    """
    mid = [0.5 * (a + b) for a, b in windows]
    fig, axes = plt.subplots(1, len(sets), figsize=(2.4 * len(sets), 2.6), sharey=True,
                             layout="constrained", squeeze=False)  # fmt: skip
    for ax, r in zip(axes[0], sets, strict=True):
        x = r["execution_error"]
        ax.plot(mid, x["off"], "o-", color="tab:orange", markersize=3, label="without")
        ax.plot(mid, x["on"], "o-", color="tab:blue", markersize=3, label="with adaptation")
        ax.plot(mid, x["best"], ":", color="tab:green", label="best primitive")
        if intact is not None:
            ax.plot(mid, intact, "--", color="0.4", label="intact, without")
        ax.set_title(r["set"], fontsize=8)
        ax.set_xlabel("elapsed time (s)", fontsize=7)
        ax.set_xscale("log")
        ax.tick_params(labelsize=6)
        ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel("execution error (share of extent)", fontsize=7)
    axes[0, 0].legend(fontsize=6)
    return fig


def save_error_over_time(windows, sets: list[dict], folder: str | os.PathLike) -> Path:
    """Save :func:`error_over_time_figure` of the damaged sets as :data:`ERROR_PNG`."""
    intact = next((r["execution_error"]["off"] for r in sets if r["set"] == "none"), None)
    path = Path(folder) / ERROR_PNG
    damaged = [r for r in sets if r["set"] != "none"]
    save_figure(error_over_time_figure(windows, damaged, intact), path, dpi=FIGURE_DPI)
    return path


def draw_pictures(runs, replays, folder: str | os.PathLike) -> list[Path]:
    """Save :data:`PATHS_PNG` and :data:`MAP_PNG` in ``folder`` from an adapted evaluation.

    The maze is the one where adaptation reached the most more targets; the outcome map is
    that maze's episode reached only with adaptation that took the most observations (or
    its most observed episode).

    Args:
        runs: :class:`~offline_evolution.runs.evaluate.SuiteRuns` with ``adapted``.
        replays: per adapted episode, its
            :class:`~offline_evolution.maze_task.adaptation_replay.ReplayedModel`.
    """
    from evorbc_ros.adaptation import outcome_table

    off, on = runs.suite, runs.adapted
    names = [m.name for m in runs.task.mazes]

    def gain(name):
        idx = [k for k, e in enumerate(off.episodes) if e.maze == name]
        return sum(on.episodes[k].reached for k in idx) - sum(off.episodes[k].reached for k in idx)

    best = max(names, key=gain)  # first of the largest gains
    maze = runs.task.mazes[names.index(best)]
    idx = [k for k, e in enumerate(off.episodes) if e.maze == best]
    folder = Path(folder)
    paths = folder / PATHS_PNG
    fig = paths_figure(
        maze,
        [off.paths[k] for k in idx],
        [off.episodes[k].reached for k in idx],
        [on.paths[k] for k in idx],
        [on.episodes[k].reached for k in idx],
        f"shipped 4ws-5 controller, {runs.perturbation.name}, held-out maze {best}, "
        f"{len(idx)} starts (each its own damage)",
    )
    save_figure(fig, paths, dpi=FIGURE_DPI)
    only = [k for k in idx if on.episodes[k].reached and not off.episodes[k].reached] or idx
    k = max(only, key=lambda j: (replays[j].observations[-1], -j))
    recorded = outcome_table(runs.repertoire.behaviour, runs.repertoire.heading)
    observed = replays[k].in_model
    outcome_map = folder / MAP_PNG
    fig = outcome_map_figure(
        recorded,
        replays[k].corrected,
        observed,
        f"{best}, episode {k - idx[0]}: {on.episodes[k].damage}; "
        f"{replays[k].observations[-1]} observations, {on.episodes[k].time:.1f} s",
    )
    save_figure(fig, outcome_map, dpi=FIGURE_DPI)
    return [paths, outcome_map]
