"""How fast and how accurate is a legged robot's physics at each rate and solver setting?

For random primitives (and a repertoire's, if given), runs each for T = 2 s from rest at a
1 kHz reference and at the candidate settings, and prints per setting: the cost of one
evaluation on one core, and the endpoint error (distance between final positions, m),
heading error and tilt-discard agreement against the reference. A 1e-6 perturbation of
every gene at the reference rate gives the chaos floor: no setting can be expected to
agree with the reference better than that. Any robot settings file works; docs/a1.md and
docs/hexapod.md record the figures.

    python bench/bench_legged_physics.py [--robot config/robots/a1.yaml] [--random 60]
        [--rates 100/50,200/50] [--repertoire FILE] [--out FILE.json]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time

import numpy as np

from evorbc_ros.repertoire import Repertoire
from sim_bridge.legged.evaluate import HEADING, TILT, evaluate_genes
from sim_bridge.legged.gait_measures import (
    NO_EARLY_STOP,
    REFERENCE,
    T,
    endpoint_errors,
    with_physics,
)
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.legged.settings import LeggedRobotSettings, load_robot_settings

CANDIDATES = "50/50,100/30,100/50,150/50,200/30,200/50,250/50,500/50"


def run(settings: LeggedRobotSettings, genes: np.ndarray) -> tuple[np.ndarray, float]:
    """Outcome rows and seconds per evaluation on one core."""
    with LeggedSim(settings) as sim:
        start = time.process_time()
        rows = evaluate_genes(sim, genes, T, settings.control_period, NO_EARLY_STOP)
        seconds = (time.process_time() - start) / len(genes)
    return rows, seconds


def compare(rows: np.ndarray, ref: np.ndarray, discard: float) -> dict:
    """Errors of ``rows`` against the reference, over primitives the reference keeps."""
    kept = ref[:, TILT] <= discard
    err = endpoint_errors(rows, ref, discard)
    heading = np.degrees(np.abs(rows[kept, HEADING] - ref[kept, HEADING]))
    return {
        "kept": int(kept.sum()),
        "endpoint_error_median_m": float(np.median(err)),
        "endpoint_error_p90_m": float(np.percentile(err, 90)),
        "heading_error_median_deg": float(np.median(heading)),
        "discard_agreement": float(np.mean((rows[:, TILT] <= discard) == kept)),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--robot", default="config/robots/a1.yaml", help="settings file")
    parser.add_argument("--random", type=int, default=60, help="random primitives (60)")
    parser.add_argument("--repertoire", help="also use this repertoire's primitives")
    parser.add_argument("--rates", default=CANDIDATES, help="RATE/ITERATIONS,... to compare")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--out", help="write the figures as JSON")
    args = parser.parse_args()

    settings = load_robot_settings(args.robot)
    discard = settings.discard_tilt
    sets = {}
    if args.random:
        rng = np.random.default_rng(args.seed)
        sets["random"] = rng.uniform(-1, 1, (args.random, settings.gait.n_parameters))
    if args.repertoire:
        sets["repertoire"] = Repertoire.load(args.repertoire).genes
    candidates = [tuple(map(float, c.split("/"))) for c in args.rates.split(",")]
    print(
        f"{settings.name}: machine {platform.processor() or platform.machine()}, "
        f"load average {os.getloadavg()[0]:.1f}; CPU time of one process per evaluation"
    )
    results = {}
    for name, genes in sets.items():
        ref, ref_cost = run(with_physics(settings, *REFERENCE), genes)
        noisy = np.clip(genes + np.random.default_rng(0).normal(0, 1e-6, genes.shape), -1, 1)
        floor, _ = run(with_physics(settings, *REFERENCE), noisy)
        label = "1000 Hz / 50 it, genes +1e-6 (chaos floor)"
        rows = {label: {**compare(floor, ref, discard), "ms_per_eval": ref_cost * 1e3}}
        for rate, iterations in candidates:
            out, cost = run(with_physics(settings, rate, int(iterations)), genes)
            rows[f"{rate:g} Hz / {iterations:g} it"] = {
                **compare(out, ref, discard),
                "ms_per_eval": cost * 1e3,
            }
        results[name] = rows
        kept = int(np.sum(ref[:, TILT] <= discard))
        print(f"\n{name} primitives ({len(genes)}, {kept} upright at the reference):")
        print(f"{'setting':<44} {'ms/eval':>8} {'err med cm':>10} {'p90 cm':>7} "
              f"{'hdg med deg':>11} {'discard agree':>13}")  # fmt: skip
        for label, r in rows.items():
            print(
                f"{label:<44} {r['ms_per_eval']:8.1f} "
                f"{100 * r['endpoint_error_median_m']:10.2f} "
                f"{100 * r['endpoint_error_p90_m']:7.2f} "
                f"{r['heading_error_median_deg']:11.1f} {r['discard_agreement']:13.2f}",
                flush=True,
            )
    if args.out:
        with open(args.out, "w", encoding="utf-8") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
