"""A running repertoire's state from its checkpoint: count, quality and symmetry so far.

A MAP-Elites run writes its checkpoint every few batches; this restores one into a
repertoire (the elites found so far) and prints what ``docs/hexapod.md`` reports for a
finished run: evaluations, primitives, mean quality, QD-score, filled cells, mirrored
cells and left/right counts (:func:`offline_evolution.repertoire.stats.repertoire_stats`),
and the fastest displacement. The run's settings must be given as the run was started.

    python bench/snapshot_repertoire.py CHECKPOINT --robot a1 --iterations 75 --seed 1
        [--out SNAPSHOT.json] [--plot SNAPSHOT.png]
"""

from __future__ import annotations

import argparse

import numpy as np

from offline_evolution.repertoire.map_elites import MapElites
from offline_evolution.repertoire.settings import load_settings
from offline_evolution.repertoire.stats import repertoire_stats


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("checkpoint")
    parser.add_argument("--robot", required=True)
    parser.add_argument("--iterations", type=int)
    parser.add_argument("--initial-batch", type=int)
    parser.add_argument("--seed", type=int)
    parser.add_argument("--out", help="also write the snapshot as a repertoire file")
    parser.add_argument("--plot", help="also draw it")
    args = parser.parse_args()
    settings = load_settings(
        robot=args.robot,
        iterations=args.iterations,
        initial_batch=args.initial_batch,
        seed=args.seed,
    )
    run = MapElites(settings, workers=1)
    try:
        run.restore(args.checkpoint)
        rep = run.repertoire()
    finally:
        run.close()
    s = repertoire_stats(rep)
    speed = np.hypot(*rep.behaviour.T) / rep.eval_time
    print(
        f"{rep.robot}: {run.evaluations:,} evaluations (iteration {run.iteration}/"
        f"{settings.iterations}): {s['count']} primitives, mean quality "
        f"{s['mean_quality']:.3f} +- {s['sd_quality']:.3f}, QD-score {s['qd_score']:.1f}, "
        f"{s['cells']} cells, {s['mirrored']:.0%} of off-axis cells mirrored, "
        f"{s['left']} left / {s['right']} right; fastest {speed.max():.3f} m/s, "
        f"90th percentile {np.percentile(speed, 90):.3f} m/s"
    )
    if args.out:
        rep.save(args.out)
    if args.plot:
        from offline_evolution.plots.repertoire import plot_repertoire

        plot_repertoire(rep, args.plot)


if __name__ == "__main__":
    main()
