"""Benchmark: training a legged robot on generated mazes (docs/design.md section 22).

The PyBullet counterpart of ``bench_training_mazes.py``. Prints, for ``--robot`` (default
the hexapod):

* the **maze setup** of a generation's draw of K generated mazes: generating and proving
  them (the clearance-aware path search; median of ``--draws`` draws);
* the **world build** in a worker: a new maze's first episode against the same episode
  again, its simulation kept (``sim_bridge/legged/maze_sims.py``); the difference is loading the
  maze's walls into PyBullet, paid once per maze and worker;
* the **cost of a generation** of arbitrator evolution with the shipped repertoire and
  NEAT settings, on the paper protocol (its own maze, one random start a genome) and with
  K fresh generated mazes more (one start each): the median over ``--generations``
  generations of the same seeded run, the first left out, with a population of
  ``--population`` (the shipped 150 costs the same per genome, 150/P times as much per
  generation) and ``--episode-time`` s episodes on ``--workers`` processes.

Run: ``.venv/bin/python bench/bench_training_mazes_legged.py [--robot hexapod] [--k 2]``.
"""

from __future__ import annotations

import argparse
import re
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from bench_hexapod_repertoire import machine

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.config import config_dir
from evorbc_ros.defaults import default_arbitrator, default_repertoire
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.registry import lookup
from offline_evolution.arbitrator.evolve import Evolution, EvolutionSettings, file_sha256
from offline_evolution.maze_task.task import MazeTaskSettings, make_task


def task_dict(robot: str, k: int, episode_time: float) -> dict:
    """The robot's shipped maze task with ``episode_time``, plus K fresh generated mazes."""
    arb = ArbitratorFile.load(default_arbitrator(robot))
    task = dict(arb.evolution["task"])
    task.pop("training", None)
    task["episode_time"] = episode_time
    if k:
        task["training"] = {"generated": k, "starts": 1, "pool": 0, "maze_seed": 1}
    return task


def setup_seconds(robot: str, k: int, draws: int, episode_time: float) -> float:
    """Median s to generate and prove one generation's K mazes."""
    settings = MazeTaskSettings.from_dict(task_dict(robot, k, episode_time), "bench")
    task = make_task(settings, robot, 1)
    try:
        task.start_training(robot, seed=1)
        t = task.training
        times = []
        for g in range(draws):
            t0 = time.perf_counter()
            t.mazes(t.training_indices(np.random.default_rng([1, g])))
            times.append(time.perf_counter() - t0)
    finally:
        task.close()
    return statistics.median(times)


def world_build_seconds(robot: str, episode_time: float) -> tuple[float, float]:
    """``(first, again)`` s of one short episode in a new generated maze, in process."""
    settings = MazeTaskSettings.from_dict(
        {**task_dict(robot, 1, episode_time), "episode_time": 1.0}, "bench"
    )
    task = make_task(settings, robot, 1)
    arb = ArbitratorFile.load(default_arbitrator(robot))
    repertoire = Repertoire.load(default_repertoire(robot))
    try:
        task.start_training(robot, seed=1)
        controller = task.controller("evorbc", repertoire, arb.mapping)
        # A first episode in the task's own maze, so that the worker's robot is loaded.
        task.evaluate([arb.network], controller, task.nominal_starts()[:1])
        first, again = [], []
        for g in range(3):
            starts, _ = task.generation_episodes(np.random.default_rng([1, g]))
            row = starts[-1:]  # the generated maze's start
            t0 = time.perf_counter()
            task.evaluate([arb.network], controller, row)
            t1 = time.perf_counter()
            task.evaluate([arb.network], controller, row)
            first.append(t1 - t0)
            again.append(time.perf_counter() - t1)
    finally:
        task.close()
    return statistics.median(first), statistics.median(again)


def generation_seconds(
    robot: str, k: int, args: argparse.Namespace, neat: Path, repertoire: Repertoire
) -> float:
    """Median s per generation, the first generation left out."""
    settings = EvolutionSettings(
        kind="evorbc",
        robot=robot,
        generations=args.generations + 1,
        seed=1,
        neat_file=str(neat),
        neat_sha256=file_sha256(neat),
        task=task_dict(robot, k, args.episode_time),
        mapping=ArbitratorFile.load(default_arbitrator(robot)).mapping,
        repertoire_fingerprint=repertoire.fingerprint(),
    )
    run = Evolution(settings, repertoire, workers=args.workers)
    try:
        stats = [run.step() for _ in range(args.generations + 1)][1:]
    finally:
        run.close()
    return statistics.median(s.seconds for s in stats)


def small_population(robot: str, population: int, folder: Path) -> Path:
    """The robot's shipped NEAT settings with ``pop_size`` = ``population``."""
    shipped = config_dir() / lookup(robot).settings.neat
    text, n = re.subn(r"(?m)^pop_size\s*=.*$", f"pop_size = {population}", shipped.read_text())
    if n != 1:  # else the run would use the shipped population and print the wrong one
        raise SystemExit(f"{shipped}: expected one pop_size line, found {n}")
    path = folder / "neat.ini"
    path.write_text(text)
    return path


def main() -> int:
    """Print the figures."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--robot", default="hexapod", help="a legged robot (default hexapod)")
    p.add_argument("--k", type=int, default=2, help="generated mazes per generation")
    p.add_argument("--draws", type=int, default=6, help="draws timed for the setup cost")
    p.add_argument("--generations", type=int, default=3, help="timed generations per setting")
    p.add_argument("--population", type=int, default=24, help="NEAT population of the runs")
    p.add_argument("--episode-time", type=float, default=20.0, help="s per episode")
    p.add_argument("--workers", type=int, default=1, help="PyBullet worker processes")
    args = p.parse_args()
    if args.k < 1 or args.draws < 1 or args.generations < 1:
        p.error("--k, --draws and --generations must be at least 1")
    print(machine())
    repertoire = Repertoire.load(default_repertoire(args.robot))

    make = setup_seconds(args.robot, args.k, args.draws, args.episode_time)
    print(
        f"\nmaze setup per generation, K = {args.k} generated {args.robot} mazes: generation "
        f"+ proof {make * 1e3:.0f} ms (median of {args.draws} draws)"
    )
    first, again = world_build_seconds(args.robot, args.episode_time)
    print(
        f"world build in a worker: a 1 s episode in a new maze {first * 1e3:.0f} ms, the same "
        f"episode again {again * 1e3:.0f} ms: {(first - again) * 1e3:.0f} ms per new maze"
    )
    print(
        f"\ngeneration cost, {args.robot} arbitrator evolution (population {args.population}, "
        f"{args.episode_time:g} s episodes, {args.workers} worker(s)), median of "
        f"{args.generations} generations after the first:"
    )
    with tempfile.TemporaryDirectory() as tmp:
        neat = small_population(args.robot, args.population, Path(tmp))
        base = None
        for label, k in (("paper protocol (own maze)", 0), (f"+ {args.k} fresh mazes", args.k)):
            total = generation_seconds(args.robot, k, args, neat, repertoire)
            base = base or total
            print(
                f"  {label:28s} {total:6.2f} s/generation  x{total / base:4.2f}  "
                f"({total / args.population * 1e3:.0f} ms per genome)"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
