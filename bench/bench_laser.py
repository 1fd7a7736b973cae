"""Benchmark: the laser node's conversion of one LaserScan into rangefinder readings.

Prints, for this machine, the CPU microseconds per scan of ``LaserToRangefinders.readings``
(the laser node's whole per-scan work apart from ROS itself): the 4WS layout (six rays) and
the hexapod layout (five 30-deg fields of view), 360/720/1440 beams over a full turn, with
the scanner at the body centre and 0.1 m off it (and off it with 5 % of the beams NaN).
The hexapod's own 25-beam scanner is measured too. Scans come from 50 poses in the
``obstacle`` maze (PyBullet-free box ray casts, 2 m range).

A real 2D lidar sends 10-40 scans/s of 360-1440 beams; at 40 scans/s a core has 25 000 us
per scan.

With ``--graph``: the dropout tolerance through the ROS 2 graph. The lockstep graph runs
the paper-protocol 4ws-5 controller (``paper_arbitrator``, whose figures are recorded) in
the ``obstacle`` maze with a relay between the bridge's
``scan`` and the laser node that knocks out 5 % or 20 % of the beams (independently,
seeded) and a fixed 10-deg sector; it prints the share of scans that gave readings and
whether the target was reached. Start it in a network namespace of its own if other ROS 2
graphs run on the machine.

It also prints how many scans give readings with 5 % and 20 % random NaN beams (and how
much the readings change), beside the code before issue 18.

Run: ``.venv/bin/python bench/bench_laser.py [--graph]``.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from bench_repertoire import machine

from evorbc_ros.config import config_dir
from evorbc_ros.laser import InputError, LaserPose, LaserToRangefinders
from evorbc_ros.sensors import SensorLayout
from sim_bridge.geometry import cast_ray_dir
from sim_bridge.legged.scanner import Scanner
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


def per_scan_us(converter, angle_min, increment, ranges_list, repeats=9) -> float:
    """CPU time (us) of one ``readings`` call: the mean over a pass, best of ``repeats``.

    CPU time of this thread, not wall time, and the best pass: on a shared machine other
    work only ever adds to a pass.
    """
    times = []
    for _ in range(repeats):
        start = time.thread_time()
        for r in ranges_list:
            converter.readings(angle_min, increment, r, 0.0, RANGE_MAX)
        times.append((time.thread_time() - start) / len(ranges_list) * 1e6)
    return min(times)


def graph_dropouts() -> None:
    """Share of scans used and the episode's outcome with dropouts, through the graph."""
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
    from dropout_graph import DEAD_SECTOR, DropoutRun

    from evorbc_ros.defaults import paper_arbitrator

    print(f"dead sector {DEAD_SECTOR} deg in every run; lockstep, obstacle maze, 4ws-5")
    print(f"{'dropout':>8} {'seed':>5} {'scans':>6} {'used':>6} {'share':>7}  outcome")
    domain = 180
    for dropout in (0.0, 0.05, 0.2):
        for seed in (1, 2, 3) if dropout else (1,):
            with tempfile.TemporaryDirectory() as tmp:
                run = DropoutRun(
                    Path(tmp), domain, "obstacle", dropout, DEAD_SECTOR, seed, paper_arbitrator()
                )
                got = run.finish(timeout=300)
                c = run.counts()
            domain += 1
            outcome = f"reached in {got['time']:.1f} s" if got["reached"] else "not reached"
            share = c["readings"] / c["scans"]
            print(
                f"{dropout:8.0%} {seed:5d} {c['scans']:6d} {c['readings']:6d} {share:7.2%}  "
                f"{outcome}"
            )


def dropout_shares(maze, layout) -> None:
    """Scans that give readings with random dropouts, and how much the readings change.

    Scans of the bridge's laser (360 beams, centred) from 100 poses in the maze, 100 random
    dropout patterns each; the code before issue 18 (tests/reference_laser.py) alongside.
    """
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
    from reference_laser import OldLaserToRangefinders

    starts = maze.sample_starts(np.random.default_rng(1), 100, 0.05)
    inc = 2 * math.pi / 360
    clean = scans(maze, starts, LaserPose(), -math.pi, inc, 360)
    print("random NaN dropouts, 360 beams, centred, 100 poses x 100 patterns (4ws layout)")
    print(
        f"{'dropout':>8} {'used now':>9} {'before':>7} {'unchanged':>10} {'<= 0.01':>8} {'max':>6}"
    )
    for p in (0.05, 0.2):
        shares, change = [], []
        for cls in (LaserToRangefinders, OldLaserToRangefinders):
            rng = np.random.default_rng(7)
            converter, used = cls(layout), 0
            for r in clean:
                base = converter.readings(-math.pi, inc, r, 0.0, RANGE_MAX)
                for _ in range(100):
                    dropped = np.where(rng.random(r.size) < p, np.nan, r)
                    try:
                        got = converter.readings(-math.pi, inc, dropped, 0.0, RANGE_MAX)
                    except InputError:
                        continue
                    used += 1
                    if cls is LaserToRangefinders:
                        change += list(np.abs(got - base))
            shares.append(used / (100 * len(clean)))
        c = np.array(change)
        print(
            f"{p:8.0%} {shares[0]:9.2%} {shares[1]:7.1%} {np.mean(c == 0):10.1%} "
            f"{np.mean(c <= 0.01):8.1%} {c.max():6.3f}"
        )


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--graph", action="store_true", help="dropouts through the ROS 2 graph")
    if p.parse_args().graph:
        print(f"machine: {machine()}")
        graph_dropouts()
        return
    maze = load_named_maze("obstacle")
    starts = maze.sample_starts(np.random.default_rng(0), POSES, 0.05)
    layouts = {
        name: SensorLayout.load(config_dir() / "sensors" / f"{name}.yaml").rangefinders
        for name in ("4ws", "hexapod")
    }
    rng = np.random.default_rng(1)
    print(f"machine: {machine()}")
    dropout_shares(maze, layouts["4ws"])
    print("CPU us per scan (best of 9 passes over 50 scans)")
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
