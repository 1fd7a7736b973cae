"""``evorbc-evolve replay``: run a controller in the mazes and report per maze."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from evorbc_ros.arbitrator import ArbitratorError, ArbitratorFile
from evorbc_ros.defaults import default_repertoire
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.registry import lookup
from offline_evolution.commands.common import (
    CliError,
    EpisodeProgress,
    at_least,
    check_distinct,
    check_outputs,
)
from sim_bridge.cli_options import (
    add_arbitrator,
    add_flag,
    add_repertoire,
    add_seed,
    add_task,
)
from sim_bridge.robots.design import check_simulation, simulation_mismatch

#: How a user lets another repertoire fingerprint or sensor layout through.
WAIVER = "--allow-mismatch"
#: Where an EvoRBC arbitrator's repertoire comes from without --repertoire
#: (:func:`resolve_repertoire`).
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
        default="all",
        metavar="NAME|all",
        help="one maze (name or file) or all of the arbitrator's mazes (default)",
    )
    add_task(p, "the ones recorded in the arbitrator")
    p.add_argument(
        "--start",
        choices=("nominal", "random"),
        default="nominal",
        help="each maze's nominal start pose, or a random one from --seed",
    )
    add_seed(p, "seed of random starts")
    p.add_argument(
        "--episodes",
        type=at_least(1),
        default=1,
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
    add_flag(p, "--allow-mismatch")
    p.set_defaults(func=cmd_replay)


def resolve_repertoire(
    arb: ArbitratorFile, arb_path: Path, given: str | None, allow_mismatch: bool
) -> tuple[Repertoire, str, list[str]]:
    """The repertoire to replay an EvoRBC arbitrator with, its path and any warnings."""
    if given:
        candidates = [Path(given)]
    else:
        named = (arb.repertoire or {}).get("file")
        candidates = [arb_path.with_name(named)] if named else []
        candidates.append(default_repertoire(arb.robot))
        candidates = [c for c in candidates if c.exists()]
        if not candidates:
            raise CliError(f"{arb_path}: cannot find its repertoire; pass --repertoire FILE")
    errors = []
    for path in candidates:
        repertoire = Repertoire.load(path)
        try:
            warnings = arb.check_repertoire(repertoire, str(path), allow_mismatch, WAIVER)
            return repertoire, str(path), warnings
        except ArbitratorError as e:
            errors.append(str(e))
    raise CliError(
        errors[0]
        if given
        else f"{arb_path}: none of {', '.join(map(str, candidates))} is the repertoire "
        "it was evolved with; pass --repertoire FILE"
    )


def controller_inputs(arb: ArbitratorFile, arb_path: Path, args: argparse.Namespace):
    """``(repertoire or None, its path or None, task settings)`` to run ``arb`` with.

    The repertoire as :func:`resolve_repertoire` finds it (``args.repertoire``,
    ``args.allow_mismatch``; warnings go to stderr), the task from ``args.task``, else the
    one the arbitrator records, else the robot's default.
    """
    from offline_evolution.maze_task.base import MazeTaskSettings

    repertoire, rep_path, warnings = None, None, []
    if arb.kind.uses_repertoire:
        repertoire, rep_path, warnings = resolve_repertoire(
            arb, arb_path, args.repertoire, args.allow_mismatch
        )
    for w in warnings:
        print(f"evorbc-evolve: warning: {w}", file=sys.stderr)
    recorded = arb.evolution.get("task")
    if args.task:
        settings = MazeTaskSettings.load(args.task)
    elif recorded:
        settings = MazeTaskSettings.from_dict(recorded, f"{arb_path}: evolution.task")
    else:
        settings = MazeTaskSettings.load(lookup(arb.robot).settings_file("task"))
    return repertoire, rep_path, settings


def check_task(
    task, arb, arb_path: Path, repertoire, rep_path, allow_mismatch: bool, where: str = ""
) -> None:
    """Refuse a task whose simulated robot or sensor layout is not ``arb``'s.

    The robot as :func:`check_design` compares it; the layout unless ``allow_mismatch``.
    ``where`` names the task's file (a refusal then starts with it, and says which
    arbitrator the layout was compared with).
    """
    check_design(task.describe(), arb, arb_path, repertoire, rep_path)
    try:
        arb.check_sensors(task.layout, task.settings.sensors, allow_mismatch, WAIVER)
    except ArbitratorError as e:
        raise CliError(f"{where}: sensors: {e} ({arb_path})" if where else str(e)) from None


def check_design(
    simulation: dict | None,
    arb: ArbitratorFile,
    arb_path: Path,
    repertoire: Repertoire | None,
    rep_path: str | None,
) -> None:
    """Refuse files evolved for another simulated robot than the task's ``simulation``.

    Like ``evorbc-sim``'s check: a repertoire's primitives, or a controller, evolved with
    other servos, legs or physics would be replayed on a robot they were never tried on.
    """
    if repertoire is not None:
        check_simulation(repertoire, simulation, rep_path)
    mismatch = simulation_mismatch(arb.evolution.get("simulation"), simulation, "the arbitrator")
    if mismatch:
        raise CliError(f"{arb_path}: was evolved for a different robot ({mismatch})")


def cmd_replay(args: argparse.Namespace) -> int:
    """Replay and report; optionally draw trajectories and the selection heatmap."""
    from offline_evolution.maze_task.replay import replay, summarise_outcomes
    from offline_evolution.maze_task.task import CONTROL_PERIOD, MazeTaskSettings, make_task
    from offline_evolution.memory import check_replay_memory
    from sim_bridge.robots.base import control_steps

    arb_path = Path(args.arbitrator)
    if args.episodes > 1 and args.start != "random":
        raise CliError("--episodes N needs N >= 1, and N > 1 needs --start random")
    written = {"--plot": args.plot, "--heatmap": args.heatmap}
    check_outputs(written)
    check_distinct(written)
    arb = ArbitratorFile.load(arb_path)
    if args.heatmap and not arb.kind.uses_repertoire:
        raise CliError("--heatmap needs an EvoRBC arbitrator (standard NEAT has no primitives)")
    repertoire, rep_path, settings = controller_inputs(arb, arb_path, args)
    recorded = arb.evolution.get("task")
    if args.maze != "all":
        settings = MazeTaskSettings((args.maze,), settings.episode_time, 1, settings.sensors)
    where = args.task or (f"{arb_path}: evolution.task" if recorded else "the default task")
    per_maze = args.episodes * settings.samples_per_maze if args.start == "random" else 1
    check_replay_memory(
        len(settings.mazes) * per_maze,
        control_steps(settings.episode_time, CONTROL_PERIOD),
        len(arb.network.output_keys),
        arb.robot,
        f"episode_time {settings.episode_time} s in {where}",
    )
    task = make_task(settings, arb.robot)
    try:
        check_task(task, arb, arb_path, repertoire, rep_path, args.allow_mismatch, where)
        if args.start == "random":
            rng = np.random.default_rng(args.seed)
            starts = np.concatenate([task.sample_starts(rng) for _ in range(args.episodes)])
            # maze-major, so each maze's episodes are together in the report
            starts = starts[np.argsort(starts[:, 0], kind="stable")]
        else:
            starts = task.nominal_starts()
        task.progress = EpisodeProgress("replay")  # many PyBullet episodes take minutes
        outcomes, result = replay(arb, task, starts, repertoire)
    finally:
        task.close()
    for o in outcomes:
        if o.stopped_cycles:
            print(
                f"evorbc-evolve: warning: {o.maze}: the network's outputs were not finite in "
                f"{o.stopped_cycles} of {round(o.time / task.dt)} cycles; the robot stood still "
                "in those (no primitive)",
                file=sys.stderr,
            )
    mean = float(np.mean([o.fitness for o in outcomes]))
    reached = sum(o.reached for o in outcomes)
    summary = summarise_outcomes(outcomes)
    if args.json:
        print(
            json.dumps(
                {
                    "arbitrator": str(arb_path),
                    "kind": arb.kind.name,
                    "robot": arb.robot,
                    "repertoire": rep_path,
                    "start": args.start,
                    "mazes": [o.as_dict() for o in outcomes],
                    "mean_fitness": mean,
                    "reached": reached,
                    "per_maze": summary,
                },
                indent=1,
            )
        )
    else:
        print(
            f"{arb_path}: {arb.kind.name} controller for {arb.robot}"
            + (
                f", {arb.mapping} mapping over {rep_path} ({len(repertoire)} primitives)"
                if repertoire
                else ""
            )
        )
        if args.episodes == 1:
            _print_episodes(outcomes)
            print(f"mean fitness {mean:.3f}, target reached in {reached} of {len(outcomes)} mazes")
        else:
            _print_summary(summary)
            print(
                f"mean fitness {mean:.3f}, target reached in {reached} of {len(outcomes)} "
                f"episodes ({args.episodes} random starts per maze, seed {args.seed})"
            )
    if args.plot:
        from offline_evolution.plots.replay import plot_trajectories

        plot_trajectories(task, outcomes, result, args.plot, title=arb_path.name)
    if args.heatmap:
        from offline_evolution.plots.selection import plot_selection

        plot_selection(repertoire, arb.mapping, result, args.heatmap, title=arb_path.name)
    return 0


def _print_episodes(outcomes) -> None:
    """One line per episode: reached, time and fitness."""
    print(f"{'maze':<12} {'reached':>7} {'time (s)':>9} {'fitness':>8}")
    for o in outcomes:
        status = "yes" if o.reached else ("fell" if o.fell else "no")
        print(f"{o.maze:<12} {status:>7} {o.time:>9.1f} {o.fitness:>8.3f}")


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
