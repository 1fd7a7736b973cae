"""Fitness curves of arbitrator evolution (paper Fig. 9 top, Fig. 17)."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence

import numpy as np

from sim_bridge.plotting import plt, save_figure


def _column(history, key: str) -> np.ndarray:
    return np.array([h[key] if isinstance(h, dict) else getattr(h, key) for h in history])


def plot_fitness_history(history: Sequence, path: str | os.PathLike, title: str = "") -> None:
    """One run: best so far, best and mean of each generation (fitness >= 1: reached)."""
    gen = _column(history, "generation") + 1
    fig, ax = plt.subplots(figsize=(7.0, 4.0), layout="constrained")
    ax.plot(gen, _column(history, "best_so_far"), lw=2.0, label="best so far")
    ax.plot(gen, _column(history, "best"), lw=0.8, alpha=0.7, label="best of generation")
    ax.plot(gen, _column(history, "mean"), lw=0.8, alpha=0.7, label="mean of generation")
    ax.axhline(1.0, color="0.6", ls="--", lw=0.8)
    ax.text(
        gen[0],
        1.01,
        "target reached in every maze above this line",
        fontsize=7,
        color="0.4",
        va="bottom",
    )
    ax.set_xlabel("generation")
    ax.set_ylabel("fitness (eq. 5, mean over mazes)")
    ax.set_title(title)
    ax.legend(loc="lower right", fontsize=8)
    save_figure(fig, path)


def plot_fitness_comparison(
    groups: Mapping[str, Sequence[Sequence[float]]], path: str | os.PathLike, title: str = ""
) -> None:
    """Several methods, several runs each: mean best-so-far with the min-max band."""
    fig, ax = plt.subplots(figsize=(7.0, 4.0), layout="constrained")
    for label, runs in groups.items():
        length = min(len(r) for r in runs)
        curves = np.array([np.maximum.accumulate(np.asarray(r[:length])) for r in runs])
        gen = np.arange(1, length + 1)
        (line,) = ax.plot(
            gen,
            curves.mean(axis=0),
            lw=1.8,
            label=f"{label} ({len(runs)} run{'' if len(runs) == 1 else 's'})",
        )
        ax.fill_between(
            gen, curves.min(axis=0), curves.max(axis=0), color=line.get_color(), alpha=0.2, lw=0
        )
    ax.axhline(1.0, color="0.6", ls="--", lw=0.8)
    ax.set_xlabel("generation")
    ax.set_ylabel("highest fitness so far")
    ax.set_title(title)
    ax.legend(loc="lower right", fontsize=8)
    save_figure(fig, path)
