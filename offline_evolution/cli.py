"""``evorbc-evolve``: the offline evolution command line.

Subcommands:
    repertoire   generate a MAP-Elites repertoire of locomotion primitives
    export-csv   convert a repertoire file to CSV
    settled      a 4WS or legged repertoire's settled outcomes, for the node's adaptation
    arbitrator   evolve an EvoRBC arbitrator (NEAT) for a repertoire
    standard     evolve a standard-NEAT controller (the baseline)
    replay       run a controller in the mazes and report
    mazes        generate seeded, proven-solvable mazes for a robot
    evaluate     run a controller on a suite of mazes from many starts, perturbed or not
    recipe       make a shipped controller from its recipe (config/recipes/*.yaml)
    robot-from-urdf  a legged robot's settings files read from its URDF
    design-gait  a legged robot's gait design (gain, ranges, frequency, physics rate) by search

Bad arguments or files end the program with a one-line message and a non-zero status,
never a traceback (set ``EVORBC_DEBUG=1`` to see one for an unexpected failure).
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from offline_evolution.commands import (
    arbitrator,
    design_gait,
    evaluate,
    mazes,
    recipe,
    repertoire,
    replay,
    robot_from_urdf,
    settled,
)
from offline_evolution.runs.frame import one_line_errors
from sim_bridge.cli_support import OneLineParser
from sim_bridge.cluster_pool import CLUSTER_VARIABLE


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``evorbc-evolve``."""
    parser = OneLineParser(
        prog="evorbc-evolve",
        description="Offline evolution for EvoRBC: repertoires of locomotion primitives "
        "(MAP-Elites) and arbitrators (NEAT).",
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    repertoire.add_parsers(sub)
    settled.add_parsers(sub)
    arbitrator.add_parsers(sub)
    replay.add_parsers(sub)
    mazes.add_parsers(sub)
    evaluate.add_parsers(sub)
    recipe.add_parsers(sub)
    robot_from_urdf.add_parsers(sub)
    design_gait.add_parsers(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``evorbc-evolve``; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if getattr(args, "cluster", None):
        # The evaluation pools read it when they first spread work (sim_bridge/cluster_pool).
        os.environ[CLUSTER_VARIABLE] = args.cluster
    return one_line_errors("evorbc-evolve", lambda: args.func(args))


if __name__ == "__main__":
    sys.exit(main())
