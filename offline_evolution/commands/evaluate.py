"""``evorbc-evolve evaluate``: a controller on a suite of mazes, from many starts, perturbed."""

from __future__ import annotations

import argparse
import json

from evorbc_ros.robots.registry import DEFAULT_ROBOT
from offline_evolution import bounds
from offline_evolution.commands.common import at_least, count
from offline_evolution.commands.replay import REPERTOIRE_DEFAULT
from offline_evolution.maze_task.adapting import EXPECTED
from offline_evolution.runs.command_line import from_arguments
from offline_evolution.runs.console import EpisodePrinter, WarningPrinter
from offline_evolution.runs.evaluate import PAPER, EvaluateRun, evaluate_run
from offline_evolution.runs.replay import WAIVER
from sim_bridge.cli_options import (
    add_arbitrator,
    add_flag,
    add_repertoire,
    add_robot,
    add_seed,
    add_task,
)
from sim_bridge.cli_support import integer_in


def add_parsers(sub) -> None:
    """Register ``evaluate``."""
    p = sub.add_parser(
        "evaluate",
        help="run a controller on a suite of mazes from random starts, optionally in "
        "perturbed worlds, and report reach rate, fitness, stalls, collisions and falls",
        description="Held-out evaluation: run an arbitrator (EvoRBC or standard NEAT) from "
        "N seeded random starts in each maze of a suite (its training mazes, generated "
        "mazes, maze files or folders of them), under a perturbation set, and report per "
        "maze and overall.",
    )
    add_arbitrator(p, "the shipped one for --robot")
    add_robot(p, "whose shipped controller, without --arbitrator", DEFAULT_ROBOT)
    add_flag(p, "--paper")
    add_repertoire(p, REPERTOIRE_DEFAULT)
    p.add_argument(
        "--mazes",
        nargs="+",
        metavar="NAME|FILE|DIR",
        help=f"the suite: '{PAPER}' (the mazes the controller was trained on), maze names, "
        f"maze files or folders of them (default: {PAPER}, unless --generated is given)",
    )
    p.add_argument(
        "--generated",
        type=integer_in(1, bounds.MAZES),
        metavar="N",
        help="add N mazes generated for the robot (evorbc-evolve mazes) to the suite "
        f"(at most {bounds.MAZES:,})",
    )
    p.add_argument(
        "--generated-seed",
        type=count,
        default=EvaluateRun.generated_seed,
        metavar="N",
        help=f"seed of the generated mazes (default {EvaluateRun.generated_seed}: the "
        "held-out set, never used for training)",
    )
    p.add_argument(
        "--starts",
        type=at_least(1),
        default=EvaluateRun.starts,
        metavar="N",
        help=f"per maze ({EvaluateRun.starts})",
    )
    add_seed(p, "starts and worlds")
    p.add_argument(
        "--perturb",
        default=EvaluateRun.perturb,
        metavar="none|NAME|FILE.yaml",
        help="perturbation or damage set: a shipped one (config/perturbations/: realistic, "
        "4ws-stuck-steering, hexapod-leg-lost, ...; docs/perturbations.md) or a file",
    )
    add_task(p, "the arbitrator's; its episode time and sensors")
    p.add_argument("--plot", metavar="FILE.png", help="picture of the suite with every path")
    p.add_argument("--out", metavar="FILE.json", help="write the report as JSON")
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.add_argument(
        "--adapt",
        action="store_true",
        help="run the suite a second time, the same starts and worlds, with the controller "
        "adapting onboard (docs/design/adaptation.md), and report both",
    )
    p.add_argument(
        "--adapt-expected",
        choices=EXPECTED,
        default=EvaluateRun.adapt_expected,
        help="what an observation is compared with: the recorded outcomes, as the "
        "arbitrator node does (default), or the settled ones (4WS: the motion model's; "
        "legged: whole executions after other primitives, in PyBullet, computed first)",
    )
    add_flag(p, WAIVER)
    p.set_defaults(func=cmd_evaluate)


def cmd_evaluate(args: argparse.Namespace) -> int:
    """Evaluate, print the report, draw the suite."""
    run = from_arguments(EvaluateRun, args)
    done = evaluate_run(run, [WarningPrinter(), EpisodePrinter("evaluate")])
    report, arb = done.report, done.arbitrator
    if args.json:
        print(json.dumps(report, indent=1))
        return 0
    print(
        f"{done.path}: {arb.kind.name} controller for {arb.robot}; {len(report['mazes'])} "
        f"mazes x {run.starts} random starts (seed {run.seed}); perturbations: "
        f"{done.perturbation}"
    )
    _print_table(report["per_maze"], report["overall"])
    if report.get("per_damage"):
        print(f"by damaged part ({report['perturbation']['damage']['kind']}):")
        _print_table(report["per_damage"], None)
    adapted = report.get("adaptation")
    if adapted:
        print(f"with adaptation (expected: {adapted['expected']}):")
        _print_table(adapted["per_maze"], adapted["overall"])
        if adapted.get("per_damage"):
            print(f"with adaptation, by damaged part ({report['perturbation']['damage']['kind']}):")
            _print_table(adapted["per_damage"], None)
        pairs = zip(report["episodes"], adapted["episodes"], strict=True)
        won = lost = 0
        for off, on in pairs:
            won += on["reached"] and not off["reached"]
            lost += off["reached"] and not on["reached"]
        print(f"adaptation: {won} episodes reached only with it, {lost} only without")
    return 0


def _print_table(rows: list[dict], overall: dict | None) -> None:
    print(
        f"{'maze':<14} {'episodes':>8} {'reached':>7} {'reach %':>7} {'95 % interval':>13} "
        f"{'mean fitness':>12} {'stalls':>6} {'collisions':>10} {'falls':>5}"
    )
    for row in [*rows, overall] if overall else rows:
        if row is overall:
            print("-" * 89)
        low, high = (100 * v for v in row["reach_interval"])
        print(
            f"{row['maze']:<14} {row['episodes']:>8} {row['reached']:>7} "
            f"{100 * row['reach_rate']:>7.1f} {f'{low:.0f}-{high:.0f}':>13} "
            f"{row['mean_fitness']:>12.3f} {row['stalls']:>6} {row['collisions']:>10} "
            f"{row['falls']:>5}"
        )
