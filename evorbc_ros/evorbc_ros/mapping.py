"""Mapping functions and primitive choice (paper eq. 4, 7-9; docs/design.md section 7).

The arbitrator outputs ``m = (m1, m2)`` in [0, 1]^2. A mapping function turns them into a
point of the behaviour space (m, start frame: x forward, y left) and the primitive whose
behaviour is nearest that point runs next.

* ``cartesian``: ``(m1 (xmax - xmin) + xmin, m2 (ymax - ymin) + ymin)`` over the bounds
  of the repertoire's behaviours.
* ``polar``: ``r = tau (2 m1 - 1)``, ``alpha = pi (m2 - 1/2)`` from the forward axis,
  point ``r (cos alpha, sin alpha)``, with ``tau`` the largest displacement in the
  repertoire. ``m2 = 0.5`` is straight ahead; ``m1 < 0.5`` goes backward.

Primitive lookup is O(1): when the repertoire is loaded, a grid over the mapping's domain
is filled with the index of each cell centre's nearest primitive (ties to the lower index),
so a query only finds its cell. The grid is exactly what brute force over every primitive
gives, built by pruning primitives that cannot be nearest to a block of cells
(:func:`nearest_on_grid`), so it takes seconds, not minutes, for 200,000 primitives.

A network output that is not finite (NaN or infinite), or a point that is not, chooses
no primitive (:data:`NO_PRIMITIVE`): the robot stops for that cycle (docs/design.md section 7).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

MAPPINGS = ("polar", "cartesian")
#: The "primitive index" of a cycle in which the network chose none (non-finite output).
NO_PRIMITIVE = -1
#: Cells per axis of the lookup grid (256 x 256: about 3 mm cells for a 0.36 m repertoire).
DEFAULT_GRID_CELLS = 256


@dataclass(frozen=True)
class MappingFunction:
    """A mapping from arbitrator outputs to a point in the behaviour space."""

    name: str
    # polar: (tau, 0, 0, 0); cartesian: (xmin, xmax, ymin, ymax). Floats, m.
    params: tuple[float, float, float, float]

    @classmethod
    def for_behaviours(cls, name: str, behaviour: np.ndarray) -> MappingFunction:
        """The mapping ``name`` scaled to a repertoire's ``(n, 2)`` behaviours."""
        b = np.asarray(behaviour, dtype=np.float64)
        if len(b) == 0:
            raise ValueError("a mapping needs a repertoire with at least one primitive")
        if name == "polar":
            tau = float(np.max(np.hypot(b[:, 0], b[:, 1])))
            return cls(name, (tau, 0.0, 0.0, 0.0))
        if name == "cartesian":
            return cls(
                name,
                (
                    float(b[:, 0].min()),
                    float(b[:, 0].max()),
                    float(b[:, 1].min()),
                    float(b[:, 1].max()),
                ),
            )
        raise ValueError(f"unknown mapping {name!r}; expected one of {', '.join(MAPPINGS)}")

    @property
    def kind(self) -> int:
        """0 for polar, 1 for cartesian (the compiled kernels' code)."""
        return MAPPINGS.index(self.name)

    def domain(self) -> tuple[float, float, float, float]:
        """``(xmin, xmax, ymin, ymax)`` that every mapped point lies in, m."""
        if self.name == "polar":
            tau = self.params[0]
            return (-tau, tau, -tau, tau)
        return self.params

    def point(self, m1: float, m2: float) -> tuple[float, float]:
        """The behaviour-space point for outputs ``(m1, m2)`` (eq. 7 or 9)."""
        return map_point(self.kind, self.params, m1, m2)


def map_point(kind: int, params, m1: float, m2: float) -> tuple[float, float]:
    """Eq. 9 (kind 0, polar) or eq. 7 (kind 1, cartesian); scalar, shared with numba code."""
    if kind == 0:
        r = params[0] * (2.0 * m1 - 1.0)
        alpha = math.pi * (m2 - 0.5)
        return r * math.cos(alpha), r * math.sin(alpha)
    return (m1 * (params[1] - params[0]) + params[0], m2 * (params[3] - params[2]) + params[2])


@dataclass(frozen=True)
class PrimitiveLookup:
    """Grid over a mapping's domain holding each cell's nearest primitive."""

    origin: tuple[float, float]  # m, lower-left corner of the grid
    cell: tuple[float, float]  # m, cell size along x and y
    table: np.ndarray  # (nx, ny) int64 primitive indices

    @classmethod
    def build(
        cls,
        behaviour: np.ndarray,
        domain: tuple[float, float, float, float],
        cells: int = DEFAULT_GRID_CELLS,
    ) -> PrimitiveLookup:
        """Fill a ``cells x cells`` grid over ``domain`` with nearest-primitive indices."""
        b = np.asarray(behaviour, dtype=np.float64)
        xmin, xmax, ymin, ymax = domain
        # A degenerate side (all primitives on one line) still gets a non-zero cell.
        wx = max(xmax - xmin, 1e-9) / cells
        wy = max(ymax - ymin, 1e-9) / cells
        cx = xmin + (np.arange(cells) + 0.5) * wx
        cy = ymin + (np.arange(cells) + 0.5) * wy
        table = nearest_on_grid(b, cx, cy)
        return cls((xmin, ymin), (wx, wy), table)

    def cell_of(self, x: float, y: float) -> tuple[int, int]:
        """Grid cell of the point ``(x, y)``; points outside use the nearest border cell."""
        nx, ny = self.table.shape
        return (
            clamped_cell((x - self.origin[0]) / self.cell[0], nx),
            clamped_cell((y - self.origin[1]) / self.cell[1], ny),
        )

    def cell_centre(self, x: float, y: float) -> tuple[float, float]:
        """The centre of the cell of ``(x, y)`` (m), computed as :meth:`build` computes it.

        The primitive nearest it by brute force is the table's entry, bit for bit.
        """
        i, j = self.cell_of(x, y)
        return self.origin[0] + (i + 0.5) * self.cell[0], self.origin[1] + (j + 0.5) * self.cell[1]

    def nearest(self, x: float, y: float) -> int:
        """Index of the primitive nearest ``(x, y)`` (exact at cell centres).

        The point must be finite (see :func:`choose_primitive`).
        """
        return int(self.table[self.cell_of(x, y)])


def clamped_cell(f: float, n: int) -> int:
    """Cell index ``floor(f)`` clamped to ``[0, n - 1]``; shared with numba code.

    Clamped before ``floor``: a huge but finite ``f`` (1e300) has no int64 form in compiled
    code, where converting it would be undefined, so both forms compare first.
    """
    if f < 0.0:
        return 0
    if f >= n:
        return n - 1
    return math.floor(f)


def choose_primitive(
    mapping: MappingFunction, lookup: PrimitiveLookup, m1: float, m2: float
) -> tuple[int, float, float]:
    """``(primitive index, x, y)`` for network outputs ``(m1, m2)``.

    Non-finite outputs, or a point that overflows to infinity, choose no primitive:
    ``(NO_PRIMITIVE, nan, nan)``. The robot then stops for the cycle (docs/design.md section 7).
    """
    if not (math.isfinite(m1) and math.isfinite(m2)):
        return NO_PRIMITIVE, math.nan, math.nan
    x, y = mapping.point(m1, m2)
    if not (math.isfinite(x) and math.isfinite(y)):
        return NO_PRIMITIVE, math.nan, math.nan
    return lookup.nearest(x, y), x, y


#: Largest block of (cells x primitives) distances computed at once (2 MB of float64).
_BLOCK = 1 << 18
#: Relative slack of the pruning test: a primitive is dropped only if its lower bound
#: exceeds the best upper bound by more than any rounding of the squared distances.
_SLACK = 1e-9


def nearest_on_grid(behaviour: np.ndarray, cx: np.ndarray, cy: np.ndarray) -> np.ndarray:
    """``(len(cx), len(cy))`` index of the primitive nearest each point ``(cx[i], cy[j])``.

    Exactly brute force's answer (:func:`nearest_brute_force`, ties to the lower index):
    the squared distances that decide are computed by the same formula, over every
    primitive that could be nearest. A block of cells is split in four until few
    primitives remain; a primitive is dropped from a block when its distance to the
    block's rectangle exceeds the largest distance from that rectangle to some primitive
    (by a relative slack far above rounding). Identical behaviours keep only the lowest
    index (the same answer). ``cx`` and ``cy`` must be increasing.

    Cost: about ``n`` per block level plus the final blocks' distances, a few seconds for
    200,000 spread-out primitives on 256 x 256 cells (bench/bench_lookup.py).
    """
    b = np.asarray(behaviour, dtype=np.float64)
    bx, by = b[:, 0], b[:, 1]
    # Identical behaviours: only the lowest index can win a tie, so only it is kept.
    order = np.lexsort((np.arange(len(b)), by, bx))  # by x, then y, then index
    new = np.ones(len(b), dtype=bool)
    new[1:] = (bx[order][1:] != bx[order][:-1]) | (by[order][1:] != by[order][:-1])
    idx = np.sort(order[new])
    table = np.empty((len(cx), len(cy)), dtype=np.int64)
    stack = [(0, len(cx), 0, len(cy), idx)]
    while stack:
        i0, i1, j0, j1, idx = stack.pop()
        px, py = bx[idx], by[idx]
        qx, qy = cx[i0:i1], cy[j0:j1]
        # Distance bounds between the block's rectangle of cell centres and each primitive.
        gx = np.maximum(np.maximum(qx[0] - px, px - qx[-1]), 0.0)
        gy = np.maximum(np.maximum(qy[0] - py, py - qy[-1]), 0.0)
        fx = np.maximum(np.abs(px - qx[0]), np.abs(px - qx[-1]))
        fy = np.maximum(np.abs(py - qy[0]), np.abs(py - qy[-1]))
        upper = np.min(fx * fx + fy * fy)  # every cell has a primitive at most this far
        keep = gx * gx + gy * gy <= upper * (1.0 + _SLACK)
        idx, px, py = idx[keep], px[keep], py[keep]
        n_cells = (i1 - i0) * (j1 - j0)
        if n_cells * len(idx) <= _BLOCK or n_cells == 1 or len(idx) == 1:
            table[i0:i1, j0:j1] = _nearest_block(qx, qy, px, py, idx)
            continue
        im, jm = (i0 + i1) // 2, (j0 + j1) // 2
        for a, b_ in ((i0, im), (im, i1)):
            for c, d in ((j0, jm), (jm, j1)):
                if a < b_ and c < d:
                    stack.append((a, b_, c, d, idx))
    return table


def _nearest_block(qx, qy, px, py, idx) -> np.ndarray:
    """Brute force over candidates ``idx`` (increasing) for the cells ``qx x qy``.

    The same formula as :func:`nearest_brute_force` and the original grid fill, so ties
    and near-ties resolve bit for bit alike; chunked along x to bound memory.
    """
    out = np.empty((len(qx), len(qy)), dtype=np.int64)
    rows = max(1, _BLOCK // max(1, len(qy) * len(idx)))
    for s in range(0, len(qx), rows):
        d2 = (qx[s : s + rows, None, None] - px[None, None, :]) ** 2 + (
            qy[None, :, None] - py[None, None, :]
        ) ** 2
        out[s : s + rows] = idx[np.argmin(d2, axis=2)]
    return out


def nearest_brute_force(behaviour: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Exact nearest primitive for each of ``(k, 2)`` points (ties to the lower index)."""
    b = np.asarray(behaviour, dtype=np.float64)
    p = np.atleast_2d(points)
    d2 = ((p[:, None, :] - b[None, :, :]) ** 2).sum(axis=2)
    return np.argmin(d2, axis=1)
