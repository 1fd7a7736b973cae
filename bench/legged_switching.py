"""Measure: does a legged repertoire stay up when its primitives are switched?

``bench/legged_hold.py`` holds each primitive alone; an arbitrator switches them as often
as every control cycle (0.1 s). This runs ``--episodes`` episodes of ``--time`` s from
rest on flat ground (no walls), each switching to a primitive drawn uniformly from the
repertoire every ``--period`` s (several periods compare), the gait clock running on as
the executor's does, and reports how many fell (body tilt past the robot's fallen tilt)
and when: the fall rate that switching itself brings, to set against a controller's
falls in its mazes (docs/your-robot.md). ``--blend S`` eases each switch, the joint
targets ramped from the previous primitive's to the new one's over S s (an experiment:
the executor switches at once).

    python bench/legged_switching.py REPERTOIRE.json [--settings MODEL.yaml]
        [--periods 0.1 0.5 2] [--episodes 20] [--time 30] [--seed 0] [--blend 0]
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


def switching(sim, table, rows: np.ndarray, period: float, fallen: float, blend: float) -> float:
    """s at which the body fell (inf: never), running ``rows[k]`` in the k-th period.

    ``blend`` s: after a switch the joint targets move linearly from the previous
    primitive's to the new one's (both at the same gait times) over that long; 0: at once,
    as the executor switches.
    """
    sim.reset()
    dt = sim.settings.physics.dt
    steps = max(1, round(period / dt))  # physics steps a period
    ramp = np.clip((np.arange(steps) + 1) * dt / blend, 0.0, 1.0)[:, None] if blend > 0 else 1.0
    previous = None
    for row in rows:
        times = sim.step_times(steps)
        targets = table.joint_targets(times, np.full(steps, row))
        if previous is not None and previous != row and blend > 0:
            before = table.joint_targets(times, np.full(steps, previous))
            targets = before + ramp * (targets - before)
        previous = row
        tilt, _ = sim.run(targets, fallen)
        if tilt > fallen:
            return sim.time
    return math.inf


def main() -> None:
    from sim_bridge.legged.physics import LeggedSim

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("repertoire")
    parser.add_argument("--settings", help="the legged settings file (default: the robot's)")
    parser.add_argument("--periods", type=float, nargs="+", default=[0.1, 0.5, 2.0])
    parser.add_argument("--episodes", type=int, default=20)
    parser.add_argument("--time", type=float, default=30.0, help="s an episode")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--blend", type=float, default=0.0, help="s a switch's ramp lasts")
    parser.add_argument("--json", help="write the figures here")
    args = parser.parse_args()
    rep, settings = load_legged(args.repertoire, args.settings)
    began = time.process_time()
    rows = []
    with LeggedSim(settings) as sim:
        table = sim.gait_table(rep.genes)
        for period in args.periods:
            rng = np.random.default_rng([args.seed, round(period * 1000)])
            draws = rng.integers(len(rep), size=(args.episodes, math.ceil(args.time / period)))
            falls = np.array(
                [switching(sim, table, d, period, settings.fallen_tilt, args.blend) for d in draws]
            )
            fell = np.isfinite(falls)
            row = {
                "period_s": period,
                "episodes": args.episodes,
                "fell": int(fell.sum()),
                "fall_times_s": sorted(round(float(f), 2) for f in falls[fell]),
            }
            rows.append(row)
            median = np.median(falls[fell]) if fell.any() else math.nan
            print(
                f"{rep.robot}: switching every {period:g} s for {args.time:g} s: "
                f"{row['fell']} of {args.episodes} fell (median at {median:.1f} s)"
            )
    print(f"{time.process_time() - began:.0f} s CPU")
    if args.json:
        out = {
            "command": f"bench/legged_switching.py {args.repertoire} --periods "
            + " ".join(f"{p:g}" for p in args.periods)
            + f" --episodes {args.episodes} --time {args.time:g} --seed {args.seed}",
            "robot": rep.robot,
            "primitives": len(rep),
            "rows": rows,
        }
        atomic_write_text(args.json, json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
