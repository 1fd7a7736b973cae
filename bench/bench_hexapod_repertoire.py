"""Benchmark: hexapod repertoire generation (issue 5 performance targets).

``throughput`` prints hexapod primitive evaluations per second on every core (PyBullet,
one client per worker) and the projected wall time of the full Table I budget
(25k + 1000 x 1000 evaluations of 2 s; target at most 5 h).

``operators`` runs MAP-Elites with each variation operator and archive at the same
budget and seed, and prints for each: evaluations and wall time to reach the paper's 336
primitives, then count, mean quality, QD-score and left/right symmetry at the end (see
:mod:`offline_evolution.repertoire.stats`). Each run checkpoints into ``--out`` and a
finished run is not repeated, so an interrupted benchmark resumes where it stopped.

Run: ``.venv/bin/python bench/bench_hexapod_repertoire.py throughput`` or
``... operators --iterations 175 --out /tmp/hexapod-operators``.
"""

from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np

from evorbc_ros.atomic_io import atomic_write_text
from evorbc_ros.repertoire import Repertoire
from offline_evolution.repertoire.map_elites import generate_repertoire
from offline_evolution.repertoire.settings import load_settings
from offline_evolution.repertoire.stats import repertoire_stats
from sim_bridge.hexapod.robot import HexapodRobot
from sim_bridge.legged.pool import available_cores

PAPER_COUNT = 336  # primitives in the paper's hexapod repertoire (Sec. V-B)
COMBOS = [("paper", "grid"), ("iso_line_dd", "grid"), ("paper", "cvt"), ("iso_line_dd", "cvt")]


def machine() -> str:
    """CPU model and core count."""
    with open("/proc/cpuinfo") as f:
        names = [line.split(":", 1)[1].strip() for line in f if line.startswith("model name")]
    return f"{names[0] if names else 'unknown CPU'}, {available_cores()} cores"


def throughput(n: int, workers: int | None) -> None:
    """Evaluations per second of random primitives on ``workers`` processes."""
    settings = load_settings(robot="hexapod")
    robot = HexapodRobot(workers=workers)
    try:
        genes = np.random.default_rng(0).uniform(-1, 1, size=(n, 37))
        robot.evaluate_primitives(genes[:100], settings.eval_time)  # start the workers
        start = time.perf_counter()
        robot.evaluate_primitives(genes, settings.eval_time)
        wall = time.perf_counter() - start
    finally:
        robot.close()
    rate = n / wall
    print(f"machine: {machine()}; physics: {robot.describe()}")
    print(
        f"{n} random primitives of {settings.eval_time:g} s on {robot.pool.workers} worker(s): "
        f"{wall:.1f} s = {rate:.1f} evaluations/s ({1e3 / rate * robot.pool.workers:.1f} ms each "
        f"per core); full Table I ({settings.evaluations:,} evaluations) projected "
        f"{settings.evaluations / rate / 3600:.2f} h"
    )


def operators(out: str, iterations: int, seed: int, combos: list[tuple[str, str]]) -> None:
    """Run every operator/archive combination at the same budget; print the comparison."""
    os.makedirs(out, exist_ok=True)
    for variation, archive in combos:
        name = f"{variation}-{archive}-seed{seed}"
        result_path = os.path.join(out, f"{name}.result.json")
        if not os.path.exists(result_path):
            run_one(out, name, variation, archive, iterations, seed, result_path)
        with open(result_path) as f:
            r = json.load(f)
        s = r["stats"]
        reach = (
            f"{r['evaluations_to_paper_count']:,} evaluations / {r['minutes_to_paper_count']:.0f} "
            "min"
            if r["evaluations_to_paper_count"]
            else "not reached"
        )
        print(
            f"{variation:>11} {archive:>4}: {r['evaluations']:,} evaluations in "
            f"{r['minutes']:.0f} min; {PAPER_COUNT} primitives after {reach}; final "
            f"{s['count']} primitives, mean quality {s['mean_quality']:.2f} ± "
            f"{s['sd_quality']:.2f}, QD-score {s['qd_score']:.0f}, mirrored cells "
            f"{100 * s['mirrored']:.0f} %, left/right {s['left']}/{s['right']}"
        )


def run_one(out, name, variation, archive, iterations, seed, result_path) -> None:
    """One MAP-Elites run with a coverage curve; resumes from its checkpoint."""
    settings = load_settings(
        robot="hexapod", variation=variation, archive=archive, iterations=iterations, seed=seed
    )
    curve_path = os.path.join(out, f"{name}.curve.json")
    curve = []
    if os.path.exists(curve_path):
        with open(curve_path) as f:
            curve = json.load(f)  # [evaluations, cells, seconds] of earlier sessions
    offset = curve[-1][2] if curve else 0.0

    def progress(p):
        curve.append([p.evaluations, p.cells, offset + p.elapsed])
        atomic_write_text(curve_path, json.dumps(curve))
        print(f"  {name}: {p.evaluations:,} evaluations, {p.cells} primitives", flush=True)

    rep = generate_repertoire(
        settings,
        checkpoint=os.path.join(out, f"{name}.checkpoint.npz"),
        checkpoint_every=10,
        progress=progress,
    )
    rep.save(os.path.join(out, f"{name}.json"))
    first = next((c for c in curve if c[1] >= PAPER_COUNT), None)
    result = {
        "settings": settings.as_dict(),
        "evaluations": settings.evaluations,
        "minutes": curve[-1][2] / 60,
        "evaluations_to_paper_count": first[0] if first else None,
        "minutes_to_paper_count": first[2] / 60 if first else None,
        "stats": repertoire_stats(Repertoire.load(os.path.join(out, f"{name}.json"))),
    }
    atomic_write_text(result_path, json.dumps(result, indent=1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="what", required=True)
    t = sub.add_parser("throughput", help="evaluations/s and the projected Table I time")
    t.add_argument("--n", type=int, default=2000, help="primitives to evaluate")
    t.add_argument("--workers", type=int, help="worker processes (default: every core)")
    o = sub.add_parser("operators", help="paper vs Iso+LineDD, grid vs CVT, equal budget")
    o.add_argument("--out", required=True, help="directory for runs, curves and results")
    o.add_argument("--iterations", type=int, default=175, help="iterations after 25k initial")
    o.add_argument("--seed", type=int, default=1)
    o.add_argument("--only", nargs="*", metavar="VARIATION:ARCHIVE", help="e.g. iso_line_dd:grid")
    args = parser.parse_args()
    if args.what == "throughput":
        throughput(args.n, args.workers)
    else:
        combos = [tuple(c.split(":")) for c in args.only] if args.only else COMBOS
        operators(args.out, args.iterations, args.seed, combos)


if __name__ == "__main__":
    main()
