"""Wall boxes, point distances, ray casts and the broad-phase grid, against hand arithmetic.

Most cases use one horizontal wall with dyadic numbers, so that every coordinate is exact in
binary floating point and the "exactly touching" cases really are exact:

    segment (1, 2) - (3, 2), thickness 0.25
    box: centre (2, 2), along (1, 0), half length 1, half thickness 0.125
         x in [1, 3], y in [1.875, 2.125]; corners (1, 1.875) (3, 1.875) (1, 2.125) (3, 2.125)

Walls are boxes with FLAT ends at the segment's endpoints (not capsules): beyond an end, the
distance is measured to the end face, or to its corner when the point is off to the side.

Ray rules pinned here (``ray_box``): a ray whose origin is in the box or on its surface
reads 0; a ray that only touches the box (through a corner, or sliding along a face line)
counts as a hit, at the first point it touches; a ray that passes outside, however close,
misses (inf).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from sim_bridge.geometry import (
    WallGrid,
    box_corners,
    box_distance,
    box_distances,
    cast_ray,
    clearance,
    ray_box,
    wall_boxes,
)
from sim_bridge.maze import load_named_maze

TOL = 1e-12
S = math.sqrt(0.5)  # a diagonal component; (S, S) is a unit vector to 1 ulp, and dx == dy
EPS = 1e-9  # "a hair": far above rounding (1e-16), far below anything geometric

WALL = wall_boxes(np.array([[1.0, 2.0, 3.0, 2.0]]), 0.25)


def distance(px, py, boxes=WALL, k=0):
    return box_distance(px, py, boxes, k)


def ray(ox, oy, dx, dy, boxes=WALL, k=0):
    return ray_box(ox, oy, dx, dy, boxes, k)


# -- boxes ------------------------------------------------------------------------------------


def test_wall_boxes_rows_are_centre_direction_and_half_extents():
    # (1, 2) - (3, 2): centre (2, 2), direction (2, 0) / 2 = (1, 0), half length 2 / 2 = 1,
    # half thickness 0.25 / 2 = 0.125.
    np.testing.assert_array_equal(WALL, [[2.0, 2.0, 1.0, 0.0, 1.0, 0.125]])
    # A vertical wall drawn downwards, (0, 3) - (0, -1): centre (0, 1), direction (0, -1),
    # half length 2; thickness 0.01 -> half thickness 0.005.
    np.testing.assert_array_equal(
        wall_boxes(np.array([[0.0, 3.0, 0.0, -1.0]]), 0.01), [[0.0, 1.0, 0.0, -1.0, 2.0, 0.005]]
    )


def test_box_corners_of_an_axis_aligned_wall():
    corners = {tuple(c) for c in box_corners(WALL)[0]}
    assert corners == {(1.0, 1.875), (3.0, 1.875), (1.0, 2.125), (3.0, 2.125)}


def test_box_corners_of_a_wall_at_30_degrees():
    # Segment (0, 0) - (sqrt3, 1): length 2, direction e = (sqrt3/2, 1/2), normal
    # n = (-1/2, sqrt3/2); thickness 0.2 -> corners = endpoint +- 0.1 n:
    #   (0, 0) + 0.1 n = (-0.05, 0.0866025...)      (0, 0) - 0.1 n = (0.05, -0.0866025...)
    #   (sqrt3, 1) + 0.1 n = (1.6820508..., 1.0866025...)
    #   (sqrt3, 1) - 0.1 n = (1.7820508..., 0.9133974...)
    r3 = math.sqrt(3.0)
    boxes = wall_boxes(np.array([[0.0, 0.0, r3, 1.0]]), 0.2)
    expected = [
        (-0.05, 0.05 * r3),
        (0.05, -0.05 * r3),
        (r3 - 0.05, 1 + 0.05 * r3),
        (r3 + 0.05, 1 - 0.05 * r3),
    ]
    got = sorted(map(tuple, box_corners(boxes)[0]))
    np.testing.assert_allclose(got, sorted(expected), rtol=0, atol=TOL)


# -- point distances --------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("point", "expected", "why"),
    [
        ((2.0, 3.0), 0.875, "above the middle: 3 - 2.125"),
        ((1.5, 1.0), 0.875, "below: 1.875 - 1"),
        ((2.9, 2.5), 0.375, "above, near the right end: 2.5 - 2.125"),
        ((3.5, 2.0), 0.5, "on the axis beyond the flat end: 3.5 - 3 (a capsule would say 0.375)"),
        ((3.5, 2.1), 0.5, "beyond the end, within the thickness: still the end face, 3.5 - 3"),
        ((0.25, 1.9), 0.75, "beyond the left end, within the thickness: 1 - 0.25"),
        ((3.375, 2.625), 0.625, "off-axis beyond the end: corner (3, 2.125), hypot(0.375, 0.5)"),
        ((0.7, 1.475), 0.5, "off-axis beyond the left end: corner (1, 1.875), hypot(0.3, 0.4)"),
        ((2.5, 2.0), 0.0, "inside"),
        ((2.0, 2.125), 0.0, "on the top face"),
        ((3.0, 2.0), 0.0, "on the end face"),
        ((1.0, 1.875), 0.0, "on a corner"),
    ],
)
def test_point_to_box_distance(point, expected, why):
    assert distance(*point) == pytest.approx(expected, abs=TOL), why
    # The vectorised and the candidate-list forms agree with the scalar one.
    vec = box_distances(np.array([point[0]]), np.array([point[1]]), WALL[0])
    assert vec[0] == pytest.approx(expected, abs=TOL)
    assert clearance(*point, WALL, np.array([0], np.int64)) == pytest.approx(expected, abs=TOL)


def test_distance_beyond_a_flat_end_is_exact_in_dyadic_numbers():
    # (0, 1.5): beyond the left end, below: du = |0 - 2| - 1 = 1, dv = |1.5 - 2| - 0.125 =
    # 0.375, distance = sqrt(1 + 0.140625) = sqrt(73) / 8 = 1.0680004681...
    assert distance(0.0, 1.5) == pytest.approx(math.sqrt(73.0) / 8.0, abs=TOL)


R3 = math.sqrt(3.0)
TILTED = wall_boxes(np.array([[0.0, 0.0, R3, 1.0]]), 0.2)  # 30 deg, centre (sqrt3/2, 1/2)


@pytest.mark.parametrize(
    ("a", "b", "expected", "why"),
    [
        # point = centre + a e + b n, e = (cos30, sin30), n = (-sin30, cos30); half length
        # 1, half thickness 0.1: distance = hypot(max(|a| - 1, 0), max(|b| - 0.1, 0)).
        (0.3, 0.6, 0.5, "beside the middle: 0.6 - 0.1"),
        (-0.8, -0.35, 0.25, "on the other side: 0.35 - 0.1"),
        (1.3, 0.1, 0.3, "beyond the end, level with the face line: 1.3 - 1"),
        (1.3, 0.0, 0.3, "beyond the end on the axis: 1.3 - 1"),
        (1.4, 0.4, 0.5, "beyond the end, off to the side: hypot(0.4, 0.3)"),
        (-1.6, -0.9, 1.0, "beyond the other end: hypot(0.6, 0.8)"),
        (0.2, -0.05, 0.0, "inside"),
    ],
)
def test_point_to_a_wall_rotated_30_degrees(a, b, expected, why):
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    px = R3 / 2 + a * c - b * s
    py = 0.5 + a * s + b * c
    assert box_distance(px, py, TILTED, 0) == pytest.approx(expected, abs=TOL), why


def test_clearance_is_the_nearest_candidate_and_inf_without_candidates():
    # Two walls: WALL, and (5, 0) - (5, 4) with thickness 0.25 (x in [4.875, 5.125]).
    boxes = wall_boxes(np.array([[1.0, 2.0, 3.0, 2.0], [5.0, 0.0, 5.0, 4.0]]), 0.25)
    # (4, 2): to the first wall's end face 4 - 3 = 1, to the second's face 4.875 - 4 = 0.875.
    assert clearance(4.0, 2.0, boxes, np.array([0, 1], np.int64)) == pytest.approx(0.875)
    assert clearance(4.0, 2.0, boxes, np.array([0], np.int64)) == pytest.approx(1.0)
    assert clearance(4.0, 2.0, boxes, np.zeros(0, np.int64)) == math.inf


# -- single rays against one box --------------------------------------------------------------


@pytest.mark.parametrize(
    ("origin", "direction", "expected", "why"),
    [
        ((2.0, 0.0), (0.0, 1.0), 1.875, "head-on, from below: 1.875 - 0"),
        ((2.5, 4.0), (0.0, -1.0), 1.875, "head-on, from above: 4 - 2.125"),
        ((0.0, 2.0), (1.0, 0.0), 1.0, "head-on at the flat end: 1 - 0"),
        ((5.0, 2.1), (-1.0, 0.0), 2.0, "head-on at the other end, off-axis: 5 - 3"),
        # 3-4-5 ray from (1.25, 0.275) along (0.6, 0.8): reaches y = 1.875 after
        # t = 1.6 / 0.8 = 2, at x = 1.25 + 0.6 * 2 = 2.45, within [1, 3].
        ((1.25, 0.275), (0.6, 0.8), 2.0, "oblique, onto the bottom face"),
        # From (0, 1.25) along (0.8, 0.6): reaches x = 1 after t = 1 / 0.8 = 1.25, at
        # y = 1.25 + 0.6 * 1.25 = 2.0, within [1.875, 2.125]: the end face.
        ((0.0, 1.25), (0.8, 0.6), 1.25, "oblique, onto the flat end face"),
        # From (1, 0.875) along (S, S): y = 1.875 after t = 1 / S = sqrt2, at x = 2.
        ((1.0, 0.875), (S, S), 1.0 / S, "diagonal onto the bottom face"),
    ],
)
def test_ray_hits(origin, direction, expected, why):
    assert ray(*origin, *direction) == pytest.approx(expected, abs=TOL), why


@pytest.mark.parametrize(
    ("origin", "direction", "why"),
    [
        ((2.0, 3.0), (0.0, 1.0), "above, pointing up (away)"),
        ((0.0, 2.0), (-1.0, 0.0), "left of the end, pointing left (away)"),
        ((4.0, 2.0), (S, S), "right of the end, pointing up-right (away)"),
        ((0.0, 0.0), (S, -S), "below-left, pointing down-right"),
        ((0.0, 2.125 + EPS), (1.0, 0.0), "parallel to the top face, a hair above it"),
        ((0.0, 1.875 - EPS), (1.0, 0.0), "parallel to the bottom face, a hair below it"),
        ((3.0 + EPS, 0.0), (0.0, 1.0), "parallel to the right end face, a hair outside it"),
        ((0.0, 4.0), (1.0, 0.0), "parallel, far above"),
    ],
)
def test_ray_misses(origin, direction, why):
    assert ray(*origin, *direction) == math.inf, why


@pytest.mark.parametrize("direction", [(1.0, 0.0), (0.0, -1.0), (-S, S), (0.6, -0.8)])
def test_ray_from_inside_reads_zero(direction):
    assert ray(2.0, 2.0, *direction) == 0.0
    assert ray(2.999, 1.9, *direction) == 0.0


def test_ray_from_the_surface_reads_zero_even_pointing_away():
    # The origin (2, 2.125) is on the top face: it touches the box, whatever the direction.
    assert ray(2.0, 2.125, 0.0, 1.0) == 0.0
    assert ray(3.0, 2.0, 1.0, 0.0) == 0.0  # on the end face, pointing away
    assert ray(1.0, 1.875, -S, -S) == 0.0  # on a corner, pointing away


def test_ray_along_a_face_line_hits_where_it_reaches_the_box():
    # Rule: a ray that slides along the line of a face touches the box; the hit is where it
    # first touches it, i.e. the corner at the near end of that face.
    # Along the top face line y = 2.125 from x = 0: touches the corner (1, 2.125) at t = 1.
    assert ray(0.0, 2.125, 1.0, 0.0) == 1.0
    # Along the bottom face line from the right: touches (3, 1.875) at t = 5 - 3 = 2.
    assert ray(5.0, 1.875, -1.0, 0.0) == 2.0
    # Along the flat end's line x = 3, upwards from y = 0: touches (3, 1.875) at t = 1.875.
    assert ray(3.0, 0.0, 0.0, 1.0) == 1.875
    # ... and a hair inside that line it enters the box there too; a hair outside it misses.
    assert ray(3.0 - EPS, 0.0, 0.0, 1.0) == 1.875
    assert ray(3.0 + EPS, 0.0, 0.0, 1.0) == math.inf
    # Starting on the face line beside the box, pointing away from it: a miss.
    assert ray(0.0, 2.125, -1.0, 0.0) == math.inf


def test_ray_through_a_corner_exactly_hits_it_and_a_hair_beside_misses():
    # From (2, 0.875) along (-S, S): the line y - 0.875 = 2 - x passes (1, 1.875), the
    # bottom-left corner; before it the ray is below the box, after it left of the box, so
    # it only touches the corner. Box frame: u slab gives t <= (1 - 0) / S, v slab gives
    # t >= (1.875 - 0.875) / S: t_in == t_out == 1 / S = sqrt2 = 1.41421356...
    assert ray(2.0, 0.875, -S, S) == 1.0 / S
    assert ray(2.0, 0.875, -S, S) == pytest.approx(math.sqrt(2.0), abs=TOL)
    # Shifted left by a hair, the line passes (1 - EPS, 1.875): outside the corner, a miss.
    assert ray(2.0 - EPS, 0.875, -S, S) == math.inf
    # Shifted right by a hair, it clips the bottom face at (1 + EPS, 1.875), t = 1/S again.
    assert ray(2.0 + EPS, 0.875, -S, S) == pytest.approx(1.0 / S, abs=TOL)


def test_ray_grazing_the_top_right_corner_of_the_flat_end():
    # From (4, 1.125) along (-S, S): reaches x = 3 and y = 2.125 together (both after 1/S),
    # the top-right corner; right of the box before it, above it after it.
    assert ray(4.0, 1.125, -S, S) == 1.0 / S
    assert ray(4.0 + EPS, 1.125, -S, S) == math.inf  # passes above-right of the corner
    # A hair left, it reaches the end face x = 3 after (1 - EPS) / S, at y = 2.125 - EPS.
    assert ray(4.0 - EPS, 1.125, -S, S) == pytest.approx((1.0 - EPS) / S, abs=TOL)


def test_ray_into_a_corner_from_outside_hits_on_both_sides_of_it():
    # From (0, 0.875) along (S, S): aims straight at the bottom-left corner (1, 1.875) from
    # below-left; a hair either way it enters the box anyway.
    assert ray(0.0, 0.875, S, S) == 1.0 / S
    # A hair left: x = 1 after (1 + EPS) / S, at y = 1.875 + EPS: through the end face.
    assert ray(-EPS, 0.875, S, S) == pytest.approx((1.0 + EPS) / S, abs=TOL)
    # A hair right: y = 1.875 after 1 / S, at x = 1 + EPS: through the bottom face.
    assert ray(EPS, 0.875, S, S) == pytest.approx(1.0 / S, abs=TOL)


def test_ray_against_a_rotated_wall():
    # The 30-deg wall: centre c = (sqrt3/2, 1/2), e = (sqrt3/2, 1/2), n = (-1/2, sqrt3/2),
    # half length 1, half thickness 0.1. In the box frame a ray is u(t) = u0 + t du,
    # v(t) = v0 + t dv; it is in the box while |u| <= 1 and |v| <= 0.1.
    #
    # Head-on from c + 1 n along -n: v(t) = 1 - t reaches 0.1 at t = 0.9.
    nx, ny = -0.5, R3 / 2
    assert ray_box(R3 / 2 + nx, 0.5 + ny, -nx, -ny, TILTED, 0) == pytest.approx(0.9, abs=TOL)
    # From (-1, 0) along +x: q = (-1 - sqrt3/2, -1/2), u0 = q.e = -1 - sqrt3/2,
    # du = sqrt3/2; v0 = q.n = 1/2, dv = -1/2. |u| <= 1 for t in [1, 1 + 4/sqrt3];
    # |v| <= 0.1 for t in [0.8, 1.2]; first inside at t = 1: the point (0, 0), the middle
    # of the flat end face.
    assert ray_box(-1.0, 0.0, 1.0, 0.0, TILTED, 0) == pytest.approx(1.0, abs=TOL)
    # From (1, -1) along +y: q = (1 - sqrt3/2, -3/2), u0 = sqrt3/2 - 3/2, du = 1/2;
    # v0 = -1/2 - sqrt3/2, dv = sqrt3/2. |v| <= 0.1 for t in [1 + 0.8/sqrt3, 1 + 1.2/sqrt3];
    # |u| <= 1 for t in [1 - sqrt3, 5 - sqrt3]: enters the lower long face at
    # t = 1 + 0.8/sqrt3 = 1.4618802...
    assert ray_box(1.0, -1.0, 0.0, 1.0, TILTED, 0) == pytest.approx(1 + 0.8 / R3, abs=TOL)


# -- several walls: the nearest, max range ----------------------------------------------------

# An L: (0, 0) - (2, 0) and (2, 0) - (2, 2), thickness 0.25.
#   horizontal box: x in [0, 2],         y in [-0.125, 0.125]
#   vertical box:   x in [1.875, 2.125], y in [0, 2]
# The flat ends leave a notch at the outer corner: x in (2, 2.125], y in [-0.125, 0).
L_WALLS = wall_boxes(np.array([[0.0, 0.0, 2.0, 0.0], [2.0, 0.0, 2.0, 2.0]]), 0.25)
BOTH = np.array([0, 1], np.int64)


@pytest.mark.parametrize(
    ("origin", "angle", "horizontal", "vertical", "why"),
    [
        # Down from (1.9375, 3): the vertical wall's top end face y = 2 after 1, the
        # horizontal wall's top face y = 0.125 after 2.875.
        ((1.9375, 3.0), -math.pi / 2, 2.875, 1.0, "from above, through both"),
        # Up from (1.9375, -1): horizontal bottom face y = -0.125 after 0.875, the vertical
        # wall's bottom end face y = 0 after 1.
        ((1.9375, -1.0), math.pi / 2, 0.875, 1.0, "from below, through both"),
        # Right from (-1, 0.0625): horizontal end face x = 0 after 1; vertical face
        # x = 1.875 after 2.875 (y = 0.0625 is within its [0, 2]).
        ((-1.0, 0.0625), 0.0, 1.0, 2.875, "from the left, along the horizontal wall"),
        # Down-right from (1, 0.75): horizontal top face y = 0.125 after 0.625 / S (at
        # x = 1.625); the vertical face x = 1.875 is reached only at y = -0.125, below it.
        ((1.0, 0.75), -math.pi / 4, 0.625 / S, math.inf, "diagonal, horizontal only"),
        # Down-right from (1, 1): both faces at the inner corner (1.875, 0.125), 0.875 / S.
        ((1.0, 1.0), -math.pi / 4, 0.875 / S, 0.875 / S, "diagonal into the inner corner"),
    ],
)
def test_l_shape_ray_hits_the_nearer_wall(origin, angle, horizontal, vertical, why):
    dx, dy = math.cos(angle), math.sin(angle)
    # (Directions from cos/sin are unit to 1 ulp; no ray here grazes anything.)
    assert ray_box(*origin, dx, dy, L_WALLS, 0) == pytest.approx(horizontal, abs=TOL), why
    assert ray_box(*origin, dx, dy, L_WALLS, 1) == pytest.approx(vertical, abs=TOL), why
    nearest = min(horizontal, vertical)
    for order in (BOTH, BOTH[::-1].copy()):
        assert cast_ray(*origin, angle, 5.0, L_WALLS, order) == pytest.approx(nearest, abs=TOL)


def test_l_corner_outer_notch_of_the_flat_ends():
    # From (3, -0.0625) along -x: y = -0.0625 is below the vertical box (y >= 0), so the ray
    # passes through the notch and hits the horizontal box's end face x = 2 at t = 1.
    assert cast_ray(3.0, -0.0625, math.pi, 5.0, L_WALLS, BOTH) == pytest.approx(1.0, abs=TOL)
    # At y = +0.0625 it hits the vertical box's outer face x = 2.125 first: t = 0.875.
    assert cast_ray(3.0, 0.0625, math.pi, 5.0, L_WALLS, BOTH) == pytest.approx(0.875, abs=TOL)
    # Up through the notch from (2.0625, -1): x = 2.0625 is beyond the horizontal box's
    # end (x <= 2), so the first thing is the vertical box's bottom end face y = 0, t = 1.
    assert cast_ray(2.0625, -1.0, math.pi / 2, 5.0, L_WALLS, BOTH) == pytest.approx(1.0, abs=TOL)


def test_cast_ray_is_capped_at_max_range():
    # From (1, 1) along +x: the vertical face x = 1.875 is 0.875 away.
    assert cast_ray(1.0, 1.0, 0.0, 2.0, L_WALLS, BOTH) == 0.875
    assert cast_ray(1.0, 1.0, 0.0, 0.5, L_WALLS, BOTH) == 0.5  # wall beyond range
    assert cast_ray(1.0, 1.0, 0.0, 0.875, L_WALLS, BOTH) == 0.875  # exactly at range
    assert cast_ray(1.0, 1.0, math.pi / 2, 3.0, L_WALLS, BOTH) == 3.0  # up: nothing
    assert cast_ray(1.0, 1.0, 0.0, 2.0, L_WALLS, np.zeros(0, np.int64)) == 2.0  # no walls
    assert cast_ray(1.0, 1.0, 0.0, 2.0, L_WALLS, np.array([0], np.int64)) == 2.0  # other wall
    # From inside a wall: 0.
    assert cast_ray(1.0, 0.0, 1.0, 2.0, L_WALLS, BOTH) == 0.0


# -- broad phase ------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def obstacle():
    return load_named_maze("obstacle")


@pytest.mark.parametrize(("reach", "cell"), [(1.05, 0.2), (0.05, 0.2), (0.3, 0.05)])
def test_wall_grid_lists_every_wall_within_reach(obstacle, reach, cell):
    boxes = obstacle.boxes
    grid = WallGrid.build(boxes, reach, cell)
    (x0, y0), nx, ny = grid.origin, grid.shape[0], grid.shape[1]
    x1, y1 = x0 + nx * cell, y0 + ny * cell
    rng = np.random.default_rng(12)
    # Random points over the grid and a margin around it, plus every cell corner on a
    # coarse lattice (cell boundaries are where rounding would bite).
    px = np.concatenate([rng.uniform(x0 - 0.5, x1 + 0.5, 3000), x0 + cell * np.arange(nx)])
    py = np.concatenate([rng.uniform(y0 - 0.5, y1 + 0.5, 3000), y0 + cell * (np.arange(nx) % ny)])
    dist = np.stack([box_distances(px, py, b) for b in boxes], axis=1)  # (points, walls)
    inside = outside = 0
    for k in range(len(px)):
        cand = grid.candidates(float(px[k]), float(py[k]))
        assert cand.dtype == np.int64
        i, j = math.floor((px[k] - x0) / cell), math.floor((py[k] - y0) / cell)
        if not (0 <= i < nx and 0 <= j < ny):
            np.testing.assert_array_equal(cand, np.arange(len(boxes)))
            outside += 1
            continue
        inside += 1
        near = set(np.nonzero(dist[k] <= reach)[0])
        # The scalar compiled distance is the one the simulator uses; check it agrees.
        for w in near:
            assert box_distance(float(px[k]), float(py[k]), boxes, w) <= reach
        assert near <= set(cand.tolist()), (px[k], py[k], sorted(near - set(cand.tolist())))
        # Same nearest wall, hence the same clearance, from the candidates as from all.
        if near:
            assert clearance(px[k], py[k], boxes, cand) == clearance(
                px[k], py[k], boxes, grid.all_ids
            )
    assert inside > 1000 and outside > 200  # both kinds were exercised


def test_wall_grid_outside_the_grid_returns_every_wall(obstacle):
    grid = obstacle.wall_grid(1.05)
    (x0, y0), (nx, ny), cell = grid.origin, grid.shape, grid.cell
    every = np.arange(len(obstacle.walls))
    far = [
        (x0 - 1e-9, y0 + 0.5),  # just left of the grid
        (x0 + nx * cell, y0 + 0.5),  # on the right edge: cells are [lo, hi), so outside
        (x0 + 1.0, y0 + ny * cell + 1.0),  # above
        (x0 + 1.0, y0 - 100.0),  # far below
        (1e6, -1e6),
    ]
    for x, y in far:
        np.testing.assert_array_equal(grid.candidates(x, y), every)
    # The grid reaches beyond the walls by at least `reach`, so every point within reach of
    # a wall is inside it: the maze's outer corners plus reach are inside.
    bx0, by0, bx1, by1 = obstacle.bounds()
    assert x0 <= bx0 - 1.05 and y0 <= by0 - 1.05
    assert x0 + nx * cell >= bx1 + 1.05 and y0 + ny * cell >= by1 + 1.05
