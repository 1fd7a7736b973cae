"""Measure: the upper bound of onboard adaptation, controllers trained on the damaged robot.

Evaluates the controllers config/recipes/measurements/ROBOT-damage-bound.yaml writes (each
the shipped controller continued on a robot of one damage set, and the control continued
on the robot it was trained on: ``realistic`` for the 4ws-5, intact for the hexapod) on
the held-out generated mazes with the command docs/adaptation.md uses for the shipped one:
``evorbc-evolve evaluate --arbitrator FILE --generated 20 --starts S --perturb SET
--adapt`` (seed 21021 mazes, never trained on; starts and worlds seed 0; ``recorded``
expected, the robot family's default ``AdaptationSettings``;
:func:`offline_evolution.runs.evaluate.run_suites`, the command's own code). Each damage
controller runs on its own set; the control on every set, intact (``none``) included.
Prints the figures and writes them compactly (``--out``, docs/results/adaptation/).

    nice evorbc-evolve recipe config/recipes/measurements/ROBOT-damage-bound.yaml --out RUNS
    python bench/adaptation_bound.py --runs RUNS [--robot 4ws-5|hexapod] [--starts 20]
        [--within-time] [--out docs/results/adaptation/bound.json]

``--within-time`` (the 4ws-5 only) adds the slow drive's time bound.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np

from evorbc_ros.atomic_io import atomic_write_text
from offline_evolution.reporters import Reporters
from offline_evolution.runs.evaluate import EvaluateRun, run_suites

#: Per robot: recipe step -> the set it trained on (the step's task file names it), and
#: which step is the control.
STEPS = {
    "4ws-5": {
        "stuck-steering": "4ws-stuck-steering",
        "slow-drive": "4ws-slow-drive",
        "slow-wheel": "4ws-slow-wheel",
        "slipping-wheel": "4ws-slipping-wheel",
        "realistic": "realistic",
    },
    "hexapod": {
        "leg-lost": "hexapod-leg-lost",
        "weak-side": "hexapod-weak-side",
        "knee-locked": "hexapod-knee-locked",
        "intact": "none",
    },
}
CONTROL = {"4ws-5": "realistic", "hexapod": "intact"}


def control_sets(robot: str) -> tuple[str, ...]:
    """The sets the control runs on: intact, every damage, and its own."""
    sets = [s for step, s in STEPS[robot].items() if step != CONTROL[robot]]
    own = STEPS[robot][CONTROL[robot]]
    return tuple(dict.fromkeys(["none", *sets, own]))


def figures(episodes) -> dict:
    """Reached (count, %), mean time to the target (s) of those reached, of ``episodes``."""
    times = [e.time for e in episodes if e.reached]
    return {
        "reached": len(times),
        "reach_pct": round(100 * len(times) / len(episodes), 2),
        "mean_time_s": round(float(np.mean(times)), 2) if times else math.nan,
    }


def measure(arbitrator: Path, name: str, starts: int = 20) -> dict:
    """One controller on one set, without and with adaptation (the same episodes)."""
    run = EvaluateRun(
        arbitrator=str(arbitrator), generated=20, starts=starts, perturb=name, adapt=True
    )
    runs = run_suites(run, Reporters([]))
    pairs = list(zip(runs.suite.episodes, runs.adapted.episodes, strict=True))
    return {
        "set": name,
        "episodes": len(pairs),
        "off": figures(runs.suite.episodes),
        "on": figures(runs.adapted.episodes),
        "won": sum(b.reached and not a.reached for a, b in pairs),
        "lost": sum(a.reached and not b.reached for a, b in pairs),
    }


def within_time(gains=(0.6, 0.65, 0.7)) -> dict:
    """The shipped controller on the intact robot: reached (%) within ``120 s x gain``.

    A robot whose every wheel turns at ``gain`` of its command drives the same path
    ``1 / gain`` times slower at best, so an episode the intact robot finishes in ``t``
    fits the 120 s episode only if ``t <= 120 gain`` (at best: the slow robot's ramps and
    turns are slower too): a bound on ``4ws-slow-drive``'s
    reach (gain 0.6-0.7) that no controller of this repertoire passes by driving the
    intact robot's paths.
    """
    runs = run_suites(EvaluateRun(robot="4ws-5", generated=20, starts=20), Reporters([]))
    episode_time = runs.task.settings.episode_time  # s
    out = {}
    for gain in gains:
        share = np.mean([e.reached and e.time <= episode_time * gain for e in runs.suite.episodes])
        out[f"{gain:g}"] = round(100 * float(share), 2)
    print(f"intact, shipped: reached (%) within {episode_time:g} s x gain: {out}")
    return out


def main() -> None:
    """Evaluate every finished step of the recipe's output folder; print and write."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", required=True, metavar="DIR", help="the recipe's --out")
    parser.add_argument("--robot", choices=list(STEPS), default="4ws-5")
    parser.add_argument("--steps", nargs="+", help="default: every step of --robot's recipe")
    parser.add_argument("--starts", type=int, default=20, help="starts per held-out maze")
    parser.add_argument("--out", metavar="FILE.json")
    parser.add_argument(
        "--within-time", action="store_true", help="also the slow drive's time bound"
    )
    args = parser.parse_args()
    if args.within_time and args.robot != "4ws-5":
        parser.error("--within-time: the 4ws-5's slow-drive bound only (--robot 4ws-5)")
    steps = STEPS[args.robot]
    for step in args.steps or ():
        if step not in steps:
            parser.error(f"--steps: {step!r} is not a step of {args.robot}'s recipe")
    runs = Path(args.runs)
    results = []
    for step in args.steps or steps:
        path = runs / f"{args.robot}-bound-{step}.arbitrator.json"
        if not path.is_file() or path.with_name(path.name + ".checkpoint.json").exists():
            print(f"{step}: not finished in {runs}, skipped", flush=True)
            continue
        evolution = json.loads(path.read_text())["evolution"]
        sets = control_sets(args.robot) if step == CONTROL[args.robot] else (steps[step],)
        for name in sets:
            row = {"trained_on": steps[step], **measure(path, name, args.starts)}
            row["generations"] = evolution.get("generations")
            row["evolution_min"] = round(evolution.get("seconds", math.nan) / 60, 1)
            results.append(row)
            a, b = row["off"], row["on"]
            print(
                f"trained on {steps[step]:20s} on {name:20s} without {a['reach_pct']:5.1f} %, "
                f"{a['mean_time_s']:5.1f} s | with {b['reach_pct']:5.1f} %, "
                f"{b['mean_time_s']:5.1f} s | won / lost {row['won']} / {row['lost']}",
                flush=True,
            )
    bound = {"within_time_pct": within_time()} if args.within_time else {}
    if args.out:
        data = {"robot": args.robot, "starts": args.starts, "expected": "recorded"}
        data.update(controllers=results, **bound)
        text = json.dumps(data, indent=1)
        atomic_write_text(args.out, text + "\n")


if __name__ == "__main__":
    main()
