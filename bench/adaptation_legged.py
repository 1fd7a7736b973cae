"""Measure: onboard adaptation of a shipped legged controller on the held-out mazes.

For each set (intact and the robot's damage sets) runs ``evorbc-evolve evaluate --robot R
--generated G --starts S --perturb SET --adapt`` (``offline_evolution.runs.evaluate.run_suites``,
the command's own code: the held-out generated mazes, seed 21021, never tuned on; starts
and worlds seed 0; the robot family's default
:class:`~evorbc_ros.adaptation.AdaptationSettings`, the node's) and reports reach and mean
time to the target without and with adaptation, the episodes won and lost, the loss
against the intact robot without adaptation and its share with adaptation (issue 42's
target: at most half; intact: at most 2 points), falls, observations per adapted episode
and reach per damaged leg or side. ``--out FILE.json`` writes the figures
(docs/results/adaptation/). ``--expected settled`` compares observations with the legged
settled outcomes (``evaluate --adapt-expected settled``: computed first, in PyBullet);
several (``--expected recorded settled``) run the unadapted suite once and adapt against
each; ``--generated 0`` runs the controller's own training mazes instead of generated ones.
``--intact FILE`` takes the intact robot's reach from an earlier ``--out`` of the same
suite, so that each damage set can run on its own (``--sets hexapod-leg-lost``).
``--setting KEY=VALUE`` (repeatable) overrides a field of the robot family's default
:class:`~evorbc_ros.adaptation.AdaptationSettings` (``noise=1.0``, ``average=8``), to compare
settings on the training mazes before one is made the default.

    python bench/adaptation_legged.py [--robot hexapod] [--generated 10] [--starts 4]
        [--expected recorded settled] [--sets none hexapod-leg-lost ...] [--setting noise=1]
        [--intact FILE]
        [--out docs/results/adaptation/hexapod.json]
"""

from __future__ import annotations

import argparse
import json
import math
import time
from dataclasses import asdict

import numpy as np

from evorbc_ros.atomic_io import atomic_write_text
from offline_evolution.maze_task.evaluation import summarise
from offline_evolution.reporters import Reporters
from offline_evolution.runs.evaluate import EvaluateRun, run_suites

#: The damage sets of each legged robot (config/perturbations/).
DAMAGE = {
    "hexapod": ("hexapod-leg-lost", "hexapod-knee-locked", "hexapod-weak-side"),
    "a1": ("a1-weak-leg", "a1-knee-locked"),
}


def reach(episodes) -> dict:
    """Reached share (%), falls and mean time to the target (s) of the episodes reached."""
    row = summarise(episodes, "")
    times = [e.time for e in episodes if e.reached]
    return {
        "episodes": row["episodes"],
        "reached": row["reached"],
        "reach_pct": round(100 * row["reach_rate"], 2),
        "mean_time_s": round(float(np.mean(times)), 2) if times else math.nan,
        "falls": row["falls"],
    }


def measure(robot: str, name: str, generated: int, starts: int, expected=("recorded",), cache=None):
    """One set's figures per ``expected`` (see the module docstring); ``generated`` 0: the
    training mazes. The suite without adaptation runs once; ``cache``: expected outcomes by
    repertoire fingerprint (the settled ones are computed once for every set)."""
    run = EvaluateRun(
        robot=robot,
        generated=generated or None,
        starts=starts,
        perturb=name,
        adapt=True,
        adapt_expected=expected[0],
    )
    began = time.monotonic()
    runs = run_suites(run, Reporters([]))
    observations = runs.task.observations  # of the adapted suite, the last one run
    results = [figures(name, runs, runs.adapted, observations, expected[0], began)]
    for other in expected[1:]:
        began = time.monotonic()
        adapted, observations = adapted_again(runs, run, other, {} if cache is None else cache)
        results.append(figures(name, runs, adapted, observations, other, began))
    return results


def adapted_again(runs, run: EvaluateRun, expected: str, cache: dict):
    """The suite of ``runs`` adapting again, against ``expected``: ``(suite, observations)``.

    As :func:`~offline_evolution.runs.evaluate.run_suites` adapts (the same task, starts,
    worlds and settings), without running the unadapted suite again.
    """
    from offline_evolution.maze_task.adapting import expected_outcomes
    from offline_evolution.maze_task.evaluation import evaluate_suite

    task, rep, arb = runs.task, runs.repertoire, runs.arbitrator
    key = (rep.fingerprint(), expected)
    if key not in cache:
        began = time.process_time()
        cache[key] = expected_outcomes(rep, task.robot, expected)
        print(f"expected {expected}: {time.process_time() - began:.1f} s of CPU", flush=True)
    task.adapt(task.adapting_for(rep, runs.settings, cache[key]))
    try:
        controller = task.controller(arb.kind, rep, arb.mapping)
        suite = evaluate_suite(
            task, arb.network, controller, run.starts, run.seed, runs.perturbation
        )
    finally:
        task.adapt(None)
        task.close()
    return suite, list(task.observations)


def figures(name: str, runs, adapted, observations, expected: str, began: float) -> dict:
    """The figures of one adapted suite against the unadapted one."""
    off, on = runs.suite.episodes, adapted.episodes
    pairs = list(zip(off, on, strict=True))
    paths = zip(runs.suite.choices, adapted.choices, strict=True)
    per_part = {}
    for part in sorted({e.damaged_part for e in off if e.damaged_part}):
        idx = [k for k, e in enumerate(off) if e.damaged_part == part]
        per_part[part] = {
            "off": reach([off[k] for k in idx]),
            "on": reach([on[k] for k in idx]),
        }
    return {
        "set": name,
        "off": reach(off),
        "on": reach(on),
        "won": sum(b.reached and not a.reached for a, b in pairs),
        "lost": sum(a.reached and not b.reached for a, b in pairs),
        "observations_per_episode": round(float(np.mean(observations)), 2),
        "episodes_observed_pct": round(100 * float(np.mean(np.array(observations) > 0)), 1),
        "changed_episodes": sum(not np.array_equal(a, b) for a, b in paths),
        **({"per_part": per_part} if per_part else {}),
        "expected": expected,
        "settings": asdict(runs.settings),
        "wall_s": round(time.monotonic() - began, 1),
    }


def with_losses(results: list[dict], intact: float | None = None) -> list[dict]:
    """Each set's loss (reach points below the intact robot without adaptation) and share.

    ``intact``: the intact robot's reach without adaptation (%), when ``results`` hold no
    ``none`` set (``--intact``).
    """
    if intact is None:
        intact = next(r for r in results if r["set"] == "none")["off"]["reach_pct"]
    for r in results:
        off, on = intact - r["off"]["reach_pct"], intact - r["on"]["reach_pct"]
        r["loss_off"], r["loss_on"] = round(off, 2), round(on, 2)
        r["loss_share"] = round(on / off, 3) if off > 0 else None
    return results


def print_table(results: list[dict]) -> None:
    """The markdown table of docs/adaptation.md."""
    print("| set | without | with | won / lost | loss without / with (share) | obs. / episode |")
    print("|---|---|---|---|---|---|")
    for r in results:
        share = f" ({100 * r['loss_share']:.0f} %)" if r["loss_share"] is not None else ""
        print(
            f"| {r['set']} ({r['expected']}) "
            f"| {r['off']['reach_pct']:.1f} %, {r['off']['mean_time_s']:.1f} s "
            f"| {r['on']['reach_pct']:.1f} %, {r['on']['mean_time_s']:.1f} s "
            f"| {r['won']} / {r['lost']} | {r['loss_off']:.1f} / {r['loss_on']:.1f}{share} "
            f"| {r['observations_per_episode']:.1f} |"
        )


def override_settings(pairs: list[str]) -> dict:
    """Make ``evorbc_ros.adaptation.settings_for`` give the family default with ``pairs``.

    What ``evaluate --adapt`` adapts with is the node's default for the robot's family
    (:func:`offline_evolution.maze_task.adapting.task_adapting`, called in this process),
    so replacing the function here changes the suites measured and nothing else.

    Returns:
        The overridden fields, typed as the settings' (for the JSON record).
    """
    import dataclasses

    import evorbc_ros.adaptation as adaptation

    fields = {f.name: f.type for f in dataclasses.fields(adaptation.AdaptationSettings)}
    changes = {}
    for pair in pairs:
        key, _, value = pair.partition("=")
        if key not in fields:
            raise SystemExit(f"--setting {pair}: no such field (one of {', '.join(fields)})")
        kind = {"int": int, "float": float}.get(str(fields[key]), str)
        changes[key] = kind(value)
    default = adaptation.settings_for
    adaptation.settings_for = lambda family: dataclasses.replace(default(family), **changes)
    return changes


def intact_reach(path: str, robot: str, generated: int, starts: int) -> float:
    """The intact robot's reach without adaptation (%) in an earlier ``--out`` file.

    Raises:
        SystemExit: one line, if the file is not of the same robot and suite or has no
            ``none`` set.
    """
    with open(path, encoding="utf-8") as f:
        earlier = json.load(f)
    suite = (earlier.get("robot"), earlier.get("generated"), earlier.get("starts_per_maze"))
    want = (robot, {"count": generated, "seed": 21021} if generated else suite[1], starts)
    if suite != want:
        raise SystemExit(f"--intact {path}: another suite ({suite}), expected {want}")
    for r in earlier.get("sets", []):
        if r.get("set") == "none":
            return float(r["off"]["reach_pct"])
    raise SystemExit(f"--intact {path}: no 'none' set in it")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="hexapod", choices=sorted(DAMAGE))
    parser.add_argument("--generated", type=int, default=10)
    parser.add_argument("--starts", type=int, default=4)
    parser.add_argument(
        "--expected", nargs="+", default=["recorded"], choices=("recorded", "settled")
    )
    parser.add_argument("--sets", nargs="+", default=None, help="default: none and the damage")
    parser.add_argument("--out", help="write the figures as JSON")
    parser.add_argument("--setting", action="append", default=[], metavar="KEY=VALUE")
    parser.add_argument(
        "--intact", help="an --out file of the same suite with 'none', when --sets lacks it"
    )
    args = parser.parse_args()
    changes = override_settings(args.setting)
    sets = args.sets or ["none", *DAMAGE[args.robot]]
    intact = None
    if "none" not in sets:
        if not args.intact:
            parser.error("--sets: the losses are against 'none', the intact robot: add it or "
                         "give --intact FILE")  # fmt: skip
        intact = intact_reach(args.intact, args.robot, args.generated, args.starts)
    results, cache = [], {}
    for name in sets:
        for r in measure(args.robot, name, args.generated, args.starts, args.expected, cache):
            results.append(r)
            print(json.dumps(r), flush=True)
    with_losses(results, intact)
    print_table(results)
    if args.out:
        out = {
            "command": f"bench/adaptation_legged.py --robot {args.robot} --generated "
            f"{args.generated} --starts {args.starts} --sets {' '.join(sets)} "
            f"--expected {' '.join(args.expected)}"
            + "".join(f" --setting {pair}" for pair in args.setting),
            "robot": args.robot,
            "expected": args.expected,
            "generated": {"count": args.generated, "seed": 21021}
            if args.generated
            else "the controller's training mazes",
            "starts_per_maze": args.starts,
            "seed": 0,
            "settings_changed": changes,
            **({"intact_from": args.intact, "intact_reach_pct": intact} if intact else {}),
            "sets": results,
        }
        atomic_write_text(args.out, json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
