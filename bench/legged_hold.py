"""Measure: do a legged repertoire's primitives stay up when held longer than their T?

A repertoire evaluates each primitive for T = 2 s from rest and discards it if the body
tilts past ``tilt.discard_deg`` (eq. 6). An arbitrator may hold a primitive for many
cycles. For each primitive this holds it from rest for ``--hold`` s (its own settings'
physics, no walls) and records when the body tilted past the fallen tilt, then, for a
range of discard tilts, how many primitives a repertoire would keep and how many of those
fall: whether the largest tilt within T predicts a later fall (docs/your-robot.md, "The
Laikago's falls").

    python bench/legged_hold.py REPERTOIRE.json [--settings MODEL.yaml] [--hold 30]
        [--json FILE]

A robot made by a recipe needs its folder on ``$EVORBC_ROBOT_PATH`` (``DIR/robots``);
``--settings`` defaults to the registered robot's model file.
"""

from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np
from legged_bench_input import load_legged

from evorbc_ros.atomic_io import atomic_write_text

#: deg: the discard tilts compared (the shipped robots' is 45).
THRESHOLDS = (10, 15, 20, 25, 30, 35, 45)


def held(sim, table, row: int, hold: float, fallen: float) -> tuple[float, float]:
    """``(largest tilt within 2 s (rad), s it fell at or inf)`` holding ``row`` from rest."""
    sim.reset()
    dt = sim.settings.physics.dt
    chunk = round(1.0 / dt)  # steps: 1 s at a time, so T = 2 s is two chunks
    first, fell = 0.0, math.inf
    for second in range(math.ceil(hold)):
        targets = table.joint_targets(sim.step_times(chunk), np.full(chunk, row))
        tilt, _ = sim.run(targets, fallen)
        if second < 2:
            first = max(first, tilt)
        if tilt > fallen:
            fell = sim.time
            break
    return first, fell


def main() -> None:
    from sim_bridge.legged.physics import LeggedSim

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("repertoire")
    parser.add_argument("--settings", help="the legged settings file (default: the robot's)")
    parser.add_argument("--hold", type=float, default=30.0, help="s each primitive is held")
    parser.add_argument("--json", help="write the figures here")
    args = parser.parse_args()
    rep, settings = load_legged(args.repertoire, args.settings)
    began = time.process_time()
    with LeggedSim(settings) as sim:
        table = sim.gait_table(rep.genes)
        rows = [held(sim, table, i, args.hold, settings.fallen_tilt) for i in range(len(rep))]
    tilts = np.degrees([r[0] for r in rows])
    falls = np.array([r[1] for r in rows])
    fell = np.isfinite(falls)
    print(
        f"{rep.robot}: {int(fell.sum())} of {len(rep)} primitives fell held {args.hold:g} s "
        f"(median at {np.median(falls[fell]) if fell.any() else math.nan:.2f} s); "
        f"{time.process_time() - began:.0f} s CPU"
    )
    table_rows = []
    for deg in THRESHOLDS:
        kept = tilts <= deg
        row = {"discard_deg": deg, "kept": int(kept.sum()), "fall": int((kept & fell).sum())}
        table_rows.append(row)
        print(f"  discard above {deg:>2} deg: kept {row['kept']:>4}, of them fall {row['fall']:>4}")
    if args.json:
        out = {
            "command": f"bench/legged_hold.py {args.repertoire} --hold {args.hold:g}",
            "robot": rep.robot,
            "primitives": len(rep),
            "hold_s": args.hold,
            "fell": int(fell.sum()),
            "fall_times_s": sorted(round(float(f), 2) for f in falls[fell]),
            "by_discard": table_rows,
        }
        atomic_write_text(args.json, json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
