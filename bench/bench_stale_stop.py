"""Benchmark: the executor's stale stop through real processes (wall clock, DDS).

A ``primitive_executor`` process runs the shipped robot's (4ws-5) primitives. This script
plays the arbitrator and the sensor nodes: it publishes a primitive, rangefinder and goal
readings at 10 Hz, so the robot drives, then falls silent. The latency is the time from
its last input to the first zero-speed wheel command that arrives back here: the
executor's ``stale_timeout`` (0.3 s) plus up to one timer period (0.1 s) plus DDS. Each
trial falls silent at a seeded random phase of the executor's timer, then resumes.

Prints min / median / max over the trials, and the machine.

Run: ``.venv/bin/python bench/bench_stale_stop.py [--trials 20] [--seed 1]``.
"""

from __future__ import annotations

import argparse
import os
import signal
import statistics
import subprocess
import time

import numpy as np
import rclpy
from bench_repertoire import machine
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Float64MultiArray

from evorbc_ros.nodes.common import RELIABLE, vector_message
from sim_bridge.bringup import NODES, node_command

GENES = [1.0, 0.0, 0.0, 0.0, 0.0]  # full speed ahead (4ws-5)


def main() -> None:
    """Run the trials and print the latency figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=20)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--domain-id", type=int, default=77)
    args = parser.parse_args()
    os.environ.update(ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST", ROS_DOMAIN_ID=str(args.domain_id))
    proc = subprocess.Popen(
        node_command(NODES["primitive_executor"], {"robot": "4ws-5"}),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    rclpy.init()
    node = Node("stale_stop_bench")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    arrivals: list[tuple[float, float]] = []  # (monotonic s, wheel velocity rad/s)
    node.create_subscription(
        Float64MultiArray,
        "wheel_velocity_controller/commands",
        lambda m: arrivals.append((time.monotonic(), m.data[0])),
        RELIABLE,
    )
    pubs = [
        node.create_publisher(Float64MultiArray, t, RELIABLE)
        for t in ("evorbc/rangefinders", "evorbc/goal_sectors", "evorbc/primitive")
    ]
    values = [[0.0] * 6, [1.0, 0.0, 0.0, 0.0], GENES]

    def spin_for(seconds: float) -> None:
        until = time.monotonic() + seconds
        while time.monotonic() < until:
            executor.spin_once(timeout_sec=max(0.0, until - time.monotonic()))

    def drive(seconds: float) -> float:
        """Publish every input at 10 Hz for ``seconds``; the time of the last publish."""
        last = time.monotonic()
        until = last + seconds
        while time.monotonic() < until:
            last = time.monotonic()
            for pub, v in zip(pubs, values, strict=True):
                pub.publish(vector_message(v))
            spin_for(0.1)
        return last

    try:
        deadline = time.monotonic() + 60
        while any(p.get_subscription_count() == 0 for p in pubs):
            assert time.monotonic() < deadline, "the executor never came up"
            spin_for(0.05)
        rng = np.random.default_rng(args.seed)
        latencies = []
        for _ in range(args.trials):
            drive(1.0)  # running again (the executor resumes at once)
            last = drive(rng.uniform(0.0, 0.1))  # silent at a random phase of its timer
            seen = len(arrivals)
            spin_for(1.0)
            stops = [t for t, v in arrivals[seen:] if v == 0.0]
            assert stops, "no stop command within 1 s"
            latencies.append(stops[0] - last)
        ms = sorted(1e3 * x for x in latencies)
        print(machine())
        print(
            f"stale stop ({args.trials} trials, stale_timeout 0.3 s, period 0.1 s): "
            f"min {ms[0]:.0f} ms, median {statistics.median(ms):.0f} ms, max {ms[-1]:.0f} ms"
        )
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
        proc.send_signal(signal.SIGINT)
        proc.wait(10)


if __name__ == "__main__":
    main()
