"""The primitive lookup grid is exactly brute force's, ties to the lower index, for any set
of behaviours: random, duplicated, on a lattice whose points tie at every cell centre."""

import numpy as np
import pytest

from evorbc_ros.mapping import PrimitiveLookup, nearest_on_grid


def brute_force_table(behaviour, domain, cells):
    """The grid as it was filled before: every cell centre against every primitive."""
    b = np.asarray(behaviour, dtype=np.float64)
    xmin, xmax, ymin, ymax = domain
    wx = max(xmax - xmin, 1e-9) / cells
    wy = max(ymax - ymin, 1e-9) / cells
    cx = xmin + (np.arange(cells) + 0.5) * wx
    cy = ymin + (np.arange(cells) + 0.5) * wy
    table = np.empty((cells, cells), dtype=np.int64)
    for i in range(cells):
        d2 = (cx[i] - b[None, :, 0]) ** 2 + (cy[:, None] - b[None, :, 1]) ** 2
        table[i] = np.argmin(d2, axis=1)
    return table


rng = np.random.default_rng(5)
LATTICE = np.stack(np.meshgrid(np.arange(17) / 16, np.arange(17) / 16), -1).reshape(-1, 2)
SETS = {
    "random": rng.uniform(-0.3, 0.3, (4000, 2)),
    "disc": (lambda r, a: np.column_stack([r * np.cos(a), r * np.sin(a)]))(
        0.36 * np.sqrt(rng.uniform(0, 1, 3000)), rng.uniform(-np.pi, np.pi, 3000)
    ),
    "duplicated": np.repeat(rng.uniform(-0.3, 0.3, (200, 2)), 7, axis=0)[rng.permutation(1400)],
    # Cell corners of a 16 x 16 grid over [0, 1]^2: every cell centre is exactly as far
    # from its four corners, so every cell is a tie (shuffled: the lowest index must win).
    "lattice ties": LATTICE[rng.permutation(len(LATTICE))],
    "one": np.array([[0.1, -0.2]]),
    "on a line": np.column_stack([np.linspace(-0.3, 0.3, 500), np.zeros(500)]),
    "tight cluster": rng.normal(0.2, 1e-4, (1500, 2)),
}


@pytest.mark.parametrize("name", SETS)
@pytest.mark.parametrize(
    ("domain", "cells"),
    [((-0.3, 0.3, -0.3, 0.3), 256), ((0.0, 1.0, 0.0, 1.0), 16), ((-0.31, 0.29, -0.2, 0.33), 37)],
)
def test_the_grid_equals_brute_force(name, domain, cells):
    b = SETS[name]
    lookup = PrimitiveLookup.build(b, domain, cells)
    np.testing.assert_array_equal(lookup.table, brute_force_table(b, domain, cells))


def test_lattice_ties_go_to_the_lowest_index():
    b = SETS["lattice ties"]
    table = PrimitiveLookup.build(b, (0.0, 1.0, 0.0, 1.0), 16).table
    for i in range(16):
        for j in range(16):
            corners = [
                k
                for k, (x, y) in enumerate(b)
                if abs(x - (i + 0.5) / 16) == 1 / 32 and abs(y - (j + 0.5) / 16) == 1 / 32
            ]
            assert len(corners) == 4 and table[i, j] == min(corners)


def test_arbitrary_query_points():
    b = SETS["random"]
    cx, cy = np.sort(rng.uniform(-0.5, 0.5, 50)), np.sort(rng.uniform(-0.5, 0.5, 70))
    got = nearest_on_grid(b, cx, cy)
    d2 = (cx[:, None, None] - b[None, None, :, 0]) ** 2 + (
        cy[None, :, None] - b[None, None, :, 1]
    ) ** 2
    np.testing.assert_array_equal(got, np.argmin(d2, axis=2))


def test_the_grid_computes_a_small_share_of_brute_force_distances(monkeypatch):
    """Scaling without timing: for 20,000 spread-out primitives on 256 x 256 cells the
    final distances computed are a small share of brute force's 1.3 billion."""
    import evorbc_ros.mapping as mapping

    computed = []
    original = mapping._nearest_block

    def counting(qx, qy, px, py, idx):
        computed.append(len(qx) * len(qy) * len(idx))
        return original(qx, qy, px, py, idx)

    monkeypatch.setattr(mapping, "_nearest_block", counting)
    r = 0.36 * np.sqrt(rng.uniform(0, 1, 20000))
    a = rng.uniform(-np.pi, np.pi, 20000)
    b = np.column_stack([r * np.cos(a), r * np.sin(a)])
    table = PrimitiveLookup.build(b, (-0.36, 0.36, -0.36, 0.36)).table
    assert sum(computed) < 0.05 * 256 * 256 * len(b)  # about 2 % here
    sample = rng.integers(0, 256, (200, 2))
    cell = 0.72 / 256
    centres = -0.36 + (sample + 0.5) * cell
    d2 = ((centres[:, None, :] - b[None, :, :]) ** 2).sum(axis=2)
    np.testing.assert_array_equal(table[sample[:, 0], sample[:, 1]], np.argmin(d2, axis=1))
