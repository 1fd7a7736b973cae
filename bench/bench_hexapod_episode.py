"""Benchmark: hexapod maze episodes on one core, the hot loop of arbitrator evolution.

Runs full 30 s episodes (300 control cycles of 5 physics steps) of the hexapod maze task
in one process and prints, for an EvoRBC controller and a standard-NEAT one, episodes per
second and milliseconds per control cycle (median over repeats). One control cycle is a
laser scan, the rangefinder and goal inputs, one network activation, the primitive's
joint targets and 5 physics steps; ``stepSimulation`` is about half of it.

Self-contained: the EvoRBC repertoire is ``--primitives`` random primitives evaluated
from rest in PyBullet (their genes and behaviours are all an episode needs), and the
networks are fixed random full-direct sigmoid networks with two hidden nodes, the shape
NEAT evolves (config/neat/hexapod.ini). The robots do not solve the maze; the cost of a
cycle hardly depends on where the robot walks.

Run: ``.venv/bin/python bench/bench_hexapod_episode.py [--episodes 4] [--repeats 5]``.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
from bench_hexapod_repertoire import machine

from evorbc_ros.network import ConnectionSpec, NetworkSpec, NodeSpec
from offline_evolution.arbitrator.settings import load_run_settings
from offline_evolution.maze_task.hexapod_task import HexapodMazeTask
from offline_evolution.maze_task.task import MazeTaskSettings
from sim_bridge.hexapod.physics import HexapodSim
from sim_bridge.hexapod.robot import DISCARD_TILT
from sim_bridge.legged.episode import EpisodeRunner, LeggedController
from sim_bridge.legged.evaluate import X, Y, evaluate_genes

N_INPUTS = 6  # five laser groups and the goal bearing (config/sensors/hexapod.yaml)
HIDDEN = (100, 101)  # keys of the two hidden nodes


def random_network(n_outputs: int, rng: np.random.Generator) -> NetworkSpec:
    """Every input to every output and hidden node, hidden to outputs; sigmoid, sum."""
    inputs = tuple(range(-1, -N_INPUTS - 1, -1))
    outputs = tuple(range(n_outputs))
    nodes = tuple(NodeSpec(k, float(rng.normal()), 1.0, "sigmoid", "sum") for k in outputs + HIDDEN)
    links = [(i, k) for k in outputs + HIDDEN for i in inputs]
    links += [(h, k) for k in outputs for h in HIDDEN]
    connections = tuple(ConnectionSpec(a, b, float(rng.normal())) for a, b in links)
    return NetworkSpec(inputs, outputs, nodes, connections)


def random_controller(n: int, rng: np.random.Generator) -> LeggedController:
    """EvoRBC with ``n`` random primitives, their behaviours simulated for 2 s from rest."""
    genes = rng.uniform(-1.0, 1.0, size=(n, 37))
    sim = HexapodSim()
    try:
        out = evaluate_genes(sim, genes, 2.0, sim.geometry.control_period, DISCARD_TILT)
    finally:
        sim.close()
    return LeggedController("evorbc", "polar", genes, out[:, [X, Y]], key="bench")


def time_episodes(runner, network, controller, starts, repeats: int) -> tuple[float, float]:
    """Median episodes/s and ms per control cycle over ``repeats`` rounds of ``starts``."""
    runner.run(network, controller, 0, starts[0])  # build the simulation and the lookup
    rates, per_cycle = [], []
    for _ in range(repeats):
        cycles = 0
        start = time.perf_counter()
        for pose in starts:
            cycles += runner.run(network, controller, 0, pose)["cycles"]
        wall = time.perf_counter() - start
        rates.append(len(starts) / wall)
        per_cycle.append(1e3 * wall / cycles)
    return statistics.median(rates), statistics.median(per_cycle)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--episodes", type=int, default=4, help="episodes per round")
    parser.add_argument("--repeats", type=int, default=5, help="rounds (the median is shown)")
    parser.add_argument("--primitives", type=int, default=100, help="EvoRBC repertoire size")
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    settings = MazeTaskSettings.load(load_run_settings(robot="hexapod").task_path())
    task = HexapodMazeTask(settings, workers=1)
    starts = [
        tuple(map(float, task.sample_starts(np.random.default_rng(k))[0, 1:4]))
        for k in range(args.episodes)
    ]
    runs = {
        "EvoRBC": (random_network(2, rng), random_controller(args.primitives, rng)),
        "standard NEAT": (random_network(37, rng), task.controller("standard")),
    }
    runner = EpisodeRunner(task.world)
    print(f"machine: {machine()}; one process")
    try:
        for name, (network, controller) in runs.items():
            rate, ms = time_episodes(runner, network, controller, starts, args.repeats)
            print(
                f"{name:>13}: {rate:.2f} episodes/s, {ms:.3f} ms per control cycle "
                f"(median of {args.repeats} rounds of {len(starts)} episodes of "
                f"{task.n_cycles} cycles at most)"
            )
    finally:
        runner.close()


if __name__ == "__main__":
    main()
