"""``evorbc-evolve evaluate``: a controller on a suite of mazes, from many starts, perturbed."""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.atomic_io import atomic_write_text
from evorbc_ros.config import ConfigError
from evorbc_ros.defaults import (
    PAPER_WITH_FILE,
    default_arbitrator,
    no_shipped_controller,
    paper_arbitrator,
    ships_controller,
)
from evorbc_ros.robots.registry import DEFAULT_ROBOT
from offline_evolution import bounds
from offline_evolution.commands.common import (
    CliError,
    EpisodeProgress,
    at_least,
    check_distinct,
    check_outputs,
    count,
    exclusive_outputs,
)
from offline_evolution.commands.replay import REPERTOIRE_DEFAULT, check_task, controller_inputs
from offline_evolution.mazes.held_out import HELD_OUT_SEED  # never trained on
from sim_bridge.cli_options import (
    add_arbitrator,
    add_flag,
    add_repertoire,
    add_robot,
    add_seed,
    add_task,
)
from sim_bridge.cli_support import integer_in

#: The suite word for the mazes the controller was trained on (its task's mazes).
PAPER = "paper"


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
        default=HELD_OUT_SEED,
        metavar="N",
        help=f"seed of the generated mazes (default {HELD_OUT_SEED}: the held-out set, never "
        "used for training)",
    )
    p.add_argument("--starts", type=at_least(1), default=20, metavar="N", help="per maze (20)")
    add_seed(p, "starts and worlds")
    p.add_argument(
        "--perturb",
        default="none",
        metavar="none|realistic|FILE.yaml",
        help="perturbation set: a shipped one (config/perturbations/) or a file",
    )
    add_task(p, "the arbitrator's; its episode time and sensors")
    p.add_argument("--plot", metavar="FILE.png", help="picture of the suite with every path")
    p.add_argument("--out", metavar="FILE.json", help="write the report as JSON")
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    add_flag(p, "--allow-mismatch")
    p.set_defaults(func=cmd_evaluate)


def suite_mazes(given: list[str] | None, trained: tuple[str, ...], generated: bool) -> list[str]:
    """Maze names and files of the suite, in order; folders give their ``*.yaml`` sorted."""
    if not given:
        return [] if generated else list(trained)
    out = []
    for item in given:
        if item == PAPER:
            out += trained
        elif Path(item).is_dir():
            files = sorted(str(f) for f in Path(item).glob("*.yaml"))
            if not files:
                raise CliError(f"--mazes {item}: the folder holds no .yaml maze files")
            out += files
        else:
            out.append(item)
    return out


def load_arbitrator(args) -> tuple[ArbitratorFile, Path]:
    """The arbitrator to evaluate and its path."""
    if args.arbitrator and args.paper:
        raise CliError(PAPER_WITH_FILE)
    if args.arbitrator:
        path = Path(args.arbitrator)
    else:
        if not ships_controller(args.robot):
            raise CliError(f"{no_shipped_controller(args.robot)}; pass --arbitrator FILE")
        path = (paper_arbitrator if args.paper else default_arbitrator)(args.robot)
    return ArbitratorFile.load(path), path


def cmd_evaluate(args: argparse.Namespace) -> int:
    """Evaluate, print the report, draw the suite."""
    written = {"--plot": args.plot, "--out": args.out}
    check_outputs(written)
    check_distinct(written)
    with exclusive_outputs(written):
        return _evaluate(args)


def _evaluate(args: argparse.Namespace) -> int:
    """:func:`cmd_evaluate` once its outputs are checked and locked."""
    from offline_evolution.maze_task.base import MazeTaskSettings
    from offline_evolution.maze_task.evaluation import evaluate_suite
    from offline_evolution.maze_task.perturbation import load_perturbations
    from offline_evolution.maze_task.task import CONTROL_PERIOD, make_task
    from offline_evolution.memory import check_replay_memory
    from sim_bridge.robots.base import control_steps

    perturbation = load_perturbations(args.perturb)
    arb, arb_path = load_arbitrator(args)
    repertoire, rep_path, base = controller_inputs(arb, arb_path, args)
    with tempfile.TemporaryDirectory(prefix="evorbc-suite-") as tmp:
        names = suite_mazes(args.mazes, base.mazes, bool(args.generated))
        # Checked before the mazes are generated, which takes about 0.1 s each.
        check_replay_memory(
            (len(names) + (args.generated or 0)) * args.starts,
            control_steps(base.episode_time, CONTROL_PERIOD),
            len(arb.network.output_keys),
            arb.robot,
            f"episode_time {base.episode_time} s; --starts {args.starts}",
        )
        if args.generated:
            names += _generated_files(arb.robot, args.generated, args.generated_seed, Path(tmp))
        settings = MazeTaskSettings(tuple(names), base.episode_time, 1, base.sensors)
        try:
            task = make_task(settings, arb.robot)
        except ConfigError as e:
            raise CliError(f"--mazes: {e}") from None
    try:
        check_task(task, arb, arb_path, repertoire, rep_path, args.allow_mismatch)
        controller = task.controller(arb.kind, repertoire, arb.mapping)
        task.progress = EpisodeProgress("evaluate")  # PyBullet suites take minutes
        try:
            suite = evaluate_suite(
                task, arb.network, controller, args.starts, args.seed, perturbation
            )
        except ValueError as e:
            raise CliError(f"--perturb {args.perturb}: {e}") from None
    finally:
        task.close()
    if suite.not_applicable:
        print(
            f"evorbc-evolve: warning: --perturb {perturbation.name}: {arb.robot}'s simulation "
            f"cannot model {', '.join(suite.not_applicable)}; applied: "
            f"{', '.join(suite.applied) or 'nothing'}",
            file=sys.stderr,
        )
    report = {
        "arbitrator": str(arb_path),
        "kind": arb.kind.name,
        "robot": arb.robot,
        "repertoire": rep_path,
        "mazes": [m.name for m in task.mazes],
        # Each maze's factor when one was scaled up to fit the robot (docs/design.md s. 21).
        **({"maze_scale": list(task.settings.maze_scale)} if task.settings.maze_scale else {}),
        "generated": (
            {"count": args.generated, "seed": args.generated_seed} if args.generated else None
        ),
        "starts_per_maze": args.starts,
        "seed": args.seed,
        "episode_time": settings.episode_time,
        "perturbation": perturbation.as_dict(),
        "applied": list(suite.applied),
        "not_applicable": list(suite.not_applicable),
        "per_maze": suite.per_maze(),
        "overall": suite.overall(),
        "episodes": [e.as_dict() for e in suite.episodes],
    }
    if args.out:
        atomic_write_text(args.out, json.dumps(report, indent=1) + "\n")
    if args.json:
        print(json.dumps(report, indent=1))
    else:
        print(
            f"{arb_path}: {arb.kind.name} controller for {arb.robot}; {len(task.mazes)} mazes x "
            f"{args.starts} random starts (seed {args.seed}); perturbations: {perturbation.name}"
        )
        _print_table(report["per_maze"], report["overall"])
    if args.plot:
        _plot(task, suite, args.plot, f"{arb_path.name}, perturbations: {perturbation.name}")
    return 0


def _generated_files(robot: str, n: int, seed: int, folder: Path) -> list[str]:
    """Generate ``n`` mazes of ``seed`` for ``robot`` into ``folder``; their files."""
    from offline_evolution.mazes.files import save_maze
    from offline_evolution.mazes.generator import generate_maze, spec_for_robot

    spec = spec_for_robot(robot)
    files = []
    for k in range(n):
        maze = generate_maze(spec, seed, k).maze
        path = folder / f"{maze.name}.yaml"
        save_maze(maze, path)
        files.append(str(path))
    return files


def _print_table(rows: list[dict], overall: dict) -> None:
    print(
        f"{'maze':<14} {'episodes':>8} {'reached':>7} {'reach %':>7} {'95 % interval':>13} "
        f"{'mean fitness':>12} {'stalls':>6} {'collisions':>10} {'falls':>5}"
    )
    for row in [*rows, overall]:
        if row is overall:
            print("-" * 89)
        low, high = (100 * v for v in row["reach_interval"])
        print(
            f"{row['maze']:<14} {row['episodes']:>8} {row['reached']:>7} "
            f"{100 * row['reach_rate']:>7.1f} {f'{low:.0f}-{high:.0f}':>13} "
            f"{row['mean_fitness']:>12.3f} {row['stalls']:>6} {row['collisions']:>10} "
            f"{row['falls']:>5}"
        )


def _plot(task, suite, path: str, title: str) -> None:
    from offline_evolution.plots.suite import plot_suite

    names = [m.name for m in task.mazes]
    paths = [
        [p for p, e in zip(suite.paths, suite.episodes, strict=True) if e.maze == n] for n in names
    ]
    reached = [[e.reached for e in suite.episodes if e.maze == n] for n in names]
    rows = {r["maze"]: r for r in suite.per_maze()}
    titles = [f"{n}: {rows[n]['reached']}/{rows[n]['episodes']} reached" for n in names]
    plot_suite(task.mazes, path, titles=titles, paths=paths, reached=reached, title=title)
