"""``evorbc-evolve replay``: run a controller in the mazes and report per maze."""

from __future__ import annotations

import argparse
import json

from offline_evolution.commands.common import at_least
from offline_evolution.runs.command_line import from_arguments
from offline_evolution.runs.console import EpisodePrinter, WarningPrinter
from offline_evolution.runs.replay import WAIVER, ReplayRun, replay_run
from sim_bridge.cli_options import (
    add_arbitrator,
    add_flag,
    add_repertoire,
    add_seed,
    add_task,
)
from sim_bridge.verdict import episode_line

#: Where an EvoRBC arbitrator's repertoire comes from without --repertoire
#: (:func:`offline_evolution.runs.replay.resolve_repertoire`).
REPERTOIRE_DEFAULT = "the file it names, next to it, or the shipped one"


def add_parsers(sub) -> None:
    """Register ``replay``."""
    p = sub.add_parser(
        "replay",
        help="run a controller in the mazes and report, per maze, reached or not, time and fitness",
        description="Replay an arbitrator (or a standard-NEAT controller) in the mazes it was "
        "evolved for.",
    )
    add_arbitrator(p)
    add_repertoire(p, REPERTOIRE_DEFAULT)
    p.add_argument(
        "--maze",
        default=ReplayRun.maze,
        metavar="NAME|all",
        help="one maze (name or file) or all of the arbitrator's mazes (default)",
    )
    add_task(p, "the ones recorded in the arbitrator")
    p.add_argument(
        "--start",
        choices=("nominal", "random"),
        default=ReplayRun.start,
        help="each maze's nominal start pose, or a random one from --seed",
    )
    add_seed(p, "seed of random starts")
    p.add_argument(
        "--episodes",
        type=at_least(1),
        default=ReplayRun.episodes,
        metavar="N",
        help="with --start random: N random starts per maze, reported per maze as how "
        "many reached the target or fell and the mean fitness (how robust the controller is)",
    )
    p.add_argument("--plot", metavar="FILE.png", help="draw the trajectories")
    p.add_argument(
        "--heatmap",
        metavar="FILE.png",
        help="draw which repertoire cells were used (EvoRBC, paper Fig. 14)",
    )
    p.add_argument("--json", action="store_true", help="print the results as JSON")
    add_flag(p, WAIVER)
    p.set_defaults(func=cmd_replay)


def cmd_replay(args: argparse.Namespace) -> int:
    """Replay and report; optionally draw trajectories and the selection heatmap."""
    from offline_evolution.maze_task.replay import summarise_outcomes

    run = from_arguments(ReplayRun, args)
    done = replay_run(run, [WarningPrinter(), EpisodePrinter("replay")])
    arb, outcomes, n = done.arbitrator, done.outcomes, len(done.outcomes)
    summary = summarise_outcomes(outcomes)
    if args.json:
        print(json.dumps(_as_json(done, run, summary), indent=1))
        return 0
    print(
        f"{done.path}: {arb.kind.name} controller for {arb.robot}"
        + (
            f", {arb.mapping} mapping over {done.repertoire_path} "
            f"({len(done.repertoire)} primitives)"
            if done.repertoire
            else ""
        )
    )
    head = f"mean fitness {done.mean_fitness:.3f}, target reached in {done.reached} of {n}"
    if run.episodes == 1:
        _print_episodes(outcomes)
        print(f"{head} mazes")
    else:
        _print_summary(summary)
        print(f"{head} episodes ({run.episodes} random starts per maze, seed {run.seed})")
    return 0


def _as_json(done, run, summary: list[dict]) -> dict:
    """The ``--json`` report."""
    return {
        "arbitrator": str(done.path),
        "kind": done.arbitrator.kind.name,
        "robot": done.arbitrator.robot,
        "repertoire": done.repertoire_path,
        "start": run.start,
        "mazes": [o.as_dict() for o in done.outcomes],
        "mean_fitness": done.mean_fitness,
        "reached": done.reached,
        "per_maze": summary,
    }


def _print_episodes(outcomes) -> None:
    """One line per episode, as ``evorbc-sim`` says it: reached, fell or missed, and when."""
    for o in outcomes:
        print(episode_line(o.maze, o.as_dict()))


def _print_summary(summary: list[dict]) -> None:
    """One line per maze over its episodes."""
    print(
        f"{'maze':<12} {'episodes':>8} {'reached':>7} {'fell':>5} {'mean fitness':>12} "
        f"{'mean time reached (s)':>21}"
    )
    for row in summary:
        t = row["mean_time_reached"]
        print(
            f"{row['maze']:<12} {row['episodes']:>8} {row['reached']:>7} {row['fell']:>5} "
            f"{row['mean_fitness']:>12.3f} {'-' if t is None else f'{t:.1f}':>21}"
        )
