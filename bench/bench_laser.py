"""Benchmark: the laser node's conversion of one LaserScan into rangefinder readings.

Prints, for this machine, the microseconds per scan of ``LaserToRangefinders.readings``
(the laser node's whole per-scan work apart from ROS itself): the 4WS layout (six rays) and
the hexapod layout (five 30-deg fields of view), 360/720/1440 beams over a full turn, with
the scanner at the body centre and 0.1 m off it (and off it with 5 % of the beams NaN).
The hexapod's own 25-beam scanner is measured too. Scans come from 50 poses in the
``obstacle`` maze (PyBullet-free box ray casts, 2 m range).

A real 2D lidar sends 10-40 scans/s of 360-1440 beams; at 40 scans/s a core has 25 000 us
per scan.

Run: ``.venv/bin/python bench/bench_laser.py``.
"""

from __future__ import annotations

import math
import statistics
import time

import numpy as np
from bench_repertoire import machine

from evorbc_ros.config import config_dir
from evorbc_ros.laser import LaserPose, LaserToRangefinders
from evorbc_ros.sensors import SensorLayout
from sim_bridge.geometry import cast_ray_dir
from sim_bridge.hexapod.scanner import Scanner
from sim_bridge.maze import load_named_maze

RANGE_MAX = 2.0  # m, as the bridge's laser
POSES = 50
OFFSET = LaserPose(0.0, 0.1, 0.0)  # the scanner


def scans(maze, starts, pose, angle_min, increment, n):
    """Ranges (float32, +inf for no return) of a scanner at ``pose`` on the robot."""
    every = np.arange(len(maze.boxes), dtype=np.int64)
    beams = angle_min + increment * np.arange(n)
    out = []
    for x, y, h in starts:
        ox = x + math.cos(h) * pose.x - math.sin(h) * pose.y
        oy = y + math.sin(h) * pose.x + math.cos(h) * pose.y
        a = h + pose.yaw + beams
        r = np.array(
            [
                cast_ray_dir(ox, oy, math.cos(b), math.sin(b), RANGE_MAX, maze.boxes, every)
                for b in a
            ]
        )
        out.append(np.where(r < RANGE_MAX, r, np.inf).astype(np.float32))
    return out


def per_scan_us(converter, angle_min, increment, ranges_list, repeats=5) -> float:
    """Median over ``repeats`` of the mean time (us) of one ``readings`` call."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        for r in ranges_list:
            converter.readings(angle_min, increment, r, 0.0, RANGE_MAX)
        times.append((time.perf_counter() - start) / len(ranges_list) * 1e6)
    return statistics.median(times)


def main() -> None:
    maze = load_named_maze("obstacle")
    starts = maze.sample_starts(np.random.default_rng(0), POSES, 0.05)
    layouts = {
        name: SensorLayout.load(config_dir() / "sensors" / f"{name}.yaml").rangefinders
        for name in ("4ws", "hexapod")
    }
    rng = np.random.default_rng(1)
    print(f"machine: {machine()}")
    print("us per scan (median of 5 passes over 50 scans)")
    print(f"{'layout':8} {'beams':>6} {'centred':>9} {'offset':>9} {'offset, 5 % NaN':>16}")
    for name, layout in layouts.items():
        spans = [(-math.pi, 2 * math.pi / n, n) for n in (360, 720, 1440)]
        if name == "hexapod":
            s = Scanner.from_layout(layout)
            spans.append((s.angle_min, s.angle_increment, s.beams))
        for angle_min, inc, n in spans:
            row = []
            for pose in (LaserPose(), OFFSET):
                ranges = scans(maze, starts, pose, angle_min, inc, n)
                row.append(per_scan_us(LaserToRangefinders(layout, pose), angle_min, inc, ranges))
            dropped = [np.where(rng.random(n) < 0.05, np.nan, r) for r in ranges]
            row.append(per_scan_us(LaserToRangefinders(layout, OFFSET), angle_min, inc, dropped))
            print(f"{name:8} {n:6d} {row[0]:9.0f} {row[1]:9.0f} {row[2]:16.0f}")


if __name__ == "__main__":
    main()
