"""Benchmark: A1 primitive evaluations per second and the cost of a Table I repertoire.

Evaluates the same random A1 primitives (T = 2 s, stopped early past the discard tilt, as
MAP-Elites runs them) on 1 and on 2 worker processes (one PyBullet client each), and
prints evaluations per second, the CPU cost of one evaluation, and the projected wall time
of a Table I-sized repertoire (25k + 1000 x 1000 evaluations) and of the reduced run of
docs/a1.md. Random primitives fall more often than a repertoire's mutants do (41 % stay
upright, docs/a1.md), and a fall ends an evaluation early, so the projection is a lower
bound; the reduced run's own rate is printed beside it in docs/a1.md.

With ``--episodes N`` it also runs N full maze episodes (30 s, 300 control cycles of 10
physics steps) of EvoRBC controllers on one core, as arbitrator evolution does: random
networks (:func:`bench_hexapod_episode.random_network`) over the steady ones (never past
20 deg of tilt, as a repertoire's are: docs/a1.md) of 200 random primitives evaluated from
rest, and prints the CPU per control cycle, the falls, and the projected
time of a generation (150 episodes plus the nominal watch's 10) and of 200 generations on 2
dedicated cores.

    python bench/bench_a1.py [--n 400] [--workers 1,2] [--episodes 0]
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import time

import numpy as np

from evorbc_ros.robots import registry
from offline_evolution.repertoire.settings import load_settings
from sim_bridge.legged.pool import available_cores
from sim_bridge.legged.robot import simulated_robot


def machine() -> str:
    """CPU model and core count."""
    names = []
    if os.path.exists("/proc/cpuinfo"):
        with open("/proc/cpuinfo") as f:
            names = [line.split(":", 1)[1].strip() for line in f if line.startswith("model name")]
    return f"{names[0] if names else platform.machine()}, {available_cores()} cores"


def cpu_seconds() -> float:
    """CPU seconds used by this process and its finished children (the workers, once closed)."""
    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def throughput(n: int, workers: int) -> float:
    """Evaluations per second of ``n`` random primitives on ``workers`` processes.

    Besides the wall-clock rate, prints the CPU seconds per evaluation (workers included,
    start-up excluded as far as it can be: the workers' first batch is timed apart), which
    does not depend on what else the machine runs, and the Table I projection on that
    many dedicated cores.
    """
    settings = load_settings(robot="a1")
    robot = simulated_robot(registry.lookup("a1"), workers=workers)
    try:
        genes = np.random.default_rng(0).uniform(-1, 1, size=(n, robot.settings.gait.n_parameters))
        warm = genes[: 20 * workers]
        cpu0 = cpu_seconds()
        start = time.perf_counter()
        robot.evaluate_primitives(warm, settings.eval_time)  # starts the workers
        warm_wall = time.perf_counter() - start
        start = time.perf_counter()
        out = robot.evaluate_primitives(genes, settings.eval_time)
        wall = time.perf_counter() - start
    finally:
        robot.close()
    # The warm-up batch's share of the CPU (start-up plus its evaluations) by wall time.
    cpu = (cpu_seconds() - cpu0) * wall / (wall + warm_wall)
    per_eval = cpu / n
    rate = n / wall
    upright = float(np.mean(out.max_tilt <= robot.settings.discard_tilt))
    print(
        f"{n} random primitives of {settings.eval_time:g} s on {workers} worker(s): "
        f"{wall:.1f} s = {rate:.1f} evaluations/s ({1e3 / rate * workers:.1f} ms each per "
        f"worker; {upright:.0%} upright); Table I ({settings.evaluations:,} evaluations) "
        f"projected {settings.evaluations / rate / 3600:.2f} h  [load {os.getloadavg()[0]:.1f}]",
        flush=True,
    )
    print(
        f"  CPU {1e3 * per_eval:.1f} ms per evaluation: on {workers} dedicated core(s) "
        f"{workers / per_eval:.1f} evaluations/s, Table I projected "
        f"{settings.evaluations * per_eval / workers / 3600:.2f} h",
        flush=True,
    )
    return rate


def episodes(n: int) -> None:
    """CPU per control cycle of ``n`` A1 maze episodes of random EvoRBC controllers."""
    from bench_hexapod_episode import random_network

    from offline_evolution.maze_task.legged_task import LeggedMazeTask
    from offline_evolution.maze_task.task import MazeTaskSettings
    from sim_bridge.legged.episode import LeggedController
    from sim_bridge.legged.evaluate import TILT, X, Y, evaluate_genes
    from sim_bridge.legged.physics import LeggedSim

    a1 = registry.lookup("a1")
    settings = MazeTaskSettings.load(a1.settings_file("task"))
    rng = np.random.default_rng(0)
    with LeggedMazeTask(settings, str(a1.model.path()), workers=1) as task:
        robot = task.robot
        genes = rng.uniform(-1.0, 1.0, size=(200, robot.gait.n_parameters))
        with LeggedSim(robot) as sim:
            out = evaluate_genes(sim, genes, 2.0, robot.control_period, robot.discard_tilt)
        steady = out[:, TILT] <= np.radians(20.0)
        behaviour = out[steady][:, [X, Y]]
        controller = LeggedController("evorbc", "polar", genes[steady], behaviour, key="bench")
        nets = [random_network(2, rng) for _ in range(n)]
        task.evaluate(nets[:1], controller, task.nominal_starts())  # build the simulation
        cpu = time.process_time()
        result = task.evaluate(nets, controller, task.nominal_starts(), record=True)
        cpu = time.process_time() - cpu
    # Cycles run: a fall ends an episode early (its ``cycles`` is still the whole episode's).
    per_cycle = cpu / int(np.sum(~np.isnan(result.outputs[:, :, 0])))
    generation = (150 + 10) * settings.episode_time / robot.control_period * per_cycle
    print(
        f"{n} episodes of {settings.episode_time:g} s, one core: CPU {1e3 * per_cycle:.2f} ms "
        f"per control cycle ({int(result.fell.sum())} of {n} fell, over "
        f"{int(steady.sum())} primitives); a generation of 160 episodes "
        f"{generation:.0f} s of CPU: {generation / 2:.0f} s on 2 dedicated cores, 200 "
        f"generations {200 * generation / 2 / 3600:.1f} h, 655 {655 * generation / 2 / 3600:.1f} h",
        flush=True,
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, default=400, help="random primitives (400)")
    parser.add_argument("--workers", default="1,2", help="worker counts to measure (1,2)")
    parser.add_argument("--episodes", type=int, default=0, help="maze episodes to time (0)")
    args = parser.parse_args()
    a1 = registry.lookup("a1")
    print(f"machine: {machine()}; {a1.description}")
    print(f"physics: {a1.model.physics_rate:g} Hz")
    for workers in map(int, args.workers.split(",")) if args.n else ():
        throughput(args.n, workers)
    if args.episodes:
        episodes(args.episodes)


if __name__ == "__main__":
    main()
