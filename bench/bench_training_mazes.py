"""Benchmark: training on generated mazes (docs/design.md section 22), 4ws-5.

Prints, per generation:

* the **maze setup cost** of a generation's draw of K generated mazes: generating and
  proving them (the clearance-aware path search), and the kernel upload (packing the new
  mazes' walls and broad-phase grids next to the task's own, ``MazeTask.mazes_changed``),
  for fresh draws (new mazes every generation) and for a pool (drawn again: cached), and
  whether the compiled kernel compiled again (it must not: the pack's types never change);
* the **cost of a generation** of arbitrator evolution (4ws-5, the shipped NEAT settings,
  population 150, 120 s episodes) on the paper protocol (the five paper mazes, one start
  each) and with K generated mazes more, fresh, fresh with path-length fitness
  (``distance: path``: each maze's path-distance grid and a lookup per episode), and from
  a pool: the median over
  ``--generations`` generations of the same seeded run, the first (compilation) left out.

Run: ``.venv/bin/python bench/bench_training_mazes.py [--generations 6] [--k 5]``.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from bench_hexapod_repertoire import machine

from evorbc_ros.defaults import default_repertoire
from evorbc_ros.repertoire import Repertoire
from offline_evolution.arbitrator.evolve import Evolution, EvolutionSettings, file_sha256
from offline_evolution.maze_task import kernel
from offline_evolution.maze_task.task import MazeTask, MazeTaskSettings

ROOT = Path(__file__).resolve().parents[1]
PAPER = {
    "mazes": ["obstacle", "zigzag", "baffles", "corridors", "gaps"],
    "episode_time": 120.0,
    "samples_per_maze": 1,
    "sensors": "sensors/4ws.yaml",
}


def task_dict(k: int, pool: int, distance: str = "euclidean") -> dict:
    """The paper's task plus K generated mazes (fresh if ``pool`` is 0), one start each."""
    if k == 0:
        return dict(PAPER)
    training = {"generated": k, "pool": pool, "maze_seed": 1, "distance": distance}
    return {**PAPER, "training": training}


def setup_costs(k: int, pool: int, draws: int, distance: str = "euclidean") -> dict:
    """Median s per generation: maze generation + proof, and kernel upload (repack).

    With a pool, every pool maze is made first (once per run), so draws are cache hits.
    """
    settings = MazeTaskSettings.from_dict(task_dict(k, pool, distance), "bench")
    task = MazeTask(settings, "4ws-5")
    task.start_training("4ws-5", seed=1)
    t = task.training
    if pool:
        task.use_mazes(t.mazes(range(pool)))
    make, upload = [], []
    for g in range(draws):
        rng = np.random.default_rng([1, g])
        t0 = time.perf_counter()
        mazes = t.mazes(t.training_indices(rng))
        t1 = time.perf_counter()
        task.use_mazes(mazes)
        make.append(t1 - t0)
        upload.append(time.perf_counter() - t1)
    return {"make": statistics.median(make), "upload": statistics.median(upload)}


def generation_seconds(
    k: int, pool: int, generations: int, repertoire, distance: str = "euclidean"
) -> tuple[float, float]:
    """Median ``(s per generation, s of its episodes)``, the first generation left out."""
    neat = ROOT / "config" / "neat" / "4ws.ini"
    settings = EvolutionSettings(
        kind="evorbc",
        robot="4ws-5",
        generations=generations + 1,
        seed=1,
        neat_file=str(neat),
        neat_sha256=file_sha256(neat),
        task=task_dict(k, pool, distance),
        mapping="polar",
        repertoire_fingerprint=repertoire.fingerprint(),
    )
    run = Evolution(settings, repertoire)
    try:
        stats = [run.step() for _ in range(generations + 1)][1:]
    finally:
        run.close()
    return (
        statistics.median(s.seconds for s in stats),
        statistics.median(s.evaluation_seconds for s in stats),
    )


def main() -> int:
    """Print the figures."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--generations", type=int, default=6, help="timed generations per setting")
    p.add_argument("--k", type=int, default=5, help="generated mazes per generation")
    p.add_argument("--pool", type=int, default=100, help="pool size of the pool setting")
    p.add_argument("--draws", type=int, default=10, help="draws timed for the setup cost")
    args = p.parse_args()
    print(machine())
    repertoire = Repertoire.load(default_repertoire("4ws-5"))

    print(
        f"\nmaze setup per generation, K = {args.k} generated 4ws-5 mazes (median of "
        f"{args.draws} draws):"
    )
    for label, pool, distance in (
        ("fresh", 0, "euclidean"),
        ("fresh, path fitness", 0, "path"),
        (f"pool {args.pool}, made before", args.pool, "euclidean"),
    ):
        cost = setup_costs(args.k, pool, args.draws, distance)
        print(
            f"  {label:28s} generation + proof {cost['make'] * 1e3:8.1f} ms   "
            f"kernel upload {cost['upload'] * 1e3:6.2f} ms"
        )
    print(
        f"\ngeneration cost, 4ws-5 arbitrator evolution (population 150, 120 s episodes), "
        f"median of {args.generations} generations after the first:"
    )
    base = None
    for label, k, pool, distance in (
        ("paper protocol (5 mazes)", 0, 0, "euclidean"),
        (f"+ {args.k} fresh generated mazes", args.k, 0, "euclidean"),
        (f"+ {args.k} fresh, path fitness", args.k, 0, "path"),
        (f"+ {args.k} from a pool of {args.pool}", args.k, args.pool, "euclidean"),
    ):
        before = len(kernel.run_episodes.signatures)
        total, episodes = generation_seconds(k, pool, args.generations, repertoire, distance)
        compiled = len(kernel.run_episodes.signatures) - before
        base = base or total
        print(
            f"  {label:32s} {total:6.2f} s/generation (episodes {episodes:6.2f} s)  "
            f"x{total / base:4.2f}   new kernel signatures {compiled}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
