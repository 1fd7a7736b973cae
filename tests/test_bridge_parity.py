"""The bridge's world (PyBullet contact and rays) against the offline simulator."""

import math

import numpy as np
import pytest

from evorbc_ros.robots.four_ws import FourWSGeometry
from sim_bridge.four_ws.motion import STATE_SIZE, motion_limits, step_robot
from sim_bridge.four_ws.world import FourWSWorld
from sim_bridge.geometry import cast_ray
from sim_bridge.maze import load_named_maze, maze_names

LIM = motion_limits(FourWSGeometry())
SENSOR_ANGLES = np.radians([0, 60, 120, 180, 240, 300])


@pytest.mark.parametrize("name", maze_names())
def test_same_commands_same_trajectory_and_ranges_for_1200_cycles(name):
    maze = load_named_maze(name)
    world = FourWSWorld(maze, "4ws-5")
    offline = np.zeros((1, STATE_SIZE))
    offline[0, :3] = maze.start_pose
    every = np.arange(len(maze.boxes), dtype=np.int64)
    rng = np.random.default_rng(5)
    blocked = 0
    worst_range = 0.0
    try:
        for t in range(1200):
            if t % 10 == 0:  # a new random command every second, often into a wall
                command = np.concatenate([[rng.uniform(-0.2, 0.2)], rng.uniform(-0.8, 0.8, 4)])
            moved = world.step(command)
            step_robot(offline, 0, command, LIM, maze.boxes, every)
            blocked += moved == 0.0 and abs(command[0]) > 0.05
            np.testing.assert_allclose(world.state[0, :3], offline[0, :3], atol=1e-3)
            if t % 25 == 0:
                x, y, h = world.pose
                ranges = world.scan()  # from the centre, 360 beams from -180 deg
                for a in SENSOR_ANGLES:
                    offset = (a - world.laser.angle_min) % (2 * math.pi)
                    beam = round(offset / world.laser.increment) % world.laser.beams
                    mount = (x + 0.05 * math.cos(h + a), y + 0.05 * math.sin(h + a))
                    want = cast_ray(*mount, h + a, 1.0, maze.boxes, every)
                    if want < 1.0:
                        worst_range = max(worst_range, abs(ranges[beam] - 0.05 - want))
    finally:
        world.close()
    assert blocked > 100  # the walls were tested, not just free space
    assert worst_range <= 1e-4  # 0.1 mm
