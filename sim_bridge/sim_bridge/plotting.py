"""Shared plotting set-up: a headless backend and atomic, compact PNG output."""

from __future__ import annotations

import os

import matplotlib

matplotlib.use("Agg")  # no display on robots, CI or servers

import matplotlib.pyplot as plt
from PIL import Image

from evorbc_ros.atomic_io import atomic_path

#: Colours of a PNG written by :func:`save_figure`. The figures are line plots and maze
#: drawings in a few colours plus their anti-aliasing: 64 palette colours look the same
#: as 24-bit RGB (a colour bar shows steps of 1/64 of its range) and take about a quarter
#: of the bytes; 256 took a third (docs/results/README.md, "Figures").
PALETTE_COLOURS = 64
#: dpi of the 16-inch-wide figures (a grid of 50 mazes, a grid of example repertoires):
#: 1440 px wide reads as well as 2400 on a page, in a third of the bytes (issue 40).
FIGURE_DPI = 90


def shrink_png(path: str | os.PathLike) -> None:
    """Rewrite the PNG at ``path`` in place with :data:`PALETTE_COLOURS` colours (atomically)."""
    with Image.open(path) as im:
        small = im.convert("RGB").quantize(PALETTE_COLOURS)
    with atomic_path(path) as tmp:
        small.save(tmp, format="png", optimize=True)


def save_figure(fig, path: str | os.PathLike, dpi: int = 150) -> None:
    """Save ``fig`` to ``path`` atomically and close it (a PNG with a palette)."""
    kind = str(path).rsplit(".", 1)[-1].lower() or "png"
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format=kind)
        if kind == "png":
            shrink_png(tmp)
    plt.close(fig)


__all__ = ["FIGURE_DPI", "plt", "save_figure", "shrink_png"]
