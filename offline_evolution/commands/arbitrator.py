"""``evorbc-evolve arbitrator`` (EvoRBC) and ``standard`` (the standard-NEAT baseline)."""

from __future__ import annotations

import argparse

from evorbc_ros.controller_kinds import EVORBC, STANDARD
from offline_evolution import bounds
from offline_evolution.commands.common import add_resume_options, add_workers_option
from offline_evolution.runs import terminal
from offline_evolution.runs.arbitrator import CHECKPOINT_SUFFIX, ArbitratorRun
from offline_evolution.runs.command_line import from_arguments
from sim_bridge.cli_options import add_repertoire, add_robot, add_seed, add_task
from sim_bridge.cli_support import integer_in


def _common_options(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--generations",
        type=integer_in(1, bounds.GENERATIONS),
        metavar="N",
        help="NEAT generations (default: the robot's run settings, Table I)",
    )
    p.add_argument(
        "--population",
        type=integer_in(2, bounds.POP_SIZE),
        metavar="N",
        help="NEAT population, in place of the NEAT file's pop_size (its species and "
        "elitism settings must fit it)",
    )
    p.add_argument(
        "--hall-of-fame",
        type=integer_in(1, bounds.POP_SIZE),
        metavar="N",
        help="genomes kept for the post-selection, the N best by training fitness, the last "
        "N generations' champions and up to N seen reaching from every nominal start "
        "(default: the run settings'; fewer candidates are quicker)",
    )
    p.add_argument(
        "--post-samples",
        type=integer_in(1, bounds.MAZES),
        metavar="N",
        help="random starts per maze of each hall-of-fame genome in the post-selection "
        "(default: the run settings'; fewer is quicker, less sure)",
    )
    add_seed(p, "random seed")
    p.add_argument("--out", required=True, metavar="FILE", help="arbitrator file to write (JSON)")
    p.add_argument(
        "--config",
        metavar="FILE.yaml",
        help="run settings (default: the robot's, e.g. config/arbitrator/4ws.yaml)",
    )
    p.add_argument("--neat-config", metavar="FILE.ini", help="NEAT settings (neat-python format)")
    add_task(p, "the one the run settings name")
    p.add_argument(
        "--episode-time",
        type=float,
        metavar="S",
        help="s, each training and post-selection episode's length, in place of the task's "
        "episode_time (recorded with the controller, as evaluate reads it)",
    )
    p.add_argument(
        "--plot", metavar="FILE.png", help="fitness-curve picture (default: OUT with .fitness.png)"
    )
    add_resume_options(p, CHECKPOINT_SUFFIX, "generations")
    p.add_argument(
        "--keep-checkpoint",
        action="store_true",
        help="keep the finished run's checkpoint, so that the same command with a larger "
        "--generations continues it (e.g. look at 300 generations, then go on to 1000)",
    )
    p.add_argument(
        "--quiet", action="store_true", help="no per-generation lines (a resume is still said)"
    )
    p.add_argument(
        "--init-from",
        metavar="FILE.json",
        help="start from this arbitrator file's network (and mutated copies of it) instead "
        "of random networks: carry a controller on to another task (its inputs are matched "
        "by name; docs/design.md section 8)",
    )
    add_workers_option(p)


def add_parsers(sub) -> None:
    """Register ``arbitrator`` and ``standard``."""
    from evorbc_ros.mapping import MAPPINGS

    arb = sub.add_parser(
        EVORBC.command,
        help="evolve an EvoRBC arbitrator for a repertoire (NEAT)",
        description="Evolve an arbitrator network with NEAT that maps sensor readings to a "
        "point of the repertoire's behaviour space (paper Sec. III-C).",
    )
    add_repertoire(arb)
    arb.add_argument("--mapping", choices=MAPPINGS, help="mapping function (default: polar)")
    _common_options(arb)
    arb.set_defaults(func=cmd_evolve, kind=EVORBC)

    std = sub.add_parser(
        STANDARD.command,
        help="evolve a standard-NEAT controller (the baseline)",
        description="Evolve a network whose outputs are the robot's locomotion parameters, "
        "applied every control cycle (paper Sec. IV-D).",
    )
    add_robot(std, "robot type", required=True)
    std.add_argument(
        "--equal-budget",
        action="store_true",
        help="add the generations that match EvoRBC's repertoire budget (the robot's: +25 "
        "for the 4WS robots, +455 for the hexapod)",
    )
    _common_options(std)
    std.set_defaults(func=cmd_evolve, kind=STANDARD)


def cmd_evolve(args: argparse.Namespace) -> int:
    """Evolve an arbitrator or a standard-NEAT controller and write its file and curve."""
    run = from_arguments(ArbitratorRun, args)
    return terminal.arbitrator(run, args.workers, args.quiet)
