"""The 4WS robot's sensors (docs/design.md section 5) against hand-computed readings.

The room used below: walls on the segments of the rectangle (0, 0) - (2, 1), 0.01 m thick,
so the inner faces are x = 0.005, x = 1.995, y = 0.005 and y = 0.995.

Rangefinder geometry pinned here (``sim_bridge.sensors.read_sensors``): a ray at world angle
a = heading + ray angle starts at the mount point (x, y) + r (cos a, sin a), r = 0.05 m, and
reads d = the distance from that point to the first wall. When the wall is beyond the mount
point, d = (distance from the body centre along the ray) - r, which is how the expectations
are computed. With a field of view, each ray starts at r along its OWN direction.
Reading = clip((range - d) / range, 0, 1) with range 1 m, so reading = 1 - d here.
"""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest
import yaml

from evorbc_ros.config import ConfigError, config_dir
from evorbc_ros.sensors import (
    SensorLayout,
    goal_bearing_reading,
    goal_sector_readings,
    in_sector,
    range_reading,
    rangefinder_readings,
)
from sim_bridge import sensors as compiled
from sim_bridge.geometry import WallGrid, cast_ray, wall_boxes
from sim_bridge.maze import load_named_maze
from sim_bridge.sensors import compile_layout, read_sensors

TOL = 1e-12
EPS = 1e-9  # "a hair"
R = 0.05  # mount radius, m
LAYOUT = SensorLayout.load(config_dir() / "sensors" / "4ws.yaml")
COMPILED = compile_layout(LAYOUT)
ROOM = wall_boxes(np.array([[0, 0, 2, 0], [2, 0, 2, 1], [2, 1, 0, 1], [0, 1, 0, 0]], float), 0.01)
FAR_GOAL = (100.0, 0.4)  # sectors are not under test where this goal is used


def read(x, y, heading, goal=FAR_GOAL, boxes=ROOM, layout=COMPILED, candidates=None):
    """All inputs of a robot at (x, y, heading) through the compiled kernel."""
    if candidates is None:
        candidates = np.arange(len(boxes), dtype=np.int64)
    out = np.full(layout.n_inputs, np.nan)
    read_sensors(x, y, heading, goal[0], goal[1], x, y, layout, boxes, candidates, out)
    assert not np.isnan(out).any()  # every input was written
    return out


def ranges(x, y, heading, **kwargs):
    return read(x, y, heading, **kwargs)[:6]


def sectors(x, y, heading, goal):
    return read(x, y, heading, goal=goal)[6:]


# -- the shipped layout -----------------------------------------------------------------------


def test_shipped_layout_is_the_papers():
    rf, gs = LAYOUT.rangefinders, LAYOUT.goal_sectors
    assert rf.angles == tuple(math.radians(a) for a in (0, 60, 120, 180, 240, 300))
    assert (rf.max_range, rf.mount_radius, rf.field_of_view, rf.rays) == (1.0, 0.05, 0.0, 1)
    assert gs.centres == tuple(math.radians(a) for a in (0, 90, 180, 270))
    assert gs.width == math.pi / 2
    assert not LAYOUT.goal_bearing
    assert LAYOUT.n_inputs == COMPILED.n_inputs == 10
    assert LAYOUT.input_names() == [
        *(f"range_{a:03d}" for a in (0, 60, 120, 180, 240, 300)),
        *(f"goal_sector_{a:03d}" for a in (0, 90, 180, 270)),
    ]
    assert COMPILED.ray_angles.shape == (6, 1)
    assert COMPILED.reach() == pytest.approx(1.05)


# -- rangefinders in the room -----------------------------------------------------------------

R3_2 = math.sqrt(3.0) / 2  # sin 60


@pytest.mark.parametrize(
    ("heading_deg", "expected"),
    [
        # Robot at (1.4, 0.4). Faces from the centre: right 1.995 - 1.4 = 0.595,
        # left 1.4 - 0.005 = 1.395, top 0.995 - 0.4 = 0.595, bottom 0.4 - 0.005 = 0.395.
        # Along a ray at world angle a the centre sees the right face after 0.595 / cos a,
        # the top face after 0.595 / sin a, and so on; the nearest one counts.
        (
            0,
            [
                1 - (0.595 - R),  # 0 deg: right face; d = 0.545, reading 0.455
                1 - (0.595 / R3_2 - R),  # 60: top 0.687047 (right 1.19); 0.362953
                1 - (0.595 / R3_2 - R),  # 120: top 0.687047 (left 2.79); 0.362953
                0.0,  # 180: left 1.395, d = 1.345 > 1 m: nothing in range
                1 - (0.395 / R3_2 - R),  # 240: bottom 0.456107 (left 2.79); 0.593893
                1 - (0.395 / R3_2 - R),  # 300: bottom 0.456107 (right 1.19); 0.593893
            ],
        ),
        (
            90,
            [
                1 - (0.595 - R),  # world 90: top 0.595; 0.455
                0.0,  # world 150: top 0.595 / sin 150 = 1.19 (left 1.6108); d = 1.14 > 1
                1 - (0.395 / 0.5 - R),  # world 210: bottom 0.79 (left 1.6108); 0.26
                1 - (0.395 - R),  # world 270: bottom 0.395; 0.655
                1 - (0.595 / R3_2 - R),  # world 330: right 0.687047 (bottom 0.79); 0.362953
                1 - (0.595 / R3_2 - R),  # world 30: right 0.687047 (top 1.19); 0.362953
            ],
        ),
        (
            37,
            [
                # world 37: right 0.595 / cos 37 = 0.745021 (top 0.595 / sin 37 = 0.988676)
                1 - (0.595 / math.cos(math.radians(37)) - R),  # 0.304979
                # world 97: top 0.595 / sin 97 = 0.599468 (left 11.45)
                1 - (0.595 / math.sin(math.radians(97)) - R),  # 0.450532
                # world 157: left 1.395 / cos 23 = 1.515473 (top 1.522786); d > 1
                0.0,
                # world 217: bottom 0.395 / sin 37 = 0.656348 (left 1.746729)
                1 - (0.395 / math.sin(math.radians(37)) - R),  # 0.393652
                # world 277: bottom 0.395 / sin 83 = 0.397966 (right 4.88)
                1 - (0.395 / math.sin(math.radians(83)) - R),  # 0.652034
                # world 337: right 0.595 / cos 23 = 0.646384 (bottom 1.010925)
                1 - (0.595 / math.cos(math.radians(23)) - R),  # 0.403616
            ],
        ),
    ],
)
def test_rangefinders_in_the_room(heading_deg, expected):
    got = ranges(1.4, 0.4, math.radians(heading_deg))
    np.testing.assert_allclose(got, expected, rtol=0, atol=TOL)


def test_rangefinders_touching_a_wall_read_one():
    # Robot at (1.945, 0.5), heading 0: the 0-deg mount point is (1.945 + 0.05, 0.5) =
    # (1.995, 0.5), exactly on the right wall's inner face (2 - 0.005): d = 0, reading 1.
    assert 1.945 + R == 2.0 - 0.005  # the exact touch the test relies on
    expected = [
        1.0,
        1 - (0.05 / 0.5 - R),  # 60: right face 0.05 / cos 60 = 0.1 from the centre; 0.95
        1 - (0.495 / R3_2 - R),  # 120: top face 0.995 - 0.5 = 0.495 / sin 60; 0.478423
        0.0,  # 180: left face 1.94 away
        1 - (0.495 / R3_2 - R),  # 240: bottom face 0.5 - 0.005 = 0.495 / sin 60; 0.478423
        1 - (0.05 / 0.5 - R),  # 300: right face again; 0.95
    ]
    np.testing.assert_allclose(ranges(1.945, 0.5, 0.0), expected, rtol=0, atol=TOL)
    # Closer still (the footprint would overlap the wall): the mount point is inside the
    # wall, which reads as touching too.
    assert ranges(1.948, 0.5, 0.0)[0] == 1.0


def test_rangefinder_reads_zero_at_and_beyond_its_range():
    # Robot at (0.945, 0.5), heading 0: the right face is 1.995 - (0.945 + 0.05) = 1.0 m
    # from the mount point, exactly the range: reading 0. Any farther: still 0.
    assert ranges(0.945, 0.5, 0.0)[0] == pytest.approx(0.0, abs=TOL)
    assert ranges(0.9, 0.5, 0.0)[0] == 0.0
    # 1 mm nearer: d = 0.999, reading 0.001.
    assert ranges(0.946, 0.5, 0.0)[0] == pytest.approx(0.001, abs=TOL)


def test_rangefinders_see_nothing_without_walls():
    nothing = np.zeros(0, np.int64)
    np.testing.assert_array_equal(ranges(1.4, 0.4, 0.3, candidates=nothing), np.zeros(6))


# -- rays that graze wall ends and corners ----------------------------------------------------
# To get a ray that is exactly along +x, the robot's heading is minus the sensor's angle:
# a = -angle + angle = 0 exactly, so the ray is (1, 0) and the mount point is (x + 0.05, y).
# (For other headings cos/sin are only correct to an ulp and a ray along a face line would
# drift off it by ~1e-16 m.) Robot at (0.5, 0.5): mount point (0.55, 0.5).


def post(y0):
    """A vertical wall (0.875, y0) - (0.875, y0 + 0.25), 0.01 thick: x in [0.87, 0.88]."""
    return wall_boxes(np.array([[0.875, y0, 0.875, y0 + 0.25]]), 0.01)


@pytest.mark.parametrize("k", range(6))
def test_ray_along_the_flat_end_of_a_wall(k):
    heading = -LAYOUT.rangefinders.angles[k]
    expected = np.zeros(6)
    # Post from y = 0.5: its flat end lies on the ray's line y = 0.5. The ray touches the end
    # face from the corner (0.87, 0.5) on: d = 0.87 - 0.55 = 0.32, reading 0.68.
    expected[k] = 1 - 0.32
    np.testing.assert_allclose(ranges(0.5, 0.5, heading, boxes=post(0.5)), expected, atol=TOL)
    # Its end a hair below the ray: the ray enters the post's near face at the same d.
    got = ranges(0.5, 0.5, heading, boxes=post(0.5 - EPS))
    np.testing.assert_allclose(got, expected, atol=TOL)
    # Its end a hair above the ray: a miss, nothing in range.
    np.testing.assert_array_equal(ranges(0.5, 0.5, heading, boxes=post(0.5 + EPS)), np.zeros(6))


def test_ray_along_the_long_face_of_a_wall_hits_its_near_corner():
    # A horizontal wall (0.875, 0.5625) - (1.5, 0.5625), 0.125 thick: its bottom face is
    # y = 0.5625 - 0.0625 = 0.5 (exact in binary), on the ray's line. The ray touches the
    # box first at the corner (0.875, 0.5): d = 0.875 - 0.55 = 0.325, reading 0.675.
    wall = wall_boxes(np.array([[0.875, 0.5625, 1.5, 0.5625]]), 0.125)
    assert ranges(0.5, 0.5, 0.0, boxes=wall)[0] == pytest.approx(0.675, abs=TOL)
    wall_above = wall_boxes(np.array([[0.875, 0.5625 + EPS, 1.5, 0.5625 + EPS]]), 0.125)
    assert ranges(0.5, 0.5, 0.0, boxes=wall_above)[0] == 0.0


def test_oblique_ray_past_a_corner():
    # Robot at (0, 0), heading 0; the 60-deg ray starts at 0.05 (cos 60, sin 60) and passes
    # P = 0.55 (cos 60, sin 60) = (0.275, 0.476314) at d = 0.5 from the mount point.
    # A horizontal wall, 0.01 thick, whose bottom-right corner is at P: the box spans
    # x in [P.x - 0.3, P.x], y in [P.y, P.y + 0.01]. The ray comes from below-left and leaves
    # to the right, touching only the corner. Rounding of cos/sin makes "exactly" moot here,
    # so the wall is shifted a hair each way:
    c, s = math.cos(math.pi / 3), math.sin(math.pi / 3)
    px, py = 0.55 * c, 0.55 * s

    def corner_wall(shift):
        x1 = px + shift
        return wall_boxes(np.array([[x1 - 0.3, py + 0.005, x1, py + 0.005]]), 0.01)

    # Shifted right: the ray crosses the bottom face y = P.y at x = P.x, inside it: d = 0.5.
    got = ranges(0.0, 0.0, 0.0, boxes=corner_wall(EPS))
    np.testing.assert_allclose(got, [0, 0.5, 0, 0, 0, 0], atol=TOL)
    # Shifted left: the ray passes right of the box: nothing. (The 120-deg ray crosses
    # y = P.y at x = -0.275, left of the box's x >= -0.025: a miss as well.)
    np.testing.assert_array_equal(ranges(0.0, 0.0, 0.0, boxes=corner_wall(-EPS)), np.zeros(6))


def test_ray_into_the_rooms_corner():
    # Robot at (1.945, 0.945), heading 45 deg: the 0-deg ray aims at the inner corner
    # (1.995, 0.995), 0.05 sqrt2 from the centre, where two boxes overlap: d = 0.05 sqrt2 -
    # 0.05 = 0.0207107, reading 0.9792893.
    got = ranges(1.945, 0.945, math.pi / 4)[0]
    assert got == pytest.approx(1 - (0.05 * math.sqrt(2.0) - R), abs=TOL)


# -- field of view ----------------------------------------------------------------------------


def fov_layout(angle_deg=60.0):
    return SensorLayout.from_dict(
        {
            "rangefinders": {
                "angles_deg": [angle_deg],
                "range": 1.0,
                "mount_radius": R,
                "field_of_view_deg": 30.0,
                "rays": 5,
            }
        }
    )


def test_field_of_view_spreads_the_rays():
    layout = fov_layout()
    expected = np.radians([[45.0, 52.5, 60.0, 67.5, 75.0]])  # 60 + (-15, -7.5, 0, 7.5, 15)
    np.testing.assert_allclose(layout.rangefinders.ray_angles(), expected, atol=TOL)
    # One ray if the field of view is 0 (several rays without one are refused on load).
    single = SensorLayout.from_dict({"rangefinders": {"angles_deg": [10], "range": 1}})
    np.testing.assert_allclose(single.rangefinders.ray_angles(), np.radians([[10.0]]))


def test_field_of_view_reads_the_nearest_of_its_rays():
    # Robot at (1.4, 0.4), heading 0, one sensor at 60 deg with rays at 45 ... 75 deg. The top
    # face (0.595 above the centre) is nearest along the steepest ray: 0.595 / sin 75 =
    # 0.615990 (45: 0.841457 to the top and to the right face alike; 60: 0.687047), so
    # d = 0.565990 and the reading is 0.434010 (the axis ray alone would give 0.362953).
    layout = compile_layout(fov_layout())
    got = read(1.4, 0.4, 0.0, layout=layout)
    assert got[0] == pytest.approx(1 - (0.595 / math.sin(math.radians(75)) - R), abs=TOL)
    # The onboard formula from the five ray distances agrees bit for bit.
    d = [
        cast_ray(1.4 + R * math.cos(a), 0.4 + R * math.sin(a), a, 1.0, ROOM, np.arange(4))
        for a in layout.ray_angles[0]
    ]
    assert rangefinder_readings(np.array([d]), fov_layout().rangefinders)[0] == got[0]


# -- goal sectors -----------------------------------------------------------------------------
SECTOR_0, SECTOR_90, SECTOR_180, SECTOR_270 = np.eye(4)


@pytest.mark.parametrize(
    ("bearing_deg", "expected"),
    [
        (0.0, SECTOR_0),
        (44.999999999, SECTOR_0),  # just below 45: still [-45, 45)
        (45.0, SECTOR_90),  # half-open: 45 starts [45, 135)
        (89.0, SECTOR_90),
        (135.0, SECTOR_180),
        (179.9, SECTOR_180),
        (180.0, SECTOR_180),  # straight behind
        (-180.0, SECTOR_180),
        (-135.0, SECTOR_270),  # -135 = 225 starts [225, 315)
        (-135.000000001, SECTOR_180),
        (-90.0, SECTOR_270),
        (-45.0, SECTOR_0),  # -45 = 315 starts [-45, 45)
        (-45.000000001, SECTOR_270),
        (225.0, SECTOR_270),
        (360.0, SECTOR_0),
        (-350.0, SECTOR_0),
    ],
)
def test_goal_sector_boundaries(bearing_deg, expected):
    bearing = math.radians(bearing_deg)
    got = goal_sector_readings(bearing, LAYOUT.goal_sectors)
    np.testing.assert_array_equal(got, expected)
    # The compiled in_sector is the same formula, bit for bit.
    for k, centre in enumerate(LAYOUT.goal_sectors.centres):
        assert compiled.in_sector(bearing, centre, math.pi / 2) == bool(expected[k])


def toward(world_deg):
    """A goal 1 m from (0.5, 0.5) in the world direction ``world_deg``."""
    a = math.radians(world_deg)
    return 0.5 + math.cos(a), 0.5 + math.sin(a)


@pytest.mark.parametrize(
    ("heading_deg", "goal", "expected", "why"),
    [
        # Robot at (0.5, 0.5); goal offsets are exact, so atan2 gives exact multiples of 45.
        (0, (1.5, 1.5), SECTOR_90, "45 deg left: the 90 sector owns 45"),
        (0, (1.5, -0.5), SECTOR_0, "45 deg right (-45): the 0 sector owns -45"),
        (0, (-0.5, -0.5), SECTOR_270, "-135: the 270 sector"),
        (0, (-0.5, 1.5), SECTOR_180, "135: the 180 sector"),
        (0, (-0.5, 0.5), SECTOR_180, "straight behind"),
        (0, (0.5, 0.0), SECTOR_270, "straight right"),
        # Heading 90: world 135 (goal up-left) is body 135 - 90 = 45, exactly (3pi/4 - pi/2).
        (90, (-0.5, 1.5), SECTOR_90, "heading 90, goal at body 45"),
        (90, (1.5, 0.5), SECTOR_270, "heading 90, goal straight right in the world: body -90"),
        (90, (0.5, -0.5), SECTOR_180, "heading 90, goal below: behind"),
        # Heading 37: world 0 -> body -37 (0 sector); world 90 -> 53 (90); world 180 -> 143
        # (180); world -90 -> -127 = 233 (270); world 100 -> 63 (90); world -60 -> -97 = 263
        # (270); world 10 -> -27 (0).
        (37, (1.5, 0.5), SECTOR_0, "heading 37, world 0"),
        (37, (0.5, 1.5), SECTOR_90, "heading 37, world 90"),
        (37, (-0.5, 0.5), SECTOR_180, "heading 37, world 180"),
        (37, (0.5, -0.5), SECTOR_270, "heading 37, world -90"),
        (37, toward(100), SECTOR_90, "heading 37, world 100"),
        (37, toward(-60), SECTOR_270, "heading 37, world -60"),
        (37, toward(10), SECTOR_0, "heading 37, world 10"),
    ],
)
def test_goal_sectors_from_the_robots_pose(heading_deg, goal, expected, why):
    got = sectors(0.5, 0.5, math.radians(heading_deg), goal)
    np.testing.assert_array_equal(got, expected, err_msg=why)


def test_goal_sectors_tile_the_circle_for_bearings_in_range():
    # Every bearing in [-pi, pi] lights exactly one sector (random and boundary bearings).
    rng = np.random.default_rng(5)
    bearings = [*rng.uniform(-math.pi, math.pi, 4000), *np.radians([-180, -135, -45, 45, 135])]
    for b in bearings:
        assert goal_sector_readings(float(b), LAYOUT.goal_sectors).sum() == 1.0, b


# Each sector once wrapped (bearing - centre) on its own, and rounding at a shared edge
# could light no sector at all; tiling sectors now come from one wrapped angle.
@pytest.mark.parametrize(
    ("bearing", "expected"),
    [
        (math.radians(315.0), SECTOR_0),  # 5.497787143782138 = -45 deg + 2 pi
        (math.radians(405.0), SECTOR_90),  # 7.0685834705770345 = 45 deg + 2 pi
        (-0.7853981633974486, SECTOR_270),  # 3 ulps below -pi/4 (-45 deg)
    ],
)
def test_goal_sectors_tile_the_circle_at_boundaries(bearing, expected):
    np.testing.assert_array_equal(goal_sector_readings(bearing, LAYOUT.goal_sectors), expected)


# Heading -pi, goal at world 135 deg: bearing 3pi/4 + pi = 5.497787143782138 (body -45 deg)
# once lit no goal sector.
def test_goal_sectors_robot_facing_minus_x_goal_up_left():
    # Robot at (0, 0) facing -x (heading -pi, e.g. the start region's heading_deg -180); goal
    # at (-1, 1), world 135 deg: body bearing 135 - (-180) = 315 = -45 deg, the 0 sector.
    np.testing.assert_array_equal(sectors(0.0, 0.0, -math.pi, (-1.0, 1.0)), SECTOR_0)


def test_goal_bearing_input():
    # Layout: 1 rangefinder, the 4 sectors, and the goal bearing, in that order.
    layout = SensorLayout.from_dict(
        {
            "rangefinders": {"angles_deg": [0], "range": 1.0},
            "goal_sectors": {"centres_deg": [0, 90, 180, 270], "width_deg": 90},
            "goal_bearing": True,
        }
    )
    assert layout.input_names()[-1] == "goal_bearing" and layout.n_inputs == 6
    # Robot at (0.5, 0.5) heading 0, goal straight left: bearing pi/2 -> (pi/2 + pi) / 2pi =
    # 0.75. Rangefinder: mount radius 0 here, so d = 1.995 - 0.5 = 1.495 > 1: 0.
    got = read(0.5, 0.5, 0.0, goal=(0.5, 1.5), layout=compile_layout(layout))
    np.testing.assert_array_equal(got, [0.0, *SECTOR_90, 0.75])
    # Only the goal bearing: ahead 0.5, behind 0 (pi wraps to -pi), right 0.25.
    only = compile_layout(SensorLayout.from_dict({"goal_bearing": True}))
    assert read(0.5, 0.5, 0.0, goal=(1.5, 0.5), layout=only)[0] == 0.5
    assert read(0.5, 0.5, 0.0, goal=(-0.5, 0.5), layout=only)[0] == 0.0
    assert read(0.5, 0.5, 0.0, goal=(0.5, -0.5), layout=only)[0] == 0.25
    assert goal_bearing_reading(-math.pi / 2) == 0.25


# -- onboard formulas and the compiled kernel -------------------------------------------------


@pytest.mark.parametrize(
    ("distance", "expected"),
    [
        (0.0, 1.0),  # touching
        (0.25, 0.75),  # (1 - 0.25) / 1
        (1.0, 0.0),  # at the range
        (1.5, 0.0),  # beyond: clipped
        (math.inf, 0.0),  # nothing seen
        (-0.1, 1.0),  # (inside a wall) clipped
    ],
)
def test_range_reading(distance, expected):
    assert range_reading(distance, 1.0) == expected
    assert compiled.range_reading(distance, 1.0) == expected
    # Range 2 m: (2 - d) / 2.
    assert range_reading(0.5, 2.0) == 0.75


def test_rangefinder_readings_take_the_nearest_finite_ray():
    layout = fov_layout().rangefinders  # one sensor, five rays
    assert rangefinder_readings(np.array([[0.9, 0.4, math.inf, 0.6, 0.5]]), layout)[0] == 0.6
    assert rangefinder_readings(np.array([[math.inf] * 5]), layout)[0] == 0.0  # REP 117 +inf
    six = np.array([[0.0], [0.25], [0.5], [1.0], [2.0], [math.inf]])
    np.testing.assert_array_equal(
        rangefinder_readings(six, LAYOUT.rangefinders), [1.0, 0.75, 0.5, 0.0, 0.0, 0.0]
    )


@pytest.fixture(scope="module")
def obstacle():
    return load_named_maze("obstacle")


def test_compiled_kernel_equals_the_onboard_formulas_bit_for_bit(obstacle):
    boxes = obstacle.boxes
    grid = WallGrid.build(boxes, COMPILED.reach())
    every = np.arange(len(boxes), dtype=np.int64)
    tx, ty = obstacle.target
    x0, y0, x1, y1 = obstacle.bounds()
    rng = np.random.default_rng(21)
    checked = 0
    while checked < 300:
        x, y = rng.uniform(x0, x1), rng.uniform(y0, y1)
        if obstacle.clearance(x, y) < R:
            continue
        heading = rng.uniform(-4.0, 4.0)
        got = read(x, y, heading, goal=(tx, ty), boxes=boxes, candidates=grid.candidates(x, y))
        # The same pose with every wall as a candidate: identical.
        np.testing.assert_array_equal(read(x, y, heading, goal=(tx, ty), boxes=boxes), got)
        # Onboard: distances from the mount points, then the onboard formulas.
        d = np.empty(COMPILED.ray_angles.shape)
        for s in range(d.shape[0]):
            a = heading + COMPILED.ray_angles[s, 0]
            ox, oy = x + R * math.cos(a), y + R * math.sin(a)
            d[s, 0] = cast_ray(ox, oy, a, 1.0, boxes, every)
        onboard = np.concatenate(
            [
                rangefinder_readings(d, LAYOUT.rangefinders),
                goal_sector_readings(math.atan2(ty - y, tx - x) - heading, LAYOUT.goal_sectors),
            ]
        )
        np.testing.assert_array_equal(got, onboard)
        checked += 1


def test_in_sector_is_half_open():
    w = math.pi / 2
    assert in_sector(-math.pi / 4, 0.0, w) and not in_sector(math.pi / 4, 0.0, w)
    assert in_sector(math.pi / 4, math.pi / 2, w)


# -- layout files -----------------------------------------------------------------------------


_DELETE = object()  # marks a key to remove


def shipped():
    return yaml.safe_load((config_dir() / "sensors" / "4ws.yaml").read_text())


def edited(section, key, value):
    data = shipped()
    if section is None:
        data[key] = value
    elif value is _DELETE:
        del data[section][key]
    else:
        data[section][key] = value
    return data


@pytest.mark.parametrize(
    ("section", "key", "value", "named"),
    [
        (None, "rangefinder", {"range": 1}, "'rangefinder'"),  # unknown top-level key
        ("rangefinders", "fov_deg", 30, "rangefinders.fov_deg"),  # unknown nested key
        ("goal_sectors", "radius", 1, "goal_sectors.radius"),
        ("rangefinders", "angles_deg", "0, 60, 120", "rangefinders.angles_deg"),
        ("rangefinders", "angles_deg", [], "rangefinders.angles_deg"),
        ("rangefinders", "angles_deg", [0, ".nan"], "rangefinders.angles_deg"),
        ("rangefinders", "angles_deg", [0, True], "rangefinders.angles_deg"),
        ("rangefinders", "angles_deg", _DELETE, "rangefinders.angles_deg"),
        ("rangefinders", "rays", 0, "rangefinders.rays"),
        ("rangefinders", "rays", 2.5, "rangefinders.rays"),
        ("rangefinders", "rays", True, "rangefinders.rays"),
        ("rangefinders", "range", -1.0, "rangefinders.range"),
        ("rangefinders", "range", 0, "rangefinders.range"),
        ("rangefinders", "range", "1 m", "rangefinders.range"),
        ("rangefinders", "range", _DELETE, "rangefinders.range"),
        ("rangefinders", "mount_radius", -0.05, "rangefinders.mount_radius"),
        ("rangefinders", "field_of_view_deg", -30, "rangefinders.field_of_view_deg"),
        ("goal_sectors", "width_deg", 0, "goal_sectors.width_deg"),
        ("goal_sectors", "centres_deg", ["north"], "goal_sectors.centres_deg"),
        (None, "goal_bearing", "yes", "goal_bearing"),
        (None, "rangefinders", [0, 60], "rangefinders"),
    ],
)
def test_layout_file_errors_name_the_file_and_key(tmp_path, section, key, value, named):
    data = edited(section, key, value)
    text = yaml.safe_dump(data)
    if value == [0, ".nan"]:
        text = text.replace("'.nan'", ".nan")  # a YAML NaN, not the string
    path = tmp_path / "robot_sensors.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as err:
        SensorLayout.load(path)
    message = str(err.value)
    assert str(path) in message and named in message, message
    assert "\n" not in message


def test_layout_file_without_inputs_and_missing_file(tmp_path):
    path = tmp_path / "empty.yaml"
    path.write_text("{}\n")
    with pytest.raises(ConfigError, match=re.escape("empty.yaml: the layout has no inputs")):
        SensorLayout.load(path)
    with pytest.raises(ConfigError, match=re.escape("nowhere.yaml")):
        SensorLayout.load(tmp_path / "nowhere.yaml")


def test_layout_round_trip_and_fingerprint():
    data = LAYOUT.to_dict()
    assert data["rangefinders"]["range"] == 1.0 and data["goal_sectors"]["width_deg"] == 90.0
    again = SensorLayout.from_dict(data)
    assert again == LAYOUT
    assert again.fingerprint() == LAYOUT.fingerprint()
    assert again.to_dict() == data
    # Through JSON too (arbitrator files are JSON).
    assert SensorLayout.from_dict(json.loads(json.dumps(data))) == LAYOUT
    assert len(LAYOUT.fingerprint()) == 16


@pytest.mark.parametrize(
    ("section", "key", "value"),
    [
        ("rangefinders", "range", 1.5),
        ("rangefinders", "mount_radius", 0.04),
        ("rangefinders", "field_of_view_deg", 10.0),
        ("rangefinders", "angles_deg", [0, 60, 120, 180, 240, 301]),
        ("goal_sectors", "centres_deg", [0, 90, 180, 271]),
        ("goal_sectors", "width_deg", 91),
        (None, "goal_bearing", True),
    ],
)
def test_fingerprint_changes_with_any_value(section, key, value):
    changed = SensorLayout.from_dict(edited(section, key, value))
    assert changed != LAYOUT
    assert changed.fingerprint() != LAYOUT.fingerprint()
    # ... and is a function of the values only.
    assert SensorLayout.from_dict(edited(section, key, value)).fingerprint() == (
        changed.fingerprint()
    )


def test_fingerprint_survives_a_round_trip_for_awkward_angles():
    # 3 deg etc.: radians(degrees(radians(3))) is 1 ulp off radians(3), but the saved
    # degrees are stable after one trip, so the fingerprint an arbitrator file records
    # still matches.
    data = {"rangefinders": {"angles_deg": [3, 57, 96, 201, -24], "range": 1.0}}
    layout = SensorLayout.from_dict(data)
    again = SensorLayout.from_dict(layout.to_dict())
    assert again.fingerprint() == layout.fingerprint()
    assert again.to_dict() == layout.to_dict()


def test_layout_round_trip_is_exact_for_any_angle():
    # Files hold degrees rounded to 1e-9, so radians(degrees(x)) comes back as x.
    data = {"rangefinders": {"angles_deg": [3, 57, 96, 201, -24, 60], "range": 1.0}}
    layout = SensorLayout.from_dict(data)
    assert SensorLayout.from_dict(layout.to_dict()) == layout
    assert layout.to_dict()["rangefinders"]["angles_deg"][-1] == 60.0


def test_several_rays_need_a_field_of_view():
    data = {"rangefinders": {"angles_deg": [0], "range": 1.0, "rays": 3}}
    with pytest.raises(ConfigError, match="rays is 3 but field_of_view_deg is 0"):
        SensorLayout.from_dict(data, "layout.yaml")


def test_exactly_one_tiling_sector_lights_near_every_edge():
    # Bearings a few ulps either side of each edge, also one and two turns away: the
    # onboard and compiled readings both light exactly one of the four sectors.
    edges = [math.radians(e) for e in (-45.0, 45.0, 135.0, 225.0)]
    bearings = []
    for edge in edges:
        for turns in (-2, -1, 0, 1, 2):
            b = edge + turns * 2 * math.pi
            for _ in range(4):
                bearings += [b, np.nextafter(b, np.inf), np.nextafter(b, -np.inf)]
                b = np.nextafter(b, np.inf)
    gs = LAYOUT.goal_sectors
    first, width, n = gs.centres[0], gs.width, len(gs.centres)
    for b in bearings:
        assert goal_sector_readings(b, gs).sum() == 1.0, b
        assert 0 <= compiled.tiling_sector(b, first, width, n) < n
        assert compiled.tiling_sector(b, first, width, n) == int(
            np.argmax(goal_sector_readings(b, gs))
        )


@pytest.mark.parametrize(
    ("change", "needle"),
    [
        ({"range": 300.0}, "rangefinders.range must be a number > 0 and <= 50"),
        ({"rays": 10**6, "field_of_view_deg": 30.0}, "rays must be an integer from 1 to 100"),
        ({"angles_deg": [0.0] * 361}, "angles_deg must be a list of 1 to 360 numbers"),
        ({"mount_radius": 300.0}, "mount_radius must be a number >= 0 and <= 2"),
    ],
)
def test_a_layout_that_would_exhaust_the_machine_is_refused(change, needle):
    # A 300 m range (a fuzzed layout swapped a beam angle into it) asked for 1.4 GiB of
    # lookup table at once: an internal error, not a refusal.
    data = yaml.safe_load((config_dir() / "sensors" / "4ws.yaml").read_text())
    data["rangefinders"].update(change)
    with pytest.raises(ConfigError, match=re.escape(needle)):
        SensorLayout.from_dict(data, "layout.yaml")


def test_a_motion_window_of_1e300_s_is_refused():
    # It ended in OverflowError (float infinity to integer) when the window was counted.
    data = yaml.safe_load((config_dir() / "sensors" / "4ws-p8m.yaml").read_text())
    data["motion"]["window"] = 1e300
    with pytest.raises(
        ConfigError, match=re.escape("motion.window must be a number > 0 and <= 60")
    ):
        SensorLayout.from_dict(data, "layout.yaml")
