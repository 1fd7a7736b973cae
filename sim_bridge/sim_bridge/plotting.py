"""Shared plotting set-up: a headless backend and atomic PNG output."""

from __future__ import annotations

import os

import matplotlib

matplotlib.use("Agg")  # no display on robots, CI or servers

import matplotlib.pyplot as plt

from evorbc_ros.atomic_io import atomic_path


def save_figure(fig, path: str | os.PathLike, dpi: int = 150) -> None:
    """Save ``fig`` to ``path`` atomically and close it."""
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format=str(path).rsplit(".", 1)[-1].lower() or "png")
    plt.close(fig)


__all__ = ["plt", "save_figure"]
