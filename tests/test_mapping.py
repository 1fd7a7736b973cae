"""Mapping functions (eq. 7-9) and the O(1) primitive lookup grid."""

import math

import numpy as np
import pytest

from evorbc_ros.mapping import MappingFunction, PrimitiveLookup, nearest_brute_force


@pytest.fixture(scope="module")
def behaviour(small_repertoire):
    return small_repertoire.behaviour


def test_polar_mapping_points():
    b = np.array([[0.3, 0.0], [0.0, -0.2], [-0.1, 0.1]])
    polar = MappingFunction.for_behaviours("polar", b)
    tau = 0.3
    assert polar.params[0] == tau
    cases = {
        (0.5, 0.5): (0, 0),
        (1.0, 0.5): (tau, 0),
        (0.0, 0.5): (-tau, 0),
        (1.0, 1.0): (0, tau),
        (1.0, 0.0): (0, -tau),
        (0.75, 0.75): (0.5 * tau * math.cos(math.pi / 4), 0.5 * tau * math.sin(math.pi / 4)),
    }
    for m, want in cases.items():
        np.testing.assert_allclose(polar.point(*m), want, atol=1e-15)
    assert polar.domain() == (-tau, tau, -tau, tau)


def test_cartesian_mapping_spans_the_repertoire_bounds():
    b = np.array([[0.3, 0.0], [0.0, -0.2], [-0.1, 0.1]])
    cart = MappingFunction.for_behaviours("cartesian", b)
    np.testing.assert_allclose(cart.point(0, 0), (-0.1, -0.2))
    np.testing.assert_allclose(cart.point(1, 1), (0.3, 0.1))
    np.testing.assert_allclose(cart.point(0.25, 0.5), (0.0, -0.05))
    assert cart.domain() == (-0.1, 0.3, -0.2, 0.1)


@pytest.mark.parametrize("name", ["polar", "cartesian"])
def test_grid_is_exact_at_cell_centres(behaviour, name):
    fn = MappingFunction.for_behaviours(name, behaviour)
    lookup = PrimitiveLookup.build(behaviour, fn.domain(), cells=64)
    nx, ny = lookup.table.shape
    cx = lookup.origin[0] + (np.arange(nx) + 0.5) * lookup.cell[0]
    cy = lookup.origin[1] + (np.arange(ny) + 0.5) * lookup.cell[1]
    gx, gy = np.meshgrid(cx, cy, indexing="ij")
    centres = np.column_stack([gx.ravel(), gy.ravel()])
    np.testing.assert_array_equal(lookup.table.ravel(), nearest_brute_force(behaviour, centres))
    assert [lookup.nearest(*p) for p in centres[::97]] == list(lookup.table.ravel()[::97])


@pytest.mark.parametrize("name", ["polar", "cartesian"])
def test_grid_differs_from_brute_force_only_between_nearly_equidistant_primitives(behaviour, name):
    fn = MappingFunction.for_behaviours(name, behaviour)
    lookup = PrimitiveLookup.build(behaviour, fn.domain())
    rng = np.random.default_rng(0)
    points = np.array([fn.point(*m) for m in rng.uniform(0, 1, (20000, 2))])
    grid = np.array([lookup.nearest(*p) for p in points])
    exact = nearest_brute_force(behaviour, points)
    diagonal = math.hypot(*lookup.cell)
    d_grid = np.hypot(*(points - behaviour[grid]).T)
    d_exact = np.hypot(*(points - behaviour[exact]).T)
    # Within a cell the grid keeps the centre's nearest primitive: it can only lose to
    # another primitive by less than a cell diagonal.
    assert np.all(d_grid - d_exact <= diagonal + 1e-12)
    assert np.mean(grid != exact) < 0.05
    # The bound is tight enough to fail: a grid of huge cells breaks it.
    coarse = PrimitiveLookup.build(behaviour, fn.domain(), cells=4)
    coarse_grid = np.array([coarse.nearest(*p) for p in points])
    d_coarse = np.hypot(*(points - behaviour[coarse_grid]).T)
    assert np.any(d_coarse - d_exact > diagonal)


def test_unknown_mapping_and_empty_repertoire():
    with pytest.raises(ValueError, match="unknown mapping"):
        MappingFunction.for_behaviours("spiral", np.zeros((2, 2)))
    with pytest.raises(ValueError, match="at least one primitive"):
        MappingFunction.for_behaviours("polar", np.zeros((0, 2)))
