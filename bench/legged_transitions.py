"""Measure: which of a legged repertoire's primitives fell the robot when switched into?

``bench/legged_switching.py`` counts falls when primitives are chained at random. This
blames them: for every primitive ``b`` it runs ``--trials`` transitions on flat ground,
each from rest through ``--lead`` s of another primitive drawn at random, then ``b`` for
``--hold`` s, the gait clock running on as the executor's does, and counts the
transitions that fell (body tilt past the robot's fallen tilt) while ``b`` ran. A fall in
the lead is not ``b``'s and is not counted. ``--out FILE`` writes the repertoire without the
primitives that fell in at least ``--strikes`` of their trials (an experiment on what
switching-safe primitives would give a controller: docs/your-robot.md).

    python bench/legged_transitions.py REPERTOIRE.json [--settings MODEL.yaml] [--trials 6]
        [--lead 1] [--hold 1] [--strikes 1] [--seed 0] [--out PRUNED.json] [--json FILE]

A robot made by a recipe needs its folder on ``$EVORBC_ROBOT_PATH`` (``DIR/robots``).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time

import numpy as np
from legged_bench_input import load_legged

from evorbc_ros.atomic_io import atomic_write_text


def transition(sim, table, before: int, after: int, lead: int, hold: int, fallen: float) -> int:
    """0: upright; 1: fell in ``after``'s ``hold`` steps; -1: fell in the ``lead`` steps."""
    sim.reset()
    for row, steps, code in ((before, lead, -1), (after, hold, 1)):
        targets = table.joint_targets(sim.step_times(steps), np.full(steps, row))
        tilt, _ = sim.run(targets, fallen)
        if tilt > fallen:
            return code
    return 0


def main() -> None:
    from sim_bridge.legged.physics import LeggedSim

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("repertoire")
    parser.add_argument("--settings", help="the legged settings file (default: the robot's)")
    parser.add_argument("--trials", type=int, default=6, help="transitions into each primitive")
    parser.add_argument("--lead", type=float, default=1.0, help="s of the previous primitive")
    parser.add_argument("--hold", type=float, default=1.0, help="s of the primitive after")
    parser.add_argument("--strikes", type=int, default=1, help="falls that drop a primitive")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", help="write the repertoire without the dropped primitives")
    parser.add_argument("--json", help="write the figures here")
    args = parser.parse_args()
    rep, settings = load_legged(args.repertoire, args.settings)
    dt = settings.physics.dt
    lead, hold = round(args.lead / dt), round(args.hold / dt)
    rng = np.random.default_rng(args.seed)
    n = len(rep)
    began = time.process_time()
    falls = np.zeros(n, dtype=int)
    lead_falls = 0
    with LeggedSim(settings) as sim:
        table = sim.gait_table(rep.genes)
        for b in range(n):
            others = rng.integers(n - 1, size=args.trials)
            for a in others + (others >= b):  # any primitive but b
                code = transition(sim, table, int(a), b, lead, hold, settings.fallen_tilt)
                falls[b] += code == 1
                lead_falls += code == -1
    dropped = falls >= args.strikes
    print(
        f"{rep.robot}: {int((falls > 0).sum())} of {n} primitives fell the robot in at least one "
        f"of {args.trials} transitions into them ({int(falls.sum())} of {n * args.trials} "
        f"transitions; {lead_falls} falls in a lead); {int(dropped.sum())} dropped at "
        f"{args.strikes}+; {time.process_time() - began:.0f} s CPU"
    )
    if args.out:
        keep = ~dropped
        pruned = dataclasses.replace(
            rep,
            genes=rep.genes[keep],
            behaviour=rep.behaviour[keep],
            heading=rep.heading[keep],
            quality=rep.quality[keep],
            algorithm={
                **rep.algorithm,
                "transition_test": vars(args) | {"dropped": int(dropped.sum())},
            },
        )
        pruned.save(args.out)
    if args.json:
        out = {
            "command": f"bench/legged_transitions.py {args.repertoire} --trials {args.trials} "
            f"--lead {args.lead:g} --hold {args.hold:g} --strikes {args.strikes} "
            f"--seed {args.seed}",
            "robot": rep.robot,
            "primitives": n,
            "histogram": {int(k): int((falls == k).sum()) for k in range(args.trials + 1)},
            "transitions_fell": int(falls.sum()),
            "lead_falls": lead_falls,
            "dropped": int(dropped.sum()),
        }
        atomic_write_text(args.json, json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
