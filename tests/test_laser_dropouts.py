"""Dropouts do not blind the robot (issue 18, item 2): invalid beams near a rangefinder's
axis are bridged by the valid beams around them; only a rangefinder no valid beam covers
refuses the scan. Also the beam-count rule."""

import math

import numpy as np
import pytest

from evorbc_ros.config import config_dir
from evorbc_ros.laser import InputError, LaserToRangefinders, beam_tolerance, check_beam_count
from evorbc_ros.sensors import SensorLayout
from sim_bridge.four_ws.world import FourWSWorld
from sim_bridge.legged.scanner import Scanner
from sim_bridge.maze import load_named_maze
from sim_bridge.world import LaserConfig

RF = SensorLayout.load(config_dir() / "sensors" / "4ws.yaml").rangefinders
HEXAPOD = SensorLayout.load(config_dir() / "sensors" / "hexapod.yaml").rangefinders
DEG = math.pi / 180
BEAMS = np.radians(np.arange(-180.0, 180.0, 1.0))  # 360 beams, one on each 4WS axis
AXES = [180, 240, 300, 0, 60, 120]  # beam index on the axes 0, 60, ..., 300 deg


def wavy(beams=BEAMS):
    """Ranges that differ from beam to beam, so a stand-in beam is visible in a reading."""
    return 0.3 + 0.2 * np.cos(3 * beams) + 0.01 * np.sin(17 * beams)


def read(ranges, range_min=0.0, layout=RF, angle_min=BEAMS[0], inc=DEG):
    return LaserToRangefinders(layout).readings(angle_min, inc, ranges, range_min, 10.0)


@pytest.fixture(scope="module")
def maze_scans():
    """Clean scans of the bridge's 360-beam laser from 40 poses in the obstacle maze."""
    maze = load_named_maze("obstacle")
    world = FourWSWorld(maze, "4ws-5", laser=LaserConfig())
    try:
        scans = []
        for x, y, h in maze.sample_starts(np.random.default_rng(1), 40, 0.05):
            world.state[0, :3] = (x, y, h)
            scans.append(world.scan().astype(np.float32))
        return world.laser, scans
    finally:
        world.close()


def test_the_tolerance_is_a_few_beams_within_1_to_5_degrees():
    assert math.degrees(beam_tolerance(2 * math.pi / 360)) == pytest.approx(2.5)
    assert math.degrees(beam_tolerance(-2 * math.pi / 720)) == pytest.approx(1.25)
    assert math.degrees(beam_tolerance(2 * math.pi / 1440)) == pytest.approx(1.0)  # floor
    assert math.degrees(beam_tolerance(7.5 * DEG)) == pytest.approx(5.0)  # the hexapod: cap
    assert math.degrees(beam_tolerance(12 * DEG)) == pytest.approx(6.0, abs=1e-3)  # half a gap


@pytest.mark.parametrize("value", [math.nan, 0.01])
@pytest.mark.parametrize("k", range(6))
def test_one_dead_beam_on_an_axis_is_bridged_by_its_neighbours(k, value):
    ranges = wavy()
    ranges[AXES[k]] = value  # NaN, or below range_min: invalid either way
    got = read(ranges, range_min=0.02)
    neighbours = [1 - (ranges[AXES[k] + d] - 0.05) for d in (-1, 1)]
    assert got[k] in neighbours  # the nearest valid beam, 1 deg off the axis
    others = [j for j in range(6) if j != k]
    np.testing.assert_array_equal(got[others], read(wavy(), range_min=0.02)[others])


def test_a_run_of_four_dead_beams_is_bridged_and_five_around_the_axis_blind_it():
    ranges = wavy()
    ranges[178:182] = math.nan  # -2 .. +1 deg around the 0 deg axis
    assert read(ranges)[0] == 1 - (ranges[182] - 0.05)  # +2 deg: the nearest valid beam
    ranges[182] = math.nan  # now -2 .. +2 deg: no valid beam within 2.5 deg
    with pytest.raises(InputError, match=r"rangefinder at 0\.0 deg .*within 2\.5 deg"):
        read(ranges)


def test_a_ten_degree_dead_sector_away_from_the_axes_changes_nothing():
    clean = read(wavy())
    for start in (5, 25, 45, 75, 95, 130, 205, 250, 305, 345):  # deg, sector [start, start + 10)
        ranges = wavy()
        dead = ((np.degrees(BEAMS) - start) % 360) < 10
        ranges[dead] = math.nan
        np.testing.assert_array_equal(read(ranges), clean)


def test_five_percent_random_dropouts_leave_readings_close_to_the_clean_ones(maze_scans):
    laser, scans = maze_scans
    converter = LaserToRangefinders(RF)
    rng = np.random.default_rng(18)
    used = total = 0
    change = []
    for ranges in scans:
        clean = converter.readings(laser.angle_min, laser.increment, ranges, 0.0, laser.range_max)
        for _ in range(25):
            r = ranges.copy()
            r[rng.random(r.size) < 0.05] = np.nan
            total += 1
            try:
                got = converter.readings(laser.angle_min, laser.increment, r, 0.0, laser.range_max)
            except InputError:
                continue
            used += 1
            change += list(np.abs(got - clean))
    assert total == 1000 and used >= 990  # at least 99 % of the scans give readings
    # A reading changes only when the beam on its axis is dead (5 %); its stand-in, 1-2 deg
    # off, sees the same wall a few millimetres away, or, at a wall's end, past it.
    change = np.array(change)
    assert np.mean(change == 0.0) >= 0.95
    assert np.quantile(change, 0.99) <= 0.02  # 2 cm of the 1 m range
    assert change.max() <= 0.1


def test_the_hexapod_groups_read_their_valid_beams():
    s = Scanner.from_layout(HEXAPOD)
    ranges = np.linspace(0.5, 1.7, s.beams)
    ranges[[0, 1, 2, 3]] = math.nan  # four of the first group's five beams
    got = read(ranges, layout=HEXAPOD, angle_min=s.angle_min, inc=s.angle_increment)
    assert got[0] == pytest.approx(1 - ranges[4] / 2.0)
    ranges[4] = 0.01  # the fifth: the group is blind (its neighbours are 7.5 deg away)
    with pytest.raises(InputError, match=r"rangefinder at -75\.0 deg"):
        read(ranges, range_min=0.05, layout=HEXAPOD, angle_min=s.angle_min, inc=s.angle_increment)


def test_the_refusal_counts_every_invalid_beam():
    ranges = wavy()
    ranges[[178, 180, 182]] = math.nan
    ranges[[179, 181]] = 0.01
    ranges[90] = -0.5  # negative ranges are below range_min too
    with pytest.raises(
        InputError,
        match=r"6 of the scan's 360 ranges are invalid \(3 NaN, 3 below range_min 0\.02 m\)",
    ):
        read(ranges, range_min=0.02)
    with pytest.raises(
        InputError, match=r"360 of the scan's 360 ranges are invalid \(0 NaN, 360 below"
    ):
        read(np.full(360, 0.01), range_min=0.02)


@pytest.mark.parametrize(
    ("angle_max_deg", "accepted"),
    [
        (179.0, True),  # angle_min + (n - 1) * increment: REP 138
        (180.0, True),  # one increment more: closes the full turn (common in drivers)
        (178.0, True),  # one increment less
        (179.5, True),  # the end of the last beam's interval
        (177.0, False),  # two beams more than the angles hold
        (181.0, False),
        (89.0, False),  # the ranges of a 270-beam scan with this increment
    ],
)
def test_the_beam_count_must_agree_with_the_angles(angle_max_deg, accepted):
    ranges = wavy()
    converter = LaserToRangefinders(RF)
    args = (BEAMS[0], DEG, ranges, 0.0, 10.0)
    if accepted:
        np.testing.assert_array_equal(
            converter.readings(*args, angle_max=math.radians(angle_max_deg)),
            converter.readings(*args),
        )
    else:
        with pytest.raises(InputError, match=r"the scan has 360 ranges, but .* hold \d+ beams"):
            converter.readings(*args, angle_max=math.radians(angle_max_deg))


def test_float32_angles_pass_the_beam_count_rule():
    for n in (25, 360, 720, 1440, 2000):
        inc = np.float32(2 * math.pi / n)
        lo = np.float32(-math.pi)
        check_beam_count(float(lo), float(np.float32(lo + inc * (n - 1))), float(inc), n)
    s = Scanner.from_layout(HEXAPOD)
    check_beam_count(s.angle_min, s.angle_max, s.angle_increment, s.beams)
