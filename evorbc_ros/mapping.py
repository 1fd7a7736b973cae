"""Mapping functions and primitive choice (paper eq. 4, 7-9; DESIGN.md section 7).

The arbitrator outputs ``m = (m1, m2)`` in [0, 1]^2. A mapping function turns them into a
point of the behaviour space (m, start frame: x forward, y left) and the primitive whose
behaviour is nearest that point runs next.

* ``cartesian``: ``(m1 (xmax - xmin) + xmin, m2 (ymax - ymin) + ymin)`` over the bounds
  of the repertoire's behaviours.
* ``polar``: ``r = tau (2 m1 - 1)``, ``alpha = pi (m2 - 1/2)`` from the forward axis,
  point ``r (cos alpha, sin alpha)``, with ``tau`` the largest displacement in the
  repertoire. ``m2 = 0.5`` is straight ahead; ``m1 < 0.5`` goes backward.

Primitive lookup is O(1): when the repertoire is loaded, a grid over the mapping's domain
is filled with the index of each cell centre's nearest primitive (brute force, ties to the
lower index), so a query only finds its cell.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

MAPPINGS = ("polar", "cartesian")
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
        table = np.empty((cells, cells), dtype=np.int64)
        for i in range(cells):  # one column at a time keeps memory at cells x n
            d2 = (cx[i] - b[None, :, 0]) ** 2 + (cy[:, None] - b[None, :, 1]) ** 2
            table[i] = np.argmin(d2, axis=1)
        return cls((xmin, ymin), (wx, wy), table)

    def cell_of(self, x: float, y: float) -> tuple[int, int]:
        """Grid cell of the point ``(x, y)``; points outside use the nearest border cell."""
        nx, ny = self.table.shape
        i = min(max(math.floor((x - self.origin[0]) / self.cell[0]), 0), nx - 1)
        j = min(max(math.floor((y - self.origin[1]) / self.cell[1]), 0), ny - 1)
        return i, j

    def nearest(self, x: float, y: float) -> int:
        """Index of the primitive nearest ``(x, y)`` (exact at cell centres)."""
        return int(self.table[self.cell_of(x, y)])


def nearest_brute_force(behaviour: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Exact nearest primitive for each of ``(k, 2)`` points (ties to the lower index)."""
    b = np.asarray(behaviour, dtype=np.float64)
    p = np.atleast_2d(points)
    d2 = ((p[:, None, :] - b[None, :, :]) ** 2).sum(axis=2)
    return np.argmin(d2, axis=1)
