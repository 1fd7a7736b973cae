"""Benchmark: the 4WS and hexapod hot paths in two source trees, A/B, run alternately.

The robot refactor (issue 19: the registry, robots from settings files, the episode kernel
chosen by the limits' type, the hexapod as a legged robot from a URDF) must not slow the
hot paths. This script measures, in fresh processes whose imports come from each tree
(``PYTHONPATH``; each tree keeps its own numba cache):

* 4WS primitives: evaluations/s of ``make_robot("4ws-5").evaluate_primitives`` (100k
  primitives of 2 s), MAP-Elites' hot path;
* 4WS MAP-Elites: evaluations/s of a Table I run cut to 200 iterations (10k + 200 x 1000
  evaluations; batches of 1000, where the per-batch cost counts);
* 4WS episodes: control cycles/s of one arbitrator generation (150 NEAT networks, 5 mazes,
  120 s, the shipped repertoire, EvoRBC polar mapping), the compiled episode kernel;
* hexapod primitives: evaluations/s of 2 s gaits in PyBullet on one worker;
* hexapod episodes: control cycles/s of the paper-protocol hexapod controller's 30 s episode on
  one worker;
* the onboard 10 Hz cycle: choices/s of the arbitrator node's pure part
  (``evorbc_ros.arbitration.Controller.step``: network, mapping, nearest primitive) for each
  shipped controller, on 2,000 recorded-like input vectors in [0, 1].

The trees run in turn, A B B A A B ... (this machine drifts by 20 % from day to day, and
other jobs come and go). Each round's two runs are next to each other in time, so the
figure compared is the median over rounds of the ratio new / old within a round; the best
of each tree is printed too.

``--clock cpu`` times each figure by the process's CPU time on one numba thread (every
figure here runs in the measuring process: the PyBullet robots on one worker run
in-process), so other jobs taking turns on the cores do not count; what they still cost
(shared caches) is far smaller than the wall clock's time slicing on a busy 2-core machine.

Run: ``.venv/bin/python bench/bench_ab_hot_paths.py --old /tmp/ab-old --new . [--clock cpu]``
(make the old tree with ``git worktree add --detach /tmp/ab-old fe6941e``).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

FIGURES = {
    "4ws_primitives": "4WS primitives (evaluations/s)",
    "4ws_repertoire": "4WS MAP-Elites, batches of 1000 (evaluations/s)",
    "4ws_episodes": "4WS episode kernel (control cycles/s)",
    "hexapod_primitives": "hexapod primitives (evaluations/s, 1 worker)",
    "hexapod_episodes": "hexapod episode (control cycles/s, 1 worker)",
    "onboard_cycle": "onboard 10 Hz cycle, arbitrator node's compute (choices/s)",
}

#: How the parent tells a measuring process which clock to use.
CLOCK_VARIABLE = "EVORBC_BENCH_CLOCK"


def best_rate(work, count: float, repeats: int) -> float:
    """``count`` per second of the fastest of ``repeats`` calls of ``work`` (after one).

    Timed by the wall clock, or by this process's CPU time under ``--clock cpu``.
    """
    clock = time.process_time if os.environ.get(CLOCK_VARIABLE) == "cpu" else time.perf_counter
    work()  # compile, or load the numba cache, and warm up
    times = []
    for _ in range(repeats):
        t0 = clock()
        work()
        times.append(clock() - t0)
    return count / min(times)


def measure(wanted: set[str]) -> dict:
    """The ``wanted`` figures in this process, whose imports come from the tree under test."""
    import numpy as np

    from sim_bridge.robots import make_robot

    rng = np.random.default_rng(1)
    out = {}
    if "4ws_primitives" in wanted:
        robot = make_robot("4ws-5")
        genes = rng.uniform(-1, 1, (100_000, 5))
        out["4ws_primitives"] = best_rate(lambda: robot.evaluate_primitives(genes, 2.0), 1e5, 5)
    if "4ws_repertoire" in wanted:
        from offline_evolution.repertoire.map_elites import generate_repertoire
        from offline_evolution.repertoire.settings import load_settings

        settings = load_settings(robot="4ws-5", seed=1, iterations=200)
        out["4ws_repertoire"] = best_rate(
            lambda: generate_repertoire(settings), settings.evaluations, 2
        )
    if "4ws_episodes" in wanted:
        out["4ws_episodes"] = four_ws_episodes()
    if "hexapod_primitives" in wanted:
        hexapod = make_robot("hexapod", workers=1)
        gaits = rng.uniform(-1, 1, (40, 37))
        out["hexapod_primitives"] = best_rate(
            lambda: hexapod.evaluate_primitives(gaits, 2.0), 40, 2
        )
        hexapod.close()
    if "hexapod_episodes" in wanted:
        out["hexapod_episodes"] = hexapod_episodes()
    if "onboard_cycle" in wanted:
        out["onboard_cycle"] = onboard_cycle()
    return out


def onboard_cycle() -> float:
    """Choices/s of ``Controller.step`` over the shipped controllers (harmonic mean)."""
    import numpy as np

    from evorbc_ros.arbitration import Controller
    from evorbc_ros.defaults import default_arbitrator

    rates = []
    for robot in ("4ws-5", "hexapod", "a1"):
        controller = Controller(str(default_arbitrator(robot)))
        n = controller.spec.sensors.n_inputs
        inputs = np.random.default_rng(2).uniform(0.0, 1.0, (2000, n))

        def cycles(c=controller, x=inputs):
            c.reset()
            for row in x:
                c.step(row)

        rates.append(best_rate(cycles, len(inputs), 5))
    return len(rates) / sum(1.0 / r for r in rates)


def four_ws_episodes() -> float:
    """Control cycles/s of one 4ws-5 arbitrator generation in the compiled kernel."""
    import neat
    import numpy as np

    from evorbc_ros.config import config_dir
    from evorbc_ros.defaults import default_repertoire
    from evorbc_ros.repertoire import Repertoire
    from offline_evolution.arbitrator.evolve import network_spec
    from offline_evolution.arbitrator.neat_config import load_neat_config
    from offline_evolution.maze_task.task import MazeTask, MazeTaskSettings

    task = MazeTask(MazeTaskSettings.load(config_dir() / "tasks" / "maze-4ws.yaml"), "4ws-5")
    config = load_neat_config(config_dir() / "neat" / "4ws.ini", task.layout.n_inputs, 2)
    population = neat.Population(config, seed=1).population.values()
    networks = [network_spec(g, config) for g in population]
    controller = task.controller("evorbc", Repertoire.load(default_repertoire("4ws-5")), "polar")
    starts = task.sample_starts(np.random.default_rng(0))
    cycles = task.evaluate(networks, controller, starts).cycles.sum()
    return best_rate(lambda: task.evaluate(networks, controller, starts), float(cycles), 3)


def hexapod_episodes() -> float:
    """Control cycles/s of the paper-protocol hexapod controller's episode, one worker."""
    from evorbc_ros.arbitrator import ArbitratorFile
    from evorbc_ros.defaults import default_repertoire, paper_arbitrator
    from evorbc_ros.repertoire import Repertoire
    from offline_evolution.maze_task.hexapod_task import HexapodMazeTask
    from offline_evolution.maze_task.task import MazeTaskSettings

    arb = ArbitratorFile.load(paper_arbitrator("hexapod"))
    settings = MazeTaskSettings.from_dict(arb.evolution["task"], "the paper arbitrator")
    task = HexapodMazeTask(settings, workers=1)
    try:
        rep = Repertoire.load(default_repertoire("hexapod"))
        ctrl = task.controller("evorbc", rep, arb.mapping)
        nominal = task.nominal_starts()[:1]
        cycles = task.evaluate([arb.network], ctrl, nominal).cycles.sum()
        return best_rate(lambda: task.evaluate([arb.network], ctrl, nominal), float(cycles), 2)
    finally:
        task.close()


def run_tree(tree: Path, figures: list[str], clock: str = "wall") -> dict:
    """:func:`measure` in a fresh process importing from ``tree``."""
    # Trees before the ROS package folders (docs/design.md section 10) hold the Python
    # packages at the top and find config/ through EVORBC_CONFIG_DIR; later ones one level
    # down, with the settings inside evorbc_ros.
    roots = [tree / "evorbc_ros", tree / "sim_bridge", tree]
    nested = (tree / "evorbc_ros" / "evorbc_ros" / "__init__.py").is_file()
    env = dict(
        os.environ,
        PYTHONPATH=os.pathsep.join(str(r) for r in (roots if nested else roots[2:])),
        PYTHONSAFEPATH="1",
        EVORBC_CONFIG_DIR=str(tree / "config"),
        **{CLOCK_VARIABLE: clock},
    )
    if clock == "cpu":  # CPU time sums the threads' time: time one thread
        env["NUMBA_NUM_THREADS"] = "1"
    done = subprocess.run(
        [sys.executable, str(Path(__file__).resolve()), "--measure", "--figures", *figures],
        cwd=tree,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode != 0:
        sys.exit(f"{tree}: the measurement failed:\n{done.stderr}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--old", type=Path, help="the tree before (e.g. /tmp/ab-old)")
    parser.add_argument("--new", type=Path, default=Path("."), help="the tree after")
    parser.add_argument("--rounds", type=int, default=3, help="runs of each tree")
    parser.add_argument(
        "--figures", nargs="+", choices=tuple(FIGURES), default=list(FIGURES), help="measured"
    )
    parser.add_argument(
        "--clock",
        choices=("wall", "cpu"),
        default="wall",
        help="time by the wall clock, or by CPU time on one numba thread (a busy machine)",
    )
    parser.add_argument("--measure", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.measure:
        print(json.dumps(measure(set(args.figures))))
        return
    if args.old is None:
        parser.error("--old is required")
    from bench_repertoire import machine

    trees = {"old": args.old.resolve(), "new": args.new.resolve()}
    print(f"machine: {machine()}; clock: {args.clock}")
    for label, tree in trees.items():
        head = subprocess.run(
            ["git", "-C", str(tree), "log", "-1", "--format=%h %cd", "--date=iso"],
            capture_output=True,
            text=True,
            check=False,
        ).stdout.strip()
        print(f"{label}: {tree} ({head})")
    runs: dict[str, list[dict]] = {"old": [], "new": []}
    order = ["old", "new"]
    for k in range(args.rounds):
        for label in order if k % 2 == 0 else order[::-1]:  # A B, B A, A B, ...
            figures = run_tree(trees[label], args.figures, args.clock)
            runs[label].append(figures)
            shown = ", ".join(f"{key} {value:,.0f}" for key, value in figures.items())
            print(f"  round {k + 1} {label}: {shown}", flush=True)
    print("\nnew / old: median and range of the rounds' ratios; best of each tree")
    for key in args.figures:
        ratios = sorted(n[key] / o[key] for n, o in zip(runs["new"], runs["old"], strict=True))
        old = max(r[key] for r in runs["old"])
        new = max(r[key] for r in runs["new"])
        print(
            f"  {FIGURES[key]:<46} {statistics.median(ratios):5.3f} "
            f"({ratios[0]:.3f}-{ratios[-1]:.3f});  best old {old:,.0f}, new {new:,.0f}"
        )


if __name__ == "__main__":
    main()
