"""How fast and how accurate is the hexapod's physics at each rate and solver setting?

For a set of primitives (random genes, and the primitives of a repertoire if given), runs
each for T = 2 s from rest at a 1 kHz reference and at the candidate settings, and prints
per setting: the cost of one evaluation on one core, and the endpoint error (distance
between final positions, m), heading error and tilt-discard agreement against the
reference. A 1e-6 perturbation of every gene at the reference rate gives the chaos floor:
no setting can be expected to agree with the reference better than that.

    python bench/bench_hexapod_physics.py [--random 100] [--repertoire FILE] [--out FILE.json]
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import time

import numpy as np

from evorbc_ros.repertoire import Repertoire
from sim_bridge.hexapod.physics import HexapodSim, PhysicsSettings
from sim_bridge.legged.evaluate import HEADING, TILT, X, Y, evaluate_genes

T = 2.0
PERIOD = 0.1
NO_EARLY_STOP = math.radians(180.0)  # run every primitive the full T to compare endpoints
DISCARD = math.radians(45.0)
CANDIDATES = [
    (50, 50),
    (60, 30),
    (60, 40),
    (60, 50),
    (70, 50),
    (80, 30),
    (100, 30),
    (100, 50),
    (200, 50),
]


def run(genes: np.ndarray, rate: float, iterations: int) -> tuple[np.ndarray, float]:
    """Outcome rows and seconds per evaluation on one core."""
    sim = HexapodSim(physics=PhysicsSettings(rate=rate, solver_iterations=iterations))
    start = time.perf_counter()
    rows = evaluate_genes(sim, genes, T, PERIOD, NO_EARLY_STOP)
    seconds = (time.perf_counter() - start) / len(genes)
    sim.close()
    return rows, seconds


def compare(rows: np.ndarray, ref: np.ndarray) -> dict:
    """Errors of ``rows`` against the reference, over primitives the reference keeps."""
    kept = ref[:, TILT] <= DISCARD
    err = np.hypot(rows[kept, X] - ref[kept, X], rows[kept, Y] - ref[kept, Y])
    heading = np.degrees(np.abs(rows[kept, HEADING] - ref[kept, HEADING]))
    agree = np.mean((rows[:, TILT] <= DISCARD) == kept)
    return {
        "endpoint_error_median_m": float(np.median(err)),
        "endpoint_error_p90_m": float(np.percentile(err, 90)),
        "heading_error_median_deg": float(np.median(heading)),
        "discard_agreement": float(agree),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--random", type=int, default=100, help="random primitives (100)")
    parser.add_argument("--repertoire", help="also use this repertoire's primitives")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--out", help="write the figures as JSON")
    args = parser.parse_args()

    sets = {}
    if args.random:
        sets["random"] = np.random.default_rng(args.seed).uniform(-1, 1, (args.random, 37))
    if args.repertoire:
        sets["repertoire"] = Repertoire.load(args.repertoire).genes
    print(f"machine: {platform.processor() or platform.machine()}, one core per evaluation")
    results = {}
    for name, genes in sets.items():
        ref, ref_cost = run(genes, 1000, 50)
        noisy = np.clip(genes + np.random.default_rng(0).normal(0, 1e-6, genes.shape), -1, 1)
        floor, _ = run(noisy, 1000, 50)
        rows = {"1000 Hz / 50 it, genes +1e-6 (chaos floor)": compare(floor, ref)}
        rows["1000 Hz / 50 it, genes +1e-6 (chaos floor)"]["ms_per_eval"] = ref_cost * 1e3
        for rate, iterations in CANDIDATES:
            out, cost = run(genes, rate, iterations)
            rows[f"{rate} Hz / {iterations} it"] = {**compare(out, ref), "ms_per_eval": cost * 1e3}
        results[name] = rows
        print(f"\n{name} primitives ({len(genes)}), against 1000 Hz / 50 iterations:")
        print(f"{'setting':<44} {'ms/eval':>8} {'err med cm':>10} {'p90 cm':>7} "
              f"{'hdg med deg':>11} {'discard agree':>13}")  # fmt: skip
        for label, r in rows.items():
            print(
                f"{label:<44} {r['ms_per_eval']:8.1f} "
                f"{100 * r['endpoint_error_median_m']:10.2f} "
                f"{100 * r['endpoint_error_p90_m']:7.2f} "
                f"{r['heading_error_median_deg']:11.1f} {r['discard_agreement']:13.2f}"
            )
    if args.out:
        with open(args.out, "w", encoding="utf-8") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
