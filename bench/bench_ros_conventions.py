"""Benchmark: what lifecycle, diagnostics and markers cost the 10 Hz cycle (A/B).

Compares, alternately in one session (this machine's speed drifts by 20 % from day to day):
  * ``before``: the tree of a commit before them (``--base``, default 5e54ffd);
  * ``after``: this tree (lifecycle nodes, /diagnostics at 1 Hz, markers off);
  * ``markers``: this tree with ``markers: true`` on the laser, radar and arbitrator nodes.

For each, in a fresh process importing that tree:
  * the arbitrator's callback for the message that completes a set of inputs (choice,
    publishing, and for ``markers`` drawing), p50/p99 over 2000 cycles, in process;
  * a real-time run of the five nodes (20 s of the zigzag maze): the period of the wheel
    commands arriving at the bridge, p99 of its error against 100 ms;
and, for this tree, the laser node's scan callback (360 beams) without and with markers.

Run: ``.venv/bin/python bench/bench_ros_conventions.py [--base REV] [--rounds N]``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
MARKERS = {"markers": True}


def laser_callback(markers: bool, scans: int = 2000) -> list[float]:
    """Seconds inside the laser node's scan callback (360 beams), markers off or on."""
    import math

    import rclpy
    from rclpy.parameter import Parameter
    from sensor_msgs.msg import LaserScan

    from evorbc_ros.nodes.laser_sensor import LaserSensorNode

    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "OFF"
    context = rclpy.Context()
    rclpy.init(context=context)
    node = LaserSensorNode(
        context=context, parameter_overrides=[Parameter("markers", value=markers)]
    )
    rng = np.random.default_rng(0)
    msg = LaserScan()
    msg.angle_min, msg.angle_increment = -math.pi, 2 * math.pi / 360
    msg.angle_max = msg.angle_min + 359 * msg.angle_increment
    msg.range_max = 2.0
    times = []
    for _ in range(scans):
        msg.ranges = rng.uniform(0.1, 3.0, 360).astype(np.float32).tolist()
        t0 = time.perf_counter()
        node.on_scan(msg)
        times.append(time.perf_counter() - t0)
    node.destroy_node()
    rclpy.try_shutdown(context=context)
    return times


def measure(variant: str, domain: int) -> dict:
    """The figures of one variant, in this process (its tree is on PYTHONPATH)."""
    sys.path.insert(0, str(HERE))
    from bench_ros import arbitrator_latency, graph_run

    node_params = MARKERS if variant == "markers" else {}
    _, _, callback = arbitrator_latency(2000, node_params)
    graph_params = dict.fromkeys(("laser_sensor", "radar_sensor", "arbitrator"), node_params)
    run = graph_run("zigzag", "realtime", 20.0, domain, graph_params)
    error = np.abs(np.diff(run["command_times"]) - 0.1)
    out = {
        "callback": [float(np.percentile(callback, q)) for q in (50, 99)],
        "period_error_p99": float(np.percentile(error, 99)),
        "period_mean": float(np.mean(np.diff(run["command_times"]))),
    }
    if variant != "before":
        out["laser"] = {
            str(m): [float(np.percentile(laser_callback(m), q)) for q in (50, 99)]
            for m in (False, True)
        }
    return out


def run_variant(tree: Path, variant: str, domain: int) -> dict:
    """:func:`measure` in a fresh process importing from ``tree``."""
    nested = (tree / "evorbc_ros" / "evorbc_ros" / "__init__.py").is_file()
    roots = [tree / "evorbc_ros", tree / "sim_bridge", tree] if nested else [tree]
    env = dict(
        os.environ,
        PYTHONPATH=os.pathsep.join(str(r) for r in roots),
        PYTHONSAFEPATH="1",
        EVORBC_CONFIG_DIR=str(tree / "config"),  # only read by trees before issue 38
    )
    cmd = [sys.executable, __file__, "--measure", variant, "--domain", str(domain)]
    done = subprocess.run(cmd, cwd=tree, env=env, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        sys.exit(f"{variant}: the measurement failed:\n{done.stderr[-3000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--base", default="5e54ffd", help="the commit before the change")
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--measure", help=argparse.SUPPRESS)
    p.add_argument("--domain", type=int, default=150, help=argparse.SUPPRESS)
    args = p.parse_args()
    if args.measure:
        print(json.dumps(measure(args.measure, args.domain)))
        return
    sys.path.insert(0, str(HERE))
    from bench_repertoire import machine

    print(f"machine: {machine()}")
    with tempfile.TemporaryDirectory() as tmp:
        before = Path(tmp) / "before"
        subprocess.run(
            ["git", "worktree", "add", "--detach", "-q", str(before), args.base],
            cwd=ROOT,
            check=True,
        )
        try:
            results: dict[str, list[dict]] = {"before": [], "after": [], "markers": []}
            for k in range(args.rounds):
                for j, variant in enumerate(results):  # alternately
                    tree = before if variant == "before" else ROOT
                    results[variant].append(run_variant(tree, variant, 150 + 3 * k + j))
                    print(f"round {k + 1}, {variant}: {results[variant][-1]}", flush=True)
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(before)], cwd=ROOT)
    print("\nmedians over the rounds (ms):")
    for variant, rows in results.items():
        cb50 = 1e3 * np.median([r["callback"][0] for r in rows])
        cb99 = 1e3 * np.median([r["callback"][1] for r in rows])
        per = 1e3 * np.median([r["period_error_p99"] for r in rows])
        print(
            f"  {variant:<8} arbitrator callback p50 {cb50:.3f}, p99 {cb99:.3f}; "
            f"command period error p99 {per:.2f}"
        )
    for markers in ("False", "True"):
        rows = results["after"] + results["markers"]
        l50 = 1e3 * np.median([r["laser"][markers][0] for r in rows])
        l99 = 1e3 * np.median([r["laser"][markers][1] for r in rows])
        print(f"  laser scan callback, markers {markers.lower()}: p50 {l50:.3f}, p99 {l99:.3f}")


if __name__ == "__main__":
    main()
