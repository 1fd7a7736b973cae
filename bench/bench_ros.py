"""Benchmark: the ROS 2 graph (shipped arbitrator, separate processes over DDS).

Prints, for this machine:
  * the arbitrator node's compute per control cycle: from the message that completes a
    set of inputs to the primitive it publishes (in process, over DDS), p50/p99/max, and
    the pure choice (network, mapping, lookup) without ROS;
  * the lockstep closed loop: wall time of 120 s of simulated time (a maze the controller
    does not finish sooner, or all five mazes), as a multiple of real time;
  * real-time mode: the period of the wheel commands arriving at the bridge (target
    100 ms), p50/p99 error;
  * CPU use of each node (process CPU time over wall time) in both runs.

Run: ``.venv/bin/python bench/bench_ros.py``.
"""

from __future__ import annotations

import contextlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import rclpy
from bench_repertoire import machine
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Float64MultiArray

from evorbc_ros.arbitration import Controller
from evorbc_ros.nodes.arbitrator import ArbitratorNode
from evorbc_ros.nodes.common import RELIABLE, vector_message
from sim_bridge.bringup import NODES, node_command

TICKS = os.sysconf("SC_CLK_TCK")


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of a process so far (s), from /proc."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS


def random_inputs(layout, rng, k: int) -> tuple[np.ndarray, np.ndarray]:
    """``(rangefinders, goal group)`` readings of ``layout``: uniform ranges, goal sector
    ``k`` mod the sector count lit (or a uniform bearing), a uniform motion reading."""
    n_rf = len(layout.rangefinders.angles) if layout.rangefinders else 0
    goal = []
    if layout.goal_sectors:
        n = len(layout.goal_sectors.centres)
        goal += list(np.eye(n)[k % n])
    if layout.goal_bearing:
        goal.append(rng.uniform(0, 1))
    if layout.motion:
        goal.append(rng.uniform(0, 1))
    return rng.uniform(0, 1, n_rf), np.array(goal)


def arbitrator_latency(
    cycles: int = 2000, parameters: dict | None = None
) -> tuple[list[float], list[float], list[float]]:
    """Seconds from the completing input to the primitive, of the pure choice, and inside the
    arbitrator's callback for the completing input (``parameters``: the node's overrides)."""
    from rclpy.parameter import Parameter

    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "OFF"
    context = rclpy.Context()
    rclpy.init(context=context)
    executor = SingleThreadedExecutor(context=context)
    overrides = [Parameter(k, value=v) for k, v in (parameters or {}).items()]
    node = ArbitratorNode(context=context, parameter_overrides=overrides)
    probe = Node("probe", context=context)
    executor.add_node(node)
    executor.add_node(probe)
    got = []
    callback = []  # time inside the arbitrator's callback for the completing message
    original = node.on_input

    def timed(topic, msg):
        t0 = time.perf_counter()
        original(topic, msg)
        if topic == "evorbc/goal_sectors":
            callback.append(time.perf_counter() - t0)

    node.on_input = timed  # the node's subscriptions look the method up at call time
    probe.create_subscription(
        Float64MultiArray, "evorbc/primitive", lambda m: got.append(time.perf_counter()), RELIABLE
    )
    rf = probe.create_publisher(Float64MultiArray, "evorbc/rangefinders", RELIABLE)
    gs = probe.create_publisher(Float64MultiArray, "evorbc/goal_sectors", RELIABLE)
    while rf.get_subscription_count() == 0 or gs.get_subscription_count() == 0:
        executor.spin_once(timeout_sec=0.01)
    rng = np.random.default_rng(0)
    latencies = []
    for k in range(cycles):
        ranges, goal = random_inputs(node.controller.spec.sensors, rng, k)
        rf.publish(vector_message(ranges))
        while node.groups.fresh.get("evorbc/rangefinders") is not True:
            executor.spin_once(timeout_sec=0.01)
        n = len(got)
        start = time.perf_counter()
        gs.publish(vector_message(goal))
        while len(got) == n:
            executor.spin_once(timeout_sec=0.01)
        latencies.append(got[-1] - start)
    executor.shutdown()
    node.destroy_node()
    probe.destroy_node()
    rclpy.try_shutdown(context=context)
    controller = Controller()
    pure = []
    for _ in range(cycles):
        x = np.concatenate(random_inputs(controller.spec.sensors, rng, int(rng.integers(8))))
        t0 = time.perf_counter()
        controller.step(x)
        pure.append(time.perf_counter() - t0)
    return latencies, pure, callback


def graph_run(
    maze: str, mode: str, episode_time: float, domain: int, parameters: dict | None = None
) -> dict:
    """One run of the five processes; the bridge's result plus CPU seconds per node.

    ``parameters``: node name -> more parameters for it.
    """
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST", ROS_DOMAIN_ID=str(domain))
    with tempfile.TemporaryDirectory() as tmp:
        result = Path(tmp) / "result.json"
        procs = {
            name: subprocess.Popen(
                node_command(module, {"use_sim_time": True, **(parameters or {}).get(name, {})}),
                env=env,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
            for name, module in NODES.items()
        }
        start = time.monotonic()
        procs["sim_bridge"] = subprocess.Popen(
            node_command(
                "sim_bridge.bridge_node",
                {
                    "maze": maze,
                    "mode": mode,
                    "episode_time": episode_time,
                    "result_file": str(result),
                },
            ),
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        cpu = {}
        while procs["sim_bridge"].poll() is None:
            for name, p in procs.items():
                with contextlib.suppress(FileNotFoundError, ProcessLookupError):
                    cpu[name] = cpu_seconds(p.pid)
            time.sleep(0.05)
        wall = time.monotonic() - start
        for p in procs.values():
            if p.poll() is None:
                p.send_signal(2)
        for p in procs.values():
            p.wait(10)
        out = json.loads(result.read_text())
    out["wall"] = wall
    out["cpu"] = cpu
    return out


def percentiles(values, scale=1e3) -> str:
    v = np.asarray(values) * scale
    return f"p50 {np.percentile(v, 50):.3f}, p99 {np.percentile(v, 99):.3f}, max {v.max():.3f}"


def main() -> None:
    print(f"machine: {machine()}")
    latencies, pure, callback = arbitrator_latency()
    print(
        "\narbitrator node, message in -> primitive out (ms, in process over DDS): "
        + percentiles(latencies)
    )
    print(
        "arbitrator node callback, message received -> primitive published (ms): "
        + percentiles(callback)
    )
    print("arbitrator choice alone (network, mapping, lookup; ms): " + percentiles(pure))

    print("\nlockstep closed loop, five separate processes:")
    total_sim = total_wall = total_loop = 0.0
    cpu_sum: dict[str, float] = {}
    for k, maze in enumerate(["obstacle", "zigzag", "baffles", "corridors", "gaps"]):
        r = graph_run(maze, "lockstep", 120.0, 170 + k)
        total_sim += r["time"]
        total_wall += r["wall"]
        for name, c in r["cpu"].items():
            cpu_sum[name] = cpu_sum.get(name, 0.0) + c
        total_loop += r["wall_seconds"]
        print(
            f"  {maze:<10} {r['time']:6.1f} s simulated: episode {r['wall_seconds']:5.2f} s wall "
            f"({r['time'] / r['wall_seconds']:5.1f}x real time); {r['wall']:5.2f} s with "
            "process start-up"
        )
    print(
        f"  all five: {total_sim:.1f} s simulated in {total_loop:.1f} s of episode wall time "
        f"= {total_sim / total_loop:.1f}x real time ({total_wall:.1f} s with start-up)"
    )
    print(
        "  CPU per node (share of one core over the runs): "
        + ", ".join(f"{n} {100 * c / total_wall:.0f}%" for n, c in sorted(cpu_sum.items()))
    )

    r = graph_run("zigzag", "realtime", 30.0, 180)
    periods = np.diff(r["command_times"])
    err = np.abs(periods - 0.1)
    print(
        f"\nreal-time mode, 30 s: {len(r['command_times'])} wheel commands, period "
        f"mean {1e3 * statistics.mean(periods):.2f} ms; error vs 100 ms: " + percentiles(err)
    )
    print(
        "  CPU per node: "
        + ", ".join(f"{n} {100 * c / r['wall']:.0f}%" for n, c in sorted(r["cpu"].items()))
    )


if __name__ == "__main__":
    sys.exit(main())
