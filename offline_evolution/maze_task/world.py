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


class MazePiece(NamedTuple):
    """One maze's share of a :class:`MazePack`, with rows local to the maze.

    Built once per maze (:func:`maze_piece`); :func:`combine_pieces` stacks pieces with
    offsets, so a new set of mazes costs only the pieces of the mazes not seen before.
    """

    boxes: np.ndarray  # (walls, 6)
    grid_origin: np.ndarray  # (2,) m
    grid_shape: tuple[int, int]
    offsets: np.ndarray  # (cells + 1,) int64 into ``ids``
    ids: np.ndarray  # int64 local box rows
    target: tuple[float, float]  # m
    target_radius: float  # m


def maze_piece(maze: Maze, reach: float, cell: float = 0.2) -> MazePiece:
    """``maze``'s walls and broad-phase grid for queries reaching ``reach`` metres."""
    grid = maze.wall_grid(reach, cell)
    return MazePiece(
        maze.boxes,
        np.asarray(grid.origin, dtype=np.float64),
        tuple(int(v) for v in grid.shape),
        np.asarray(grid.offsets, dtype=np.int64),
        np.asarray(grid.ids, dtype=np.int64),
        (float(maze.target[0]), float(maze.target[1])),
        float(maze.target_radius),
    )


def combine_pieces(pieces: Sequence[MazePiece], cell: float = 0.2) -> MazePack:
    """The :class:`MazePack` of mazes ``0..n-1`` whose pieces (same ``cell``) are ``pieces``."""
    boxes, origins, shapes, bases, offsets, ids, all_ids = [], [], [], [], [], [], []
    all_start = [0]
    box_base = 0
    offset_base = 0
    id_base = 0
    for p in pieces:
        n_boxes = len(p.boxes)
        boxes.append(p.boxes)
        origins.append(p.grid_origin)
        shapes.append(p.grid_shape)
        bases.append(offset_base)
        offsets.append(p.offsets + id_base)
        ids.append(p.ids + box_base)
        all_ids.append(np.arange(n_boxes, dtype=np.int64) + box_base)
        all_start.append(all_start[-1] + n_boxes)
        offset_base += len(p.offsets)
        id_base += len(p.ids)
        box_base += n_boxes
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
        targets=np.array([p.target for p in pieces], dtype=np.float64),
        target_radius=np.array([p.target_radius for p in pieces], dtype=np.float64),
    )


def pack_mazes(mazes: Sequence[Maze], reach: float, cell: float = 0.2) -> MazePack:
    """Pack ``mazes`` with broad-phase grids for queries reaching ``reach`` metres."""
    return combine_pieces([maze_piece(m, reach, cell) for m in mazes], cell)
