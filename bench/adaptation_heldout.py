"""Measure: onboard adaptation of the shipped 4ws-5 controller on the held-out mazes.

For each set (intact, the 4WS damage sets, ``realistic``) runs ``evorbc-evolve evaluate
--robot 4ws-5 --generated 20 --starts 20 --perturb SET --adapt --adapt-expected E``
(the held-out generated mazes, seed 21021; starts and worlds seed 0; default
:class:`~evorbc_ros.adaptation.AdaptationSettings`, nothing tuned on these mazes), replays
each adapted episode's outcome model from its traces
(:func:`offline_evolution.maze_task.adaptation_replay.replay_model`: observations and
primitives observed cycle by cycle, choices changed) and prints the tables of
docs/design/adaptation.md: reach and mean time to the target without and with adaptation
against the issue's targets, per damaged wheel, how many observations the episodes took,
and the reach as a function of elapsed time. ``--out FILE.json`` writes the figures
(docs/results/adaptation/); ``--pictures DIR`` draws the paths of one maze before and after
adaptation under a stuck steering wheel, that episode's corrected outcome map and the
execution error over elapsed time per set (:mod:`offline_evolution.plots.adaptation`).

    python bench/adaptation_heldout.py [--expected recorded] [--sets none ...]
        [--out docs/results/adaptation/heldout-recorded.json] [--pictures docs/]
"""

from __future__ import annotations

import argparse
import json
import math

import numpy as np

from evorbc_ros.atomic_io import atomic_write_text
from offline_evolution.maze_task.adaptation_replay import replay_model
from offline_evolution.maze_task.adapting import EXPECTED, expected_outcomes
from offline_evolution.reporters import Reporters
from offline_evolution.runs.evaluate import EvaluateRun, run_suites

SETS = (
    "none",
    "4ws-stuck-steering",
    "4ws-slow-wheel",
    "4ws-slipping-wheel",
    "4ws-slow-drive",
    "realistic",
)
#: s, elapsed times at which the reach so far and the observations are reported.
TIMES = (15, 30, 60, 90, 120)
#: s, windows of elapsed time over which execution errors are averaged.
WINDOWS = ((0, 5), (5, 10), (10, 20), (20, 30), (30, 60), (60, 120))


def world_rows(runs, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``(n, 7)`` each episode's world (gain, ..., damaged wheel) and ``(n,)`` keys, as
    :func:`~offline_evolution.maze_task.evaluation.evaluate_suite` drew them."""
    from offline_evolution.maze_task.perturbation import NONE

    if runs.perturbation is NONE:
        rows = np.zeros((n, 7))
        rows[:, 0] = 1.0
        return rows, np.zeros(n, dtype=np.int64)
    world = runs.perturbation.draw(np.random.default_rng([0, 1]), n)
    return world.kernel_arrays(runs.task.sensors.max_range), world.keys


def execution_errors(runs, replays) -> dict:
    """How far what the robot did is from what the network asked, over elapsed time.

    Per cycle: the distance between the settled outcome, on this episode's robot (its
    wheel speed gain and damaged wheel, :func:`sim_bridge.four_ws.steady.settled_outcomes`),
    of the primitive run and the recorded outcome of the grid's choice (what the evolved
    controller expects), each dimension over the repertoire's extent; ``best``: the
    nearest any primitive of the repertoire comes to it on that robot. Without adaptation
    the primitive run is the grid's choice. Means over the cycles of each of
    :data:`WINDOWS`.
    """
    from evorbc_ros.adaptation import outcome_table
    from sim_bridge.four_ws.steady import settled_outcomes

    rep, robot = runs.repertoire, runs.task.robot
    recorded = outcome_table(rep.behaviour, rep.heading)
    weight = 1.0 / (recorded.max(axis=0) - recorded.min(axis=0))
    commands = robot.commands(rep.genes)
    rows, keys = world_rows(runs, len(replays))
    sums = {k: np.zeros(len(WINDOWS)) for k in ("off", "on", "best")}
    counts = {k: np.zeros(len(WINDOWS)) for k in ("off", "on")}
    tables = {}
    for e, replay in enumerate(replays):
        damage = rows[e, 4:7] if rows[e, 4] != 0.0 else None
        slipping = damage is not None and int(damage[0]) == 3
        cache = (rows[e, 0], None if damage is None else tuple(damage), keys[e] if slipping else 0)
        if cache not in tables:
            table = settled_outcomes(commands, robot.limits, rep.eval_time, rows[e, 0], damage,
                                     int(keys[e]))  # fmt: skip
            gap = np.sqrt((((table[None, :] - recorded[:, None]) * weight) ** 2).sum(axis=-1))
            tables[cache] = gap  # (asked, run)
        gap = tables[cache]
        ran_off = runs.suite.choices[e]
        for name, asked, ran in (
            ("off", ran_off, ran_off),
            ("on", replay.asked, runs.adapted.choices[e]),
        ):
            cycle = np.arange(len(ran)) * runs.task.dt
            ok = (asked >= 0) & (ran >= 0)
            for w, (t0, t1) in enumerate(WINDOWS):
                sel = ok & (cycle >= t0) & (cycle < t1)
                sums[name][w] += gap[asked[sel], ran[sel]].sum()
                counts[name][w] += sel.sum()
                if name == "on":
                    sums["best"][w] += gap[asked[sel]].min(axis=1).sum()
    out = {}
    for name, total in sums.items():
        n = counts["on" if name == "best" else name]
        out[name] = [round(float(v), 4) for v in total / np.maximum(n, 1)]
    return out


def reach(episodes) -> dict:
    """Reached share (%) and mean time to the target (s) of the episodes reached."""
    times = [e.time for e in episodes if e.reached]
    return {
        "episodes": len(episodes),
        "reached": len(times),
        "reach_pct": round(100 * len(times) / len(episodes), 2),
        "mean_time_s": round(float(np.mean(times)), 2) if times else math.nan,
    }


def by_time(episodes, replays, dt: float) -> list[dict]:
    """At each of :data:`TIMES` (s): reached so far (%) and, adapting, the mean observations
    and primitives observed by then (an episode that ended earlier counts its last figures).
    """
    rows = []
    for s in TIMES:
        done = [e.reached and e.time <= s for e in episodes]
        row = {"t_s": s, "reached_pct": round(100 * float(np.mean(done)), 2)}
        if replays:
            k = round(s / dt)
            obs = [r.observations[min(k, len(r.observations)) - 1] for r in replays]
            seen = [r.observed[min(k, len(r.observed)) - 1] for r in replays]
            row["observations"] = round(float(np.mean(obs)), 1)
            row["observed"] = round(float(np.mean(seen)), 1)
        rows.append(row)
    return rows


def measure(name: str, expected: str) -> tuple[dict, object, list]:
    """One set: figures, the :class:`~offline_evolution.runs.evaluate.SuiteRuns` and replays."""
    run = EvaluateRun(
        robot="4ws-5", generated=20, starts=20, perturb=name, adapt=True, adapt_expected=expected
    )
    runs = run_suites(run, Reporters([]))
    off, on = runs.suite, runs.adapted
    task = runs.task
    controller = task.controller(runs.arbitrator.kind, runs.repertoire, runs.arbitrator.mapping)
    table = expected_outcomes(runs.repertoire, task.robot, expected)
    replays = [
        replay_model(runs.repertoire, controller, runs.settings, table, task.dt, p, c, o)
        for p, c, o in zip(on.paths, on.choices, on.outputs, strict=True)
    ]
    won = sum(b.reached and not a.reached for a, b in zip(off.episodes, on.episodes, strict=True))
    lost = sum(a.reached and not b.reached for a, b in zip(off.episodes, on.episodes, strict=True))
    both = [
        (a, b) for a, b in zip(off.episodes, on.episodes, strict=True) if a.reached and b.reached
    ]
    parts = sorted({e.damaged_part for e in off.episodes if e.damaged_part})
    per_part = {}
    for part in parts:
        idx = [k for k, e in enumerate(off.episodes) if e.damaged_part == part]
        per_part[part] = {
            "off": reach([off.episodes[k] for k in idx]),
            "on": reach([on.episodes[k] for k in idx]),
            "observations": round(float(np.mean([replays[k].observations[-1] for k in idx])), 1),
        }
    figures = {
        "set": name,
        "off": reach(off.episodes),
        "on": reach(on.episodes),
        "won": won,
        "lost": lost,
        "both_reached_time_s": [
            round(float(np.mean([a.time for a, _ in both])), 2) if both else math.nan,
            round(float(np.mean([b.time for _, b in both])), 2) if both else math.nan,
        ],
        "observations_per_episode": round(float(np.mean([r.observations[-1] for r in replays])), 1),
        "primitives_observed": round(float(np.mean([r.observed[-1] for r in replays])), 1),
        "changed_cycles_pct": round(
            100
            * float(np.sum([r.changed.sum() for r in replays]))
            / sum(len(r.changed) for r in replays),
            1,
        ),
        "replay_disagreements": int(sum(r.disagreements for r in replays)),
        "execution_error": execution_errors(runs, replays),
        "by_time_off": by_time(off.episodes, [], task.dt),
        "by_time_on": by_time(on.episodes, replays, task.dt),
        **({"per_part": per_part} if per_part else {}),
    }
    return figures, runs, replays


def print_tables(results: list[dict]) -> None:
    """The markdown tables of docs/design/adaptation.md."""
    intact = next((r for r in results if r["set"] == "none"), None)
    base = intact["off"]["reach_pct"] if intact else math.nan
    print("| set | without | with | won / lost | loss without | loss with | share | obs. |")
    print("|---|---|---|---|---|---|---|---|")
    for r in results:
        a, b = r["off"], r["on"]
        la, lb = base - a["reach_pct"], base - b["reach_pct"]
        share = f"{100 * lb / la:.0f} %" if la > 0 else ""
        print(
            f"| `{r['set']}` | {a['reach_pct']:.1f} %, {a['mean_time_s']:.1f} s | "
            f"{b['reach_pct']:.1f} %, {b['mean_time_s']:.1f} s | {r['won']} / {r['lost']} | "
            f"{la:.1f} | {lb:.1f} | {share} | {r['observations_per_episode']:.0f} |"
        )
    for r in results:
        for part, p in r.get("per_part", {}).items():
            a, b = p["off"]["reach_pct"], p["on"]["reach_pct"]
            print(
                f"{r['set']:20s} {part}: {a:5.1f} -> {b:5.1f} % ({p['off']['episodes']} "
                f"episodes), {p['observations']:.0f} observations"
            )
    print("execution error (share of the extent) in windows", WINDOWS, "s: off | on | best")
    for r in results:
        x = r["execution_error"]
        cells = zip(x["off"], x["on"], x["best"], strict=True)
        print(
            f"| `{r['set']}` | " + " | ".join(f"{a:.3f} / {b:.3f} / {c:.3f}" for a, b, c in cells)
        )
    for r in results:
        row = " | ".join(
            f"{off['reached_pct']:.1f} / {on['reached_pct']:.1f} ({on['observations']:.0f}, "
            f"{on['observed']:.0f})"
            for off, on in zip(r["by_time_off"], r["by_time_on"], strict=True)
        )
        print(f"| `{r['set']}` | {row} |")


def main() -> None:
    """Measure, print, write the figures and pictures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--expected", choices=EXPECTED, default="recorded")
    parser.add_argument("--sets", nargs="+", default=list(SETS))
    parser.add_argument("--out", metavar="FILE.json")
    parser.add_argument("--pictures", metavar="DIR")
    args = parser.parse_args()
    results = []
    for name in args.sets:
        figures, runs, replays = measure(name, args.expected)
        results.append(figures)
        print(f"{name}: done", flush=True)
        if args.pictures and name == "4ws-stuck-steering":
            from offline_evolution.plots.adaptation import draw_pictures

            for path in draw_pictures(runs, replays, args.pictures):
                print(f"wrote {path}")
    print_tables(results)
    if args.pictures:
        from offline_evolution.plots.adaptation import save_error_over_time

        print(f"wrote {save_error_over_time(WINDOWS, results, args.pictures)}")
    if args.out:
        text = json.dumps({"expected": args.expected, "sets": results}, indent=1)
        atomic_write_text(args.out, text + "\n")


if __name__ == "__main__":
    main()
