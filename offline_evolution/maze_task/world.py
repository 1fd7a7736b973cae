"""Several mazes packed into flat arrays for the compiled episode kernel."""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from sim_bridge.maze import Maze


class MazePack(NamedTuple):
    """Mazes ``0..n-1`` as arrays (numba-friendly).

    Wall boxes of all mazes are stacked in ``boxes``; each maze has a broad-phase grid whose
    candidate lists hold global rows of ``boxes``.
    """

    boxes: np.ndarray  # (total walls, 6)
    grid_origin: np.ndarray  # (n, 2) m
    grid_shape: np.ndarray  # (n, 2) int64 cells along x, y
    grid_cell: float  # m
    cell_base: np.ndarray  # (n,) int64: maze k's cells start at cell_offsets[cell_base[k]]
    cell_offsets: np.ndarray  # (total cells + n,) int64 into ``cell_ids``
    cell_ids: np.ndarray  # int64 global box rows
    all_start: np.ndarray  # (n + 1,) int64: every box row of maze k is all_ids[...]
    all_ids: np.ndarray  # int64
    targets: np.ndarray  # (n, 2) m
    target_radius: np.ndarray  # (n,) m


def pack_mazes(mazes: Sequence[Maze], reach: float, cell: float = 0.2) -> MazePack:
    """Pack ``mazes`` with broad-phase grids for queries reaching ``reach`` metres."""
    boxes, origins, shapes, bases, offsets, ids, all_ids = [], [], [], [], [], [], []
    all_start = [0]
    box_base = 0
    offset_base = 0
    id_base = 0
    for maze in mazes:
        b = maze.boxes
        grid = maze.wall_grid(reach, cell)
        boxes.append(b)
        origins.append(grid.origin)
        shapes.append(grid.shape)
        bases.append(offset_base)
        offsets.append(grid.offsets + id_base)
        ids.append(grid.ids + box_base)
        all_ids.append(np.arange(len(b), dtype=np.int64) + box_base)
        all_start.append(all_start[-1] + len(b))
        offset_base += len(grid.offsets)
        id_base += len(grid.ids)
        box_base += len(b)
    return MazePack(
        boxes=np.concatenate(boxes),
        grid_origin=np.array(origins, dtype=np.float64),
        grid_shape=np.array(shapes, dtype=np.int64),
        grid_cell=float(cell),
        cell_base=np.array(bases, dtype=np.int64),
        cell_offsets=np.concatenate(offsets).astype(np.int64),
        cell_ids=np.concatenate(ids).astype(np.int64),
        all_start=np.array(all_start, dtype=np.int64),
        all_ids=np.concatenate(all_ids).astype(np.int64),
        targets=np.array([m.target for m in mazes], dtype=np.float64),
        target_radius=np.array([m.target_radius for m in mazes], dtype=np.float64),
    )
