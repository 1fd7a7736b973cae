"""Benchmark: throughput of held-out evaluation (``evorbc-evolve evaluate``), episodes per second.

Runs the paper-protocol controllers (``evorbc_ros.defaults.paper_arbitrator``) through
:func:`offline_evolution.maze_task.evaluation.evaluate_suite`
(the command's work: the episodes, recorded, then the stall and collision measures) and
prints episodes per second, with the episodes alone and the measures apart:

* 4ws-5 on the five paper mazes and on ``--generated`` held-out mazes (seed 21021), ``--starts``
  random starts each, without and with the ``realistic`` perturbation set; the compiled
  kernel runs every episode of a suite in one parallel call;
* the hexapod on its maze, ``--hexapod-starts`` random starts, on every core (PyBullet
  workers), without and with ``realistic``; then on ``--hexapod-generated`` held-out
  hexapod mazes with the 60 s episodes its generalisation runs use (docs/generalisation.md).

Also the whole command in a fresh process (imports, maze generation, report, no picture).

``--adapt``: instead, the evaluation with onboard adaptation on against off
(``evaluate --adapt``, docs/design/adaptation.md): the shipped 4ws-5 controller on
``--generated`` held-out mazes x ``--starts``, intact and with a stuck steering wheel,
``--rounds`` rounds alternating off and on (the machine's load changes between them).
Adapted episodes reach more often, so they run fewer cycles: compare control cycles/s.

Run: ``.venv/bin/python bench/bench_evaluate.py [--starts 20] [--generated 50]
[--hexapod-starts 8] [--hexapod-generated 2] [--adapt [--rounds 3]]``.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_hexapod_repertoire import machine

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.defaults import default_repertoire, paper_arbitrator
from evorbc_ros.repertoire import Repertoire
from offline_evolution.maze_task import evaluation
from offline_evolution.maze_task.base import MazeTaskSettings
from offline_evolution.maze_task.perturbation import NONE, load_perturbations
from offline_evolution.maze_task.task import make_task
from offline_evolution.mazes.files import save_maze
from offline_evolution.mazes.generator import generate_maze, spec_for_robot
from offline_evolution.mazes.held_out import HELD_OUT_SEED

PAPER = ("obstacle", "zigzag", "baffles", "corridors", "gaps")
ROOT = Path(__file__).resolve().parents[1]


def timed_suite(task, arb, repertoire, starts: int, perturbation) -> tuple[float, float, int]:
    """``(seconds of the whole evaluation, seconds of the episodes, cycles run)``."""
    controller = task.controller(arb.kind, repertoire, arb.mapping)
    episodes = {"s": 0.0, "cycles": 0}
    evaluate = task.evaluate

    def timed(*a, **k):
        t = time.perf_counter()
        result = evaluate(*a, **k)
        episodes["s"] += time.perf_counter() - t
        episodes["cycles"] += int(result.cycles.sum())
        return result

    task.evaluate = timed
    try:
        start = time.perf_counter()
        evaluation.evaluate_suite(task, arb.network, controller, starts, 0, perturbation)
        total = time.perf_counter() - start
    finally:
        del task.evaluate
    return total, episodes["s"], episodes["cycles"]


def report(label: str, n: int, total: float, episodes: float, cycles: int) -> None:
    print(
        f"{label:<46} {n:>5} episodes: {n / total:7.1f} episodes/s in all ({total:6.2f} s); "
        f"episodes alone {n / episodes:7.1f}/s ({episodes:6.2f} s, {cycles / episodes / 1e3:.1f}k "
        "control cycles/s)"
    )


def held_out_files(robot: str, n: int, folder: str) -> tuple[str, ...]:
    """The first ``n`` held-out mazes of ``robot``, saved as maze files in ``folder``."""
    t = time.perf_counter()
    spec = spec_for_robot(robot)
    files = []
    for k in range(n):
        maze = generate_maze(spec, HELD_OUT_SEED, k).maze
        files.append(str(Path(folder) / f"{maze.name}.yaml"))
        save_maze(maze, files[-1])
    print(f"generating {n} held-out {robot} mazes (each proven): {time.perf_counter() - t:.1f} s")
    return tuple(files)


def four_ws(starts: int, generated: int) -> None:
    # The paper-protocol controllers (their sensor layouts below): the recorded figures'.
    arb = ArbitratorFile.load(paper_arbitrator("4ws-5"))
    repertoire = Repertoire.load(default_repertoire("4ws-5"))
    realistic = load_perturbations("realistic")
    with tempfile.TemporaryDirectory() as tmp:
        files = held_out_files("4ws-5", generated, tmp)
        suites = {"paper mazes": PAPER, f"{generated} held-out mazes": tuple(files)}
        for name, mazes in suites.items():
            task = make_task(MazeTaskSettings(mazes, 120.0, 1, "sensors/4ws.yaml"), "4ws-5")
            timed_suite(task, arb, repertoire, 1, NONE)  # compile / load the JIT cache
            for pset in (NONE, realistic):
                total, alone, cycles = timed_suite(task, arb, repertoire, starts, pset)
                label = f"4ws-5, {name} x {starts}, {pset.name}"
                report(label, len(mazes) * starts, total, alone, cycles)


def hexapod(starts: int, generated: int) -> None:
    arb = ArbitratorFile.load(paper_arbitrator("hexapod"))
    repertoire = Repertoire.load(default_repertoire("hexapod"))
    task = make_task(MazeTaskSettings(("hexapod",), 30.0, 1, "sensors/hexapod.yaml"), "hexapod")
    try:
        # Start the workers and build their simulations (one start would run in process).
        timed_suite(task, arb, repertoire, task.workers, NONE)
        for pset in (NONE, load_perturbations("realistic")):
            total, alone, cycles = timed_suite(task, arb, repertoire, starts, pset)
            label = f"hexapod, its maze x {starts}, {pset.name} ({task.workers} workers)"
            report(label, starts, total, alone, cycles)
    finally:
        task.close()
    if not generated:
        return
    with tempfile.TemporaryDirectory() as tmp:
        files = held_out_files("hexapod", generated, tmp)
        # 60 s episodes, as the hexapod's generalisation runs; the workers start and build
        # each maze's world in the timed call (an evaluation does that once per maze).
        task = make_task(MazeTaskSettings(files, 60.0, 1, "sensors/hexapod.yaml"), "hexapod")
        try:
            total, alone, cycles = timed_suite(task, arb, repertoire, starts, NONE)
            label = f"hexapod, {generated} held-out mazes x {starts}, 60 s ({task.workers} workers)"
            report(label, generated * starts, total, alone, cycles)
        finally:
            task.close()


def adapting_4ws(starts: int, generated: int, rounds: int) -> None:
    """Evaluation throughput with adaptation off and on (the best of ``rounds``)."""
    from evorbc_ros.adaptation import AdaptationSettings
    from evorbc_ros.defaults import default_arbitrator
    from offline_evolution.maze_task.adapting import adapting

    arb = ArbitratorFile.load(default_arbitrator("4ws-5"))
    repertoire = Repertoire.load(default_repertoire("4ws-5"))
    with tempfile.TemporaryDirectory() as tmp:
        files = held_out_files("4ws-5", generated, tmp)
        settings = MazeTaskSettings.from_dict(arb.evolution["task"], "shipped")
        task = make_task(MazeTaskSettings(files, 120.0, 1, settings.sensors), "4ws-5")
        arrays = adapting(repertoire, AdaptationSettings(), task.dt)
        for adapt in (None, arrays):  # compile / load the JIT caches
            task.adapt(adapt)
            timed_suite(task, arb, repertoire, 1, NONE)
        for pset in (NONE, load_perturbations("4ws-stuck-steering")):
            best = {}
            for _ in range(rounds):
                for name, adapt in (("off", None), ("on", arrays)):
                    task.adapt(adapt)
                    total, alone, cycles = timed_suite(task, arb, repertoire, starts, pset)
                    if name not in best or cycles / alone > best[name][2] / best[name][1]:
                        best[name] = (total, alone, cycles)
            task.adapt(None)
            for name, figures in best.items():
                label = f"4ws-5, {generated} held-out x {starts}, {pset.name}, adapt {name}"
                report(label, generated * starts, *figures)
            ratio = (best["on"][2] / best["on"][1]) / (best["off"][2] / best["off"][1])
            print(f"  control cycles/s with adaptation on / off: {ratio:.2f}")


def command(args: list[str]) -> float:
    """Wall seconds of ``evorbc-evolve ARGS`` in a fresh process."""
    exe = Path(sys.executable).with_name("evorbc-evolve")
    start = time.perf_counter()
    subprocess.run([str(exe), *args], check=True, capture_output=True, cwd=ROOT)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--starts", type=int, default=20)
    parser.add_argument("--generated", type=int, default=50)
    parser.add_argument("--hexapod-starts", type=int, default=8)
    parser.add_argument("--hexapod-generated", type=int, default=2)
    parser.add_argument("--adapt", action="store_true", help="adaptation on against off")
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    print(f"machine: {machine()}, load average {os.getloadavg()[0]:.1f}")
    if args.adapt:
        adapting_4ws(args.starts, args.generated, args.rounds)
        print(f"load average at the end {os.getloadavg()[0]:.1f}")
        return
    four_ws(args.starts, args.generated)
    hexapod(args.hexapod_starts, args.hexapod_generated)
    for cli in (
        ["evaluate", "--paper", "--starts", str(args.starts)],
        ["evaluate", "--paper", "--generated", str(args.generated), "--starts", str(args.starts)],
    ):
        print(f"evorbc-evolve {' '.join(cli)}: {command(cli):.1f} s in a fresh process")
    print(f"load average at the end {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
