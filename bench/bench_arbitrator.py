"""Benchmark: arbitrator evolution on the maze task (Table I: population 150, 5 mazes,
120 s episodes, 1000 generations), for EvoRBC and the standard-NEAT baseline.

Prints, for this machine:
  * control cycles per second of the batched kernel (one generation of 150 genomes x 5
    mazes, the initial population: nobody reaches the target, so every episode runs the
    full 1200 cycles), with 1 thread and with all threads;
  * NEAT's own bookkeeping per generation (reproduction, speciation, building networks);
  * the wall time of a run: measured over ``--generations`` (default 60) and projected to
    1000, or measured in full with ``--full``;
  * peak memory (max RSS of the process).

With ``--kernel-only`` it prints the kernel rates alone, for feed-forward networks
(``config/neat/4ws.ini``) and, where the tree has them, recurrent ones: "as recurrent" runs
the same feed-forward population through the recurrent path (the same outputs, so the
cost of the path alone), "recurrent" the initial population of ``4ws-recurrent.ini``, whose
genomes neat-python starts with a self-loop on every output (other networks, other
episodes: fewer reach a fixed point and stop early). To compare two source trees A/B,
run it alternately with each tree first on ``PYTHONPATH``, e.g.
``PYTHONPATH=/tmp/old .venv/bin/python bench/bench_arbitrator.py --kernel-only``.

Run: ``.venv/bin/python bench/bench_arbitrator.py [--full | --kernel-only]``. EvoRBC needs
a repertoire: the Table I 4ws-5 repertoire (seed 1) is generated first (about 2 s).
"""

from __future__ import annotations

import argparse
import dataclasses
import resource
import statistics
import time

import neat
import numba
import numpy as np
from bench_repertoire import machine

from evorbc_ros.config import config_dir
from offline_evolution.arbitrator.compiled import pack_networks
from offline_evolution.arbitrator.evolve import (
    EvolutionSettings,
    evolve,
    file_sha256,
    network_spec,
)
from offline_evolution.arbitrator.neat_config import load_neat_config
from offline_evolution.maze_task.task import (
    MazeTask,
    MazeTaskSettings,
    evorbc_controller,
    standard_controller,
)
from offline_evolution.repertoire.map_elites import generate_repertoire
from offline_evolution.repertoire.settings import load_settings


def kernel_rate(
    task, controller, n_outputs, threads: int, neat_file: str = "4ws.ini", as_recurrent=False
) -> float:
    """Control cycles per second for one generation of the initial population.

    ``as_recurrent``: run the networks through the recurrent path (same outputs when they
    have no hidden nodes, as at first).
    """
    config = load_neat_config(config_dir() / "neat" / neat_file, task.layout.n_inputs, n_outputs)
    pop = neat.Population(config, seed=1)
    specs = [network_spec(g, config) for g in pop.population.values()]
    if as_recurrent:
        specs = [dataclasses.replace(s, recurrent=True) for s in specs]
    pack = pack_networks(specs)
    starts = task.sample_starts(np.random.default_rng(0))
    before = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        task.run(pack, controller, np.arange(len(pop.population)), starts)  # warm up
        rates = []
        for _ in range(3):
            t0 = time.perf_counter()
            result = task.run(pack, controller, np.arange(len(pop.population)), starts)
            rates.append(result.cycles.sum() / (time.perf_counter() - t0))
    finally:
        numba.set_num_threads(before)
    return max(rates)


def run_figures(kind: str, generations: int, repertoire) -> dict:
    neat_file = config_dir() / "neat" / "4ws.ini"
    task_settings = MazeTaskSettings.load(config_dir() / "tasks" / "maze-4ws.yaml")
    settings = EvolutionSettings(
        kind=kind,
        robot="4ws-5",
        generations=generations,
        seed=1,
        neat_file=str(neat_file),
        neat_sha256=file_sha256(neat_file),
        task=task_settings.as_dict(),
        mapping="polar" if kind == "evorbc" else None,
        repertoire_fingerprint=repertoire.fingerprint() if kind == "evorbc" else None,
    )
    start = time.perf_counter()
    result = evolve(settings, repertoire if kind == "evorbc" else None)
    wall = time.perf_counter() - start
    h = result.history[1:]  # generation 0 includes loading the compiled kernels
    return {
        "wall": wall,
        "per_generation": statistics.mean(x.seconds for x in h),
        "evaluation": statistics.mean(x.evaluation_seconds for x in h),
        "bookkeeping": statistics.mean(x.seconds - x.evaluation_seconds for x in h),
        "best": result.best_fitness,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--generations", type=int, default=60)
    parser.add_argument("--full", action="store_true", help="run all 1000 generations")
    parser.add_argument(
        "--kernel-only", action="store_true", help="only the kernel rates (A/B comparisons)"
    )
    args = parser.parse_args()
    generations = 1000 if args.full else args.generations
    print(f"machine: {machine()}")
    repertoire = generate_repertoire(load_settings(robot="4ws-5", seed=1))
    task = MazeTask(MazeTaskSettings.load(config_dir() / "tasks" / "maze-4ws.yaml"), "4ws-5")
    controllers = {
        "evorbc": (evorbc_controller(repertoire, "polar", task.robot), 2),
        "standard": (standard_controller(task.robot), 5),
    }
    threads = numba.config.NUMBA_NUM_THREADS
    for kind, (controller, n_out) in controllers.items():
        print(f"\n== {kind} ==")
        for t in sorted({1, threads}):
            rate = kernel_rate(task, controller, n_out, t)
            print(f"kernel: {rate / 1e6:.2f} M control cycles/s with {t} thread(s)")
        if (config_dir() / "neat" / "4ws-recurrent.ini").exists():
            for t in sorted({1, threads}):
                rate = kernel_rate(task, controller, n_out, t, as_recurrent=True)
                print(f"kernel, as recurrent: {rate / 1e6:.2f} M control cycles/s, {t} thread(s)")
                rate = kernel_rate(task, controller, n_out, t, "4ws-recurrent.ini")
                print(f"kernel, recurrent: {rate / 1e6:.2f} M control cycles/s with {t} thread(s)")
        if args.kernel_only:
            continue
        f = run_figures(kind, generations, repertoire)
        projected = f["per_generation"] * 1000 / 60
        what = "measured" if args.full else f"projected from {generations} generations"
        print(f"{generations} generations: {f['wall']:.1f} s wall, best fitness {f['best']:.3f}")
        print(
            f"per generation: {f['per_generation'] * 1e3:.0f} ms, of which evaluation "
            f"{f['evaluation'] * 1e3:.0f} ms and NEAT bookkeeping {f['bookkeeping'] * 1e3:.1f} ms"
        )
        if args.full:
            print(f"1000 generations: {f['wall'] / 60:.1f} min ({what})")
        else:
            print(
                f"1000 generations: {projected:.1f} min ({what}; early generations run every "
                "episode to 120 s, later ones stop at the target)"
            )
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"\npeak memory (max RSS of this process, both runs): {rss:.0f} MiB")


if __name__ == "__main__":
    main()
