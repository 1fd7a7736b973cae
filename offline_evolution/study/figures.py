"""The paper's study figures from a results folder (Fig. 8-14 and 16-18 styles).

* fitness curves: the highest fitness so far, mean over runs with the min-max band (Fig. 9
  top, Fig. 17); EvoRBC's curves start after the generations its repertoire cost (equal
  budget), as the paper draws them;
* boxplots of each run's highest fitness (Fig. 9 bottom, Fig. 11);
* example repertoires, one per setting (Fig. 8, 10, 13);
* heatmaps of repertoire size and maze fitness over bin size and evaluation time (Fig. 12);
* aggregated mapping outputs and chosen primitives of the best controllers (Fig. 14, 18).
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence

import numpy as np
from matplotlib.colors import LogNorm

from offline_evolution.plots.repertoire import draw_repertoire, quality_norm
from offline_evolution.study.results import (
    CHOSEN_BINS,
    OUTPUT_BINS,
    SelectionCounts,
    SettingResults,
)
from sim_bridge.plotting import FIGURE_DPI, plt, save_figure


def setting_label(values: dict, keys: Sequence[str]) -> str:
    """``4ws-5, evorbc`` from a setting's grid keys (bins in cm, times in s)."""
    parts = []
    for k in keys:
        v = values.get(k)
        if k == "bin_size":
            parts.append(f"{v * 100:g} cm")
        elif k == "eval_time":
            parts.append(f"{v:g} s")
        else:
            parts.append(str(v))
    return ", ".join(parts)


def fitness_curves(
    settings: list[SettingResults],
    panel_key: str | None,
    line_keys: Sequence[str],
    path: str | os.PathLike,
    shift: dict[str, int] | None = None,
    title: str = "",
) -> None:
    """Mean highest-fitness-so-far curves with min-max bands.

    Args:
        panel_key: one panel per value of this key (None: one panel).
        line_keys: the keys that name a curve within a panel.
        shift: generations to start a curve at, by approach (EvoRBC's repertoire cost).
    """
    panels = _ordered({s.values.get(panel_key) for s in settings}) if panel_key else [None]
    cols = min(4, len(panels))
    rows = math.ceil(len(panels) / cols)
    fig, axes = plt.subplots(
        rows, cols, figsize=(4.2 * cols, 3.4 * rows), squeeze=False, sharey=True,
        layout="constrained",
    )  # fmt: skip
    for ax, panel in zip(axes.flat, panels, strict=False):
        for s in settings:
            if (panel_key and s.values.get(panel_key) != panel) or not s.runs:
                continue
            curves = [r.best_so_far for r in s.runs]
            length = min(len(c) for c in curves)
            c = np.array([np.maximum.accumulate(k[:length]) for k in curves])
            start = (shift or {}).get(s.values.get("approach", "evorbc"), 0)
            gen = start + np.arange(1, length + 1)
            label = f"{setting_label(s.values, line_keys)} ({len(curves)})"
            (line,) = ax.plot(gen, c.mean(axis=0), lw=1.6, label=label)
            ax.fill_between(gen, c.min(axis=0), c.max(axis=0), color=line.get_color(), alpha=0.18)
            if start:
                ax.plot([0, start], [0, 0], color=line.get_color(), lw=1.6)
        ax.axhline(1.0, color="0.6", ls="--", lw=0.8)
        ax.set_title(str(panel) if panel is not None else title, fontsize=10)
        ax.set_xlabel("generation")
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7, loc="lower right")
    for ax in axes.flat[len(panels) :]:
        ax.set_visible(False)
    for ax in axes[:, 0]:
        ax.set_ylabel("highest fitness so far")
    if panel_key and title:
        fig.suptitle(title, fontsize=11)
    save_figure(fig, path)


def boxplots(
    settings: list[SettingResults], keys: Sequence[str], path: str | os.PathLike, title: str = ""
) -> None:
    """One box of the runs' highest fitness per setting (whiskers 1.5 IQR, dots outliers)."""
    shown = [s for s in settings if s.runs]
    fig, ax = plt.subplots(figsize=(max(4.0, 0.9 * len(shown) + 1.5), 3.8), layout="constrained")
    ax.boxplot([s.best for s in shown], whis=1.5)
    ax.set_xticks(range(1, len(shown) + 1))
    ax.set_xticklabels(
        [setting_label(s.values, keys).replace(", ", "\n") for s in shown], fontsize=8
    )
    ax.axhline(1.0, color="0.6", ls="--", lw=0.8)
    ax.set_ylabel("highest fitness (eq. 5)")
    ax.set_title(title, fontsize=10)
    save_figure(fig, path)


def example_repertoires(
    settings: list[SettingResults],
    keys: Sequence[str],
    path: str | os.PathLike,
    grid: tuple[str, str] | None = None,
) -> None:
    """The example repertoire (first finished run's) of each EvoRBC setting, one colour scale.

    Args:
        grid: ``(row_key, column_key)`` to lay the panels out as a table (Fig. 13),
            else one row.
    """
    shown = [(s, s.example) for s in settings if s.runs and s.example is not None]
    if not shown:
        return
    if grid:
        rows_v = _ordered({s.values[grid[0]] for s, _ in shown})
        cols_v = _ordered({s.values[grid[1]] for s, _ in shown})
        place = {
            (rows_v.index(s.values[grid[0]]), cols_v.index(s.values[grid[1]])): (s, r)
            for s, r in shown
        }
        nr, nc = len(rows_v), len(cols_v)
    else:
        place = {(0, k): item for k, item in enumerate(shown)}
        nr, nc = 1, len(shown)
    fig, axes = plt.subplots(
        nr, nc, figsize=(2.6 * nc + 1.0, 2.7 * nr + 0.4), squeeze=False, layout="constrained"
    )
    norm = quality_norm(shown[0][1])
    for (i, j), ax in np.ndenumerate(axes):
        if (i, j) not in place:
            ax.set_visible(False)
            continue
        s, r = place[(i, j)]
        draw_repertoire(ax, r, norm)
        ax.set_title(f"{setting_label(s.values, keys)}\n{len(r)} primitives", fontsize=8)
        ax.tick_params(labelsize=6)
    fig.colorbar(
        plt.cm.ScalarMappable(norm=norm, cmap="viridis"),
        ax=list(axes.flat),
        shrink=0.6,
        label=f"quality ({shown[0][1].metric})",
    )
    save_figure(fig, path, dpi=FIGURE_DPI)


def bin_time_grid(
    settings: list[SettingResults],
) -> tuple[list[float], list[float], np.ndarray, np.ndarray]:
    """The cells of Fig. 12.

    Returns:
        ``bins`` (m, ascending), ``times`` (s, ascending), and per cell ``(len(times),
        len(bins))`` the mean repertoire size and the mean highest fitness of its runs;
        NaN for a cell left out of the grid or without finished runs.
    """
    bins = _ordered({s.values["bin_size"] for s in settings})
    times = _ordered({s.values["eval_time"] for s in settings})
    size = np.full((len(times), len(bins)), np.nan)
    fit = np.full((len(times), len(bins)), np.nan)
    for s in settings:
        if s.runs:
            i, j = times.index(s.values["eval_time"]), bins.index(s.values["bin_size"])
            size[i, j] = np.nanmean(s.summary("repertoire.count"))
            fit[i, j] = s.best.mean()
    return bins, times, size, fit


def bin_time_heatmaps(settings: list[SettingResults], path: str | os.PathLike) -> None:
    """Fig. 12: mean repertoire size (left) and mean highest fitness (right) per cell."""
    bins, times, size, fit = bin_time_grid(settings)
    fig, axes = plt.subplots(1, 2, figsize=(11.0, 4.4), layout="constrained")
    for ax, data, label, fmt, norm in (
        (axes[0], size, "primitives in the repertoire", "{:.0f}", LogNorm()),
        (axes[1], fit, "highest fitness in the maze task", "{:.2f}", None),
    ):
        im = ax.imshow(np.ma.masked_invalid(data), origin="lower", cmap="viridis", norm=norm)
        for (i, j), v in np.ndenumerate(data):
            if not np.isnan(v):
                ax.text(j, i, fmt.format(v), ha="center", va="center", fontsize=7, color="w")
        ax.set_xticks(range(len(bins)), [f"{b * 100:g}" for b in bins])
        ax.set_yticks(range(len(times)), [f"{t:g}" for t in times])
        ax.set_xlabel("bin size (cm)")
        ax.set_ylabel("evaluation time (s)")
        ax.set_title(f"mean {label}", fontsize=10)
        fig.colorbar(im, ax=ax, shrink=0.8)
    save_figure(fig, path)


def selection_heatmaps(panels: list[tuple[str, SelectionCounts]], path: str | os.PathLike) -> None:
    """Fig. 14 rows 2-3: where the mapping outputs fell and which primitives ran.

    Args:
        panels: per setting its label and its counts, pooled over the runs' controllers.
    """
    fig, axes = plt.subplots(
        2, len(panels), figsize=(4.0 * len(panels), 7.6), squeeze=False, layout="constrained"
    )
    for j, (label, counts) in enumerate(panels):
        ax = axes[0, j]
        edges = np.linspace(0.0, 1.0, OUTPUT_BINS + 1)
        _counts_mesh(ax, edges, counts.outputs, "Blues")
        ax.set_aspect("equal")
        ax.set_xlabel("m1")
        ax.set_ylabel("m2")
        ax.set_title(f"{label}: mapping outputs", fontsize=10)
        ax = axes[1, j]
        edges = np.linspace(-counts.reach, counts.reach, CHOSEN_BINS + 1)
        _counts_mesh(ax, edges, counts.chosen, "magma_r")
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.set_title(f"{label}: chosen primitives' displacement", fontsize=10)
    save_figure(fig, path)


def _counts_mesh(ax, edges: np.ndarray, counts: np.ndarray, cmap: str) -> None:
    """A 2-D histogram from its ``(bins, bins)`` counts (first axis x).

    Drawn as ``hist2d`` draws it: log colour scale, empty cells blank.
    """
    if counts.sum() > 0:
        ax.pcolormesh(edges, edges, counts.T.astype(float), cmap=cmap, norm=LogNorm())


def _ordered(values) -> list:
    return sorted(values, key=lambda v: (0, v) if isinstance(v, (int, float)) else (1, str(v)))
