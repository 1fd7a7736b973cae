"""Compiled 2D geometry of maze walls: distances, ray casts and a broad-phase grid.

A wall is a box: a rectangle of the wall segment's length and the wall's thickness, centred
on the segment (as the PyBullet world builds it). Boxes are rows of a ``(m, 6)`` float64
array ``(cx, cy, ex, ey, half_length, half_thickness)``: the centre (m), the unit vector
along the wall, and the half extents (m), all in the world frame.

Candidates: every query takes an int array of the box rows to consider, so that callers can
pass all walls or only the ones the :class:`WallGrid` lists near the query point.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np

CX, CY, EX, EY, HALF_LENGTH, HALF_THICKNESS = range(6)


def wall_boxes(segments: np.ndarray, thickness: float) -> np.ndarray:
    """Boxes of walls given as ``(m, 4)`` segments ``(x1, y1, x2, y2)`` and one thickness."""
    seg = np.asarray(segments, dtype=np.float64).reshape(-1, 4)
    d = seg[:, 2:4] - seg[:, 0:2]
    length = np.hypot(d[:, 0], d[:, 1])
    boxes = np.empty((len(seg), 6))
    boxes[:, 0:2] = 0.5 * (seg[:, 0:2] + seg[:, 2:4])
    boxes[:, 2:4] = d / length[:, None]
    boxes[:, HALF_LENGTH] = 0.5 * length
    boxes[:, HALF_THICKNESS] = 0.5 * thickness
    return boxes


@nb.njit(cache=True)
def box_distance(px, py, boxes, k):
    """Distance (m) from point ``(px, py)`` to box ``k``; 0 inside it."""
    qx = px - boxes[k, CX]
    qy = py - boxes[k, CY]
    ex = boxes[k, EX]
    ey = boxes[k, EY]
    du = abs(qx * ex + qy * ey) - boxes[k, HALF_LENGTH]
    dv = abs(-qx * ey + qy * ex) - boxes[k, HALF_THICKNESS]
    du = max(du, 0.0)
    dv = max(dv, 0.0)
    return math.sqrt(du * du + dv * dv)


@nb.njit(cache=True)
def clearance(px, py, boxes, candidates):
    """Smallest distance (m) from ``(px, py)`` to the candidate boxes; inf if none."""
    best = np.inf
    for j in range(candidates.shape[0]):
        d = box_distance(px, py, boxes, candidates[j])
        if d < best:
            best = d
    return best


@nb.njit(cache=True)
def _slab(o, d, half):
    """Entry and exit parameters of the line o + t d through the slab |u| <= half."""
    if d == 0.0:
        if abs(o) > half:
            return np.inf, -np.inf  # parallel and outside: empty
        return -np.inf, np.inf
    t1 = (-half - o) / d
    t2 = (half - o) / d
    if t1 > t2:
        return t2, t1
    return t1, t2


@nb.njit(cache=True)
def ray_box(ox, oy, dx, dy, boxes, k):
    """Distance along the unit ray ``(ox, oy) + t (dx, dy)``, t >= 0, to box ``k``.

    Returns 0 if the origin is inside the box and inf if the ray misses. A ray that only
    touches an edge or a corner counts as a hit.
    """
    qx = ox - boxes[k, CX]
    qy = oy - boxes[k, CY]
    ex = boxes[k, EX]
    ey = boxes[k, EY]
    # Ray in the box frame: u along the wall, v across it.
    u_in, u_out = _slab(qx * ex + qy * ey, dx * ex + dy * ey, boxes[k, HALF_LENGTH])
    v_in, v_out = _slab(-qx * ey + qy * ex, -dx * ey + dy * ex, boxes[k, HALF_THICKNESS])
    t_in = max(u_in, v_in)
    t_out = min(u_out, v_out)
    if t_in > t_out or t_out < 0.0:
        return np.inf
    return max(t_in, 0.0)


@nb.njit(cache=True)
def cast_ray_dir(ox, oy, dx, dy, max_range, boxes, candidates):
    """Distance (m) to the nearest candidate box along a unit ray, capped at ``max_range``.

    The ray is ``(ox, oy) + t (dx, dy)`` with ``(dx, dy)`` of length 1 (world frame).
    """
    best = max_range
    for j in range(candidates.shape[0]):
        d = ray_box(ox, oy, dx, dy, boxes, candidates[j])
        if d < best:
            best = d
    return best


@nb.njit(cache=True)
def cast_ray(ox, oy, angle, max_range, boxes, candidates):
    """Distance (m) along a ray to the nearest candidate box, capped at ``max_range``.

    The ray starts at ``(ox, oy)`` and points along ``angle`` (rad, world frame).
    """
    return cast_ray_dir(ox, oy, math.cos(angle), math.sin(angle), max_range, boxes, candidates)


@dataclass(frozen=True)
class WallGrid:
    """Broad phase: for each square cell, the walls within ``reach`` of any point in it.

    Queries at a point use the list of its cell, a superset of the walls that a ray of
    length ``reach`` (or a footprint of that radius) from the point can touch. Points
    outside the grid get every wall.
    """

    origin: tuple[float, float]  # m, lower-left corner of cell (0, 0)
    cell: float  # m, side of a cell
    shape: tuple[int, int]  # cells along x, y
    offsets: np.ndarray  # (nx * ny + 1,) int64, CSR row pointers into ``ids``
    ids: np.ndarray  # int64 wall rows
    all_ids: np.ndarray  # int64, every wall row (for points outside the grid)

    @classmethod
    def build(cls, boxes: np.ndarray, reach: float, cell: float = 0.2) -> WallGrid:
        """Index ``boxes`` for queries reaching ``reach`` metres from the query point."""
        corners = box_corners(boxes)
        lo = corners.min(axis=(0, 1)) - reach - cell
        hi = corners.max(axis=(0, 1)) + reach + cell
        nx, ny = (int(v) for v in np.ceil((hi - lo) / cell))
        # Conservative: a wall is listed if it is within reach of the cell's centre plus the
        # cell's half diagonal, so it is within reach of no point of the cell otherwise.
        limit = reach + cell * math.sqrt(0.5)
        # Each wall visits only the cells of its own box widened by the limit: building
        # costs the size of the index, not walls x cells (a 2,000-wall maze 800 m across
        # has 16 M cells; testing every cell against every wall took 286 s and 7.7 GB).
        counts = _grid_counts(boxes, lo[0], lo[1], cell, nx, ny, limit)
        offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        ids = _grid_ids(boxes, lo[0], lo[1], cell, nx, ny, limit, offsets)
        return cls(
            (float(lo[0]), float(lo[1])),
            float(cell),
            (nx, ny),
            offsets,
            ids,
            np.arange(len(boxes), dtype=np.int64),
        )

    def candidates(self, x: float, y: float) -> np.ndarray:
        """Wall rows to test for a query at ``(x, y)``."""
        return grid_candidates(
            x,
            y,
            self.origin[0],
            self.origin[1],
            self.cell,
            self.shape[0],
            self.shape[1],
            self.offsets,
            self.ids,
            self.all_ids,
        )


@nb.njit(cache=True)
def _near_cells(boxes, k, x0, y0, cell, nx, ny, limit):
    """Inclusive cell ranges ``(i0, i1, j0, j1)`` that may lie within ``limit`` m of box ``k``.

    They are the cells of the box's bounding box widened by ``limit`` (numba's ``floor``
    and ``ceil`` give integers).
    """
    hx = abs(boxes[k, EX]) * boxes[k, HALF_LENGTH] + abs(boxes[k, EY]) * boxes[k, HALF_THICKNESS]
    hy = abs(boxes[k, EY]) * boxes[k, HALF_LENGTH] + abs(boxes[k, EX]) * boxes[k, HALF_THICKNESS]
    i0 = max(math.floor((boxes[k, CX] - hx - limit - x0) / cell - 0.5), 0)
    i1 = min(math.ceil((boxes[k, CX] + hx + limit - x0) / cell - 0.5), nx - 1)
    j0 = max(math.floor((boxes[k, CY] - hy - limit - y0) / cell - 0.5), 0)
    j1 = min(math.ceil((boxes[k, CY] + hy + limit - y0) / cell - 0.5), ny - 1)
    return i0, i1, j0, j1


@nb.njit(cache=True)
def _is_near(boxes, k, i, j, x0, y0, cell, limit):
    """Whether box ``k`` is within ``limit`` m of the centre of cell ``(i, j)``.

    The same arithmetic as :func:`box_distances` (``hypot``), so that a wall at exactly
    the limit is listed as it was when every cell was tested against every wall.
    """
    qx = x0 + (i + 0.5) * cell - boxes[k, CX]
    qy = y0 + (j + 0.5) * cell - boxes[k, CY]
    du = max(abs(qx * boxes[k, EX] + qy * boxes[k, EY]) - boxes[k, HALF_LENGTH], 0.0)
    dv = max(abs(-qx * boxes[k, EY] + qy * boxes[k, EX]) - boxes[k, HALF_THICKNESS], 0.0)
    return math.hypot(du, dv) <= limit


@nb.njit(cache=True)
def _grid_counts(boxes, x0, y0, cell, nx, ny, limit):
    """Number of walls listed in each cell (cell ``i * ny + j``)."""
    counts = np.zeros(nx * ny, np.int64)
    for k in range(boxes.shape[0]):
        i0, i1, j0, j1 = _near_cells(boxes, k, x0, y0, cell, nx, ny, limit)
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                if _is_near(boxes, k, i, j, x0, y0, cell, limit):
                    counts[i * ny + j] += 1
    return counts


@nb.njit(cache=True)
def _grid_ids(boxes, x0, y0, cell, nx, ny, limit, offsets):
    """The walls of each cell, in wall order, at ``ids[offsets[c]:offsets[c + 1]]``."""
    ids = np.empty(offsets[-1], np.int64)
    fill = offsets[:-1].copy()
    for k in range(boxes.shape[0]):
        i0, i1, j0, j1 = _near_cells(boxes, k, x0, y0, cell, nx, ny, limit)
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                if _is_near(boxes, k, i, j, x0, y0, cell, limit):
                    c = i * ny + j
                    ids[fill[c]] = k
                    fill[c] += 1
    return ids


@nb.njit(cache=True)
def grid_candidates(x, y, x0, y0, cell, nx, ny, offsets, ids, all_ids):
    """Compiled :meth:`WallGrid.candidates` (a view into ``ids``)."""
    i = math.floor((x - x0) / cell)
    j = math.floor((y - y0) / cell)
    if i < 0 or j < 0 or i >= nx or j >= ny:
        return all_ids
    c = i * ny + j
    return ids[offsets[c] : offsets[c + 1]]


def box_corners(boxes: np.ndarray) -> np.ndarray:
    """``(m, 4, 2)`` corners of each box, m."""
    c = boxes[:, None, 0:2]
    e = boxes[:, None, 2:4]
    n = np.stack([-boxes[:, 3], boxes[:, 2]], axis=1)[:, None, :]
    su = np.array([1, 1, -1, -1])[None, :, None] * boxes[:, None, None, HALF_LENGTH]
    sv = np.array([1, -1, 1, -1])[None, :, None] * boxes[:, None, None, HALF_THICKNESS]
    return c + su * e + sv * n


def box_distances(px: np.ndarray, py: np.ndarray, box: np.ndarray) -> np.ndarray:
    """Vectorised :func:`box_distance`: distances (m) of many points to one box row."""
    qx = px - box[CX]
    qy = py - box[CY]
    du = np.maximum(np.abs(qx * box[EX] + qy * box[EY]) - box[HALF_LENGTH], 0.0)
    dv = np.maximum(np.abs(-qx * box[EY] + qy * box[EX]) - box[HALF_THICKNESS], 0.0)
    return np.hypot(du, dv)


def planar_quaternion(h: float) -> tuple[float, float]:
    """``(z, w)`` of the orientation quaternion of heading ``h`` (rad about z; x = y = 0).

    What the bridge publishes in ``odom``; numba compiles it to the same bits, so the
    offline kernel's adapting controller reads the yaw the arbitrator node reads.
    """
    return math.sin(0.5 * h), math.cos(0.5 * h)
