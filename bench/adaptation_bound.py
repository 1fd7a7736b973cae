"""Measure: the upper bound of onboard adaptation, controllers trained on the damaged robot.

Evaluates the controllers config/recipes/measurements/4ws-5-damage-bound.yaml writes (each
the shipped 4ws-5 controller continued on a robot of one 4WS damage set, and the control
continued under ``realistic``) on the held-out generated mazes with the command docs/adaptation.md
uses for the shipped one: ``evorbc-evolve evaluate --arbitrator FILE --generated 20
--starts 20 --perturb SET --adapt`` (seed 21021 mazes, never trained on; starts and worlds
seed 0; ``recorded`` expected, default ``AdaptationSettings``;
:func:`offline_evolution.runs.evaluate.run_suites`, the command's own code). Each damage
controller runs on its own set; the control on every set, intact (``none``) included.
Prints the figures and writes them compactly (``--out``, docs/results/adaptation/).

    nice evorbc-evolve recipe config/recipes/measurements/4ws-5-damage-bound.yaml --out RUNS
    python bench/adaptation_bound.py --runs RUNS [--out docs/results/adaptation/bound.json]
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

#: Recipe step -> the set it trained on (the step's task file names it).
STEPS = {
    "stuck-steering": "4ws-stuck-steering",
    "slow-drive": "4ws-slow-drive",
    "slow-wheel": "4ws-slow-wheel",
    "slipping-wheel": "4ws-slipping-wheel",
    "realistic": "realistic",
}
#: The sets the control (``realistic``) runs on.
CONTROL_SETS = ("none", *(s for s in STEPS.values() if s != "realistic"), "realistic")


def figures(episodes) -> dict:
    """Reached (count, %), mean time to the target (s) of those reached, of ``episodes``."""
    times = [e.time for e in episodes if e.reached]
    return {
        "reached": len(times),
        "reach_pct": round(100 * len(times) / len(episodes), 2),
        "mean_time_s": round(float(np.mean(times)), 2) if times else math.nan,
    }


def measure(arbitrator: Path, name: str) -> dict:
    """One controller on one set, without and with adaptation (the same episodes)."""
    run = EvaluateRun(arbitrator=str(arbitrator), generated=20, starts=20, perturb=name, adapt=True)
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
    parser.add_argument("--steps", nargs="+", choices=list(STEPS), default=list(STEPS))
    parser.add_argument("--out", metavar="FILE.json")
    parser.add_argument(
        "--within-time", action="store_true", help="also the slow drive's time bound"
    )
    args = parser.parse_args()
    runs = Path(args.runs)
    results = []
    for step in args.steps:
        path = runs / f"4ws-5-bound-{step}.arbitrator.json"
        if not path.is_file() or path.with_name(path.name + ".checkpoint.json").exists():
            print(f"{step}: not finished in {runs}, skipped", flush=True)
            continue
        evolution = json.loads(path.read_text())["evolution"]
        sets = CONTROL_SETS if step == "realistic" else (STEPS[step],)
        for name in sets:
            row = {"trained_on": STEPS[step], **measure(path, name)}
            row["generations"] = evolution.get("generations")
            row["evolution_min"] = round(evolution.get("seconds", math.nan) / 60, 1)
            results.append(row)
            a, b = row["off"], row["on"]
            print(
                f"trained on {STEPS[step]:20s} on {name:20s} without {a['reach_pct']:5.1f} %, "
                f"{a['mean_time_s']:5.1f} s | with {b['reach_pct']:5.1f} %, "
                f"{b['mean_time_s']:5.1f} s | won / lost {row['won']} / {row['lost']}",
                flush=True,
            )
    bound = {"within_time_pct": within_time()} if args.within_time else {}
    if args.out:
        data = {"expected": "recorded", "controllers": results, **bound}
        text = json.dumps(data, indent=1)
        atomic_write_text(args.out, text + "\n")


if __name__ == "__main__":
    main()
