"""LaserScan -> rangefinder readings for scans from any stack (the laser node's pure code)."""

import math

import numpy as np
import pytest

from evorbc_ros.config import config_dir
from evorbc_ros.laser import InputError, LaserPose, LaserToRangefinders
from evorbc_ros.sensors import SensorLayout
from sim_bridge.four_ws.world import FourWSWorld
from sim_bridge.maze import load_named_maze
from sim_bridge.sensors import compile_layout, read_sensors
from sim_bridge.world import LaserConfig

LAYOUT = SensorLayout.load(config_dir() / "sensors" / "4ws.yaml")
RF = LAYOUT.rangefinders  # six rays at 0, 60, ..., 300 deg, 1 m from a 0.05 m mount radius
DEG = math.pi / 180
CENTRED = LaserPose()  # scanner at the body centre, facing forward


def room_ranges(beam_angles, pose=CENTRED):
    """Ranges of a scanner at ``pose`` inside a circle of radius 0.5 m around the body
    centre (distance along each beam to the circle), so every rangefinder sees 0.45 m."""
    out = []
    for a in beam_angles:
        d = (math.cos(a + pose.yaw), math.sin(a + pose.yaw))
        b = pose.x * d[0] + pose.y * d[1]
        c = pose.x**2 + pose.y**2 - 0.25
        out.append(-b + math.sqrt(b * b - c))
    return np.array(out)


def convert(angle_min, increment, ranges, pose=CENTRED, range_min=0.0, range_max=10.0):
    return LaserToRangefinders(RF, pose).readings(
        angle_min, increment, ranges, range_min, range_max
    )


def test_full_scan_with_hundreds_of_beams():
    beams = -math.pi + 2 * math.pi / 720 * np.arange(720)
    readings = convert(-math.pi, 2 * math.pi / 720, room_ranges(beams))
    # Wall 0.5 m from the centre, 0.45 m from each mount point: (1 - 0.45) / 1.
    np.testing.assert_allclose(readings, 0.55, atol=1e-12)


def test_partial_scan_leaves_unseen_directions_empty():
    # A scan from -100 to 130 deg covers the 0, 60, 120 and 300 deg rangefinders only.
    beams = np.radians(np.arange(-100.0, 130.5, 1.0))
    readings = convert(beams[0], DEG, room_ranges(beams))
    np.testing.assert_allclose(readings, [0.55, 0.55, 0.55, 0.0, 0.0, 0.55], atol=1e-12)
    unseen = LaserToRangefinders(RF).unseen(beams[0], DEG, beams.size)
    assert [a % 360 for a in unseen] == [180.0, 240.0]  # the node warns about these once


def test_decreasing_increments_give_the_same_readings():
    up = np.radians(np.arange(-180.0, 180.0, 0.5))
    ranges = 0.3 + 0.2 * np.cos(3 * up)  # direction-dependent, so order matters
    down_angles = up[::-1]
    a = convert(up[0], 0.5 * DEG, ranges)
    b = convert(down_angles[0], -0.5 * DEG, ranges[::-1])
    np.testing.assert_allclose(a, b, atol=1e-12)
    want = [1 - (0.3 + 0.2 * math.cos(3 * math.radians(s)) - 0.05) for s in range(0, 360, 60)]
    np.testing.assert_allclose(a, want, atol=1e-12)


def test_scanner_rotated_from_the_robot_frame():
    # Mounted facing left (yaw +90 deg): its beam at -90 deg looks along the robot's +x.
    pose = LaserPose(yaw=math.pi / 2)
    beams = np.radians(np.arange(-180.0, 180.0, 1.0))
    body_dirs = beams + pose.yaw
    ranges = 0.3 + 0.2 * np.cos(body_dirs)  # a shape fixed to the robot body
    readings = convert(beams[0], DEG, ranges, pose)
    want = [1 - (0.3 + 0.2 * math.cos(math.radians(s)) - 0.05) for s in range(0, 360, 60)]
    np.testing.assert_allclose(readings, want, atol=1e-12)


def test_scanner_offset_from_the_body_centre():
    # Scanner 0.1 m ahead of the centre; the same 0.5 m circle around the centre.
    pose = LaserPose(x=0.1)
    beams = np.radians(np.arange(-180.0, 180.0, 0.25))
    readings = convert(beams[0], 0.25 * DEG, room_ranges(beams, pose), pose)
    # The circle is rebuilt from chords between neighbouring hits, each within 2 um of it
    # (0.25 deg apart), and the rays cast from the mount points: 0.45 m from each.
    np.testing.assert_allclose(readings, 0.55, atol=5e-6)


@pytest.mark.parametrize(
    ("value", "reading", "meaning"),
    [
        (math.inf, 0.0, "no return within range: nothing seen"),
        (-math.inf, 1.0, "closer than range_min: touching"),
        (0.4, 0.65, "a plain range: 1 - (0.4 - 0.05)"),
        (15.0, 0.0, "beyond range_max: no return"),
    ],
)
def test_rep117_values(value, reading, meaning):
    beams = np.radians(np.arange(-180.0, 180.0, 1.0))
    ranges = np.full(beams.size, 0.4)
    ranges[180] = value  # the beam at 0 deg
    assert convert(beams[0], DEG, ranges)[0] == pytest.approx(reading, abs=1e-12), meaning


FOV_LAYOUT = SensorLayout.from_dict(
    {"rangefinders": {"angles_deg": [0, 90], "range": 1.0, "mount_radius": 0.05,
                      "field_of_view_deg": 30, "rays": 5}}
).rangefinders  # fmt: skip


def test_invalid_beams_are_skipped_when_others_cover_the_rangefinder():
    beams = np.radians(np.arange(-180.0, 180.0, 1.0))
    ranges = np.full(beams.size, 0.6)
    ranges[180] = math.nan  # 0 deg: invalid, skipped
    ranges[180 + 5] = 0.01  # 5 deg: finite but below range_min, invalid too
    ranges[180 - 10] = 0.4  # -10 deg: the nearest valid beam
    readings = LaserToRangefinders(FOV_LAYOUT).readings(beams[0], DEG, ranges, 0.02, 10.0)
    np.testing.assert_allclose(readings, [1 - 0.35, 1 - 0.55], atol=1e-12)


@pytest.mark.parametrize(
    ("index", "value", "axis"),
    [(180, math.nan, "0.0"), (240, 0.01, "60.0"), (300, math.nan, "120.0")],
)
def test_a_rangefinder_whose_beams_are_all_invalid_refuses_the_scan(index, value, axis):
    # One-ray rangefinders: beams within 2.5 deg of the axis count (1 deg spacing). With
    # all five invalid, reading "nothing seen" would let the robot walk blind that way.
    beams = np.radians(np.arange(-180.0, 180.0, 1.0))
    ranges = np.full(beams.size, 0.4)
    ranges[index - 2 : index + 3] = value
    with pytest.raises(InputError, match=f"rangefinder at {axis} deg"):
        convert(beams[0], DEG, ranges, range_min=0.02)
    nan_everywhere = np.full(beams.size, math.nan)
    with pytest.raises(InputError, match="360 of the scan's 360 ranges"):
        LaserToRangefinders(FOV_LAYOUT).readings(beams[0], DEG, nan_everywhere, 0.0, 10.0)


def test_field_of_view_takes_the_nearest_beam_inside_it():
    layout = SensorLayout.from_dict(
        {
            "rangefinders": {
                "angles_deg": [0],
                "range": 1.0,
                "mount_radius": 0.05,
                "field_of_view_deg": 30,
                "rays": 5,
            }
        }
    ).rangefinders
    beams = np.radians(np.arange(-180.0, 180.0, 1.0))
    ranges = np.full(beams.size, 0.9)
    ranges[180 + 14] = 0.3  # 14 deg: inside +-15 deg
    ranges[180 - 16] = 0.1  # -16 deg: outside
    readings = LaserToRangefinders(layout).readings(beams[0], DEG, ranges, 0.0, 10.0)
    assert readings[0] == pytest.approx(1 - 0.25)


@pytest.mark.parametrize(
    ("angle_min", "increment", "ranges", "needle"),
    [
        (math.nan, DEG, [1.0], "angle_min"),
        (0.0, 0.0, [1.0, 2.0], "angle_increment is 0"),
        (0.0, math.inf, [1.0], "angle_increment"),
        (0.0, DEG, [], "no ranges"),
    ],
)
def test_malformed_scans_are_refused(angle_min, increment, ranges, needle):
    with pytest.raises(InputError, match=needle):
        convert(angle_min, increment, ranges)
    with pytest.raises(InputError, match="range limits"):
        convert(0.0, DEG, [1.0], range_min=2.0, range_max=1.0)


def test_simulated_laser_gives_the_offline_readings():
    # The bridge's laser (PyBullet rays from the centre, sent as float32 like a real
    # LaserScan) through the laser node's code equals the offline sensors within 0.1 mm.
    maze = load_named_maze("obstacle")
    world = FourWSWorld(maze, "4ws-5", laser=LaserConfig())
    c = compile_layout(LAYOUT)
    converter = LaserToRangefinders(RF)
    out = np.empty(c.n_inputs)
    every = np.arange(len(maze.boxes), dtype=np.int64)
    rng = np.random.default_rng(0)
    try:
        for x, y, h in maze.sample_starts(rng, 60, 0.05):
            world.state[0, :3] = (x, y, h)
            ranges = world.scan().astype(np.float32)
            laser = world.laser
            got = converter.readings(laser.angle_min, laser.increment, ranges, 0.0, laser.range_max)
            read_sensors(x, y, h, *maze.target, x, y, c, maze.boxes, every, out)
            np.testing.assert_allclose(got, out[:6], atol=1e-4)  # 0.1 mm of 1 m
    finally:
        world.close()
