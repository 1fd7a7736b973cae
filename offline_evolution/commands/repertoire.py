"""``evorbc-evolve repertoire`` and ``export-csv``."""

from __future__ import annotations

import argparse
from pathlib import Path

from evorbc_ros.repertoire import Repertoire
from offline_evolution.commands.common import (
    add_resume_options,
    add_workers_option,
    count,
    positive_float,
)
from offline_evolution.runs import terminal
from offline_evolution.runs.command_line import from_arguments
from offline_evolution.runs.outputs import check_distinct
from offline_evolution.runs.repertoire import CHECKPOINT_EVERY, CHECKPOINT_SUFFIX, RepertoireRun
from sim_bridge.cli_options import add_robot
from sim_bridge.cli_support import check_output_file


def add_parsers(sub) -> None:
    """Register ``repertoire`` and ``export-csv``."""
    from offline_evolution.quality import METRICS
    from offline_evolution.repertoire.settings import ARCHIVES, VARIATIONS

    rep = sub.add_parser(
        "repertoire",
        help="generate a MAP-Elites repertoire of locomotion primitives",
        description="Generate a repertoire with batch MAP-Elites (paper Algorithm 1). "
        "Settings come from the robot's settings file (config/repertoire/4ws.yaml or "
        "hexapod.yaml: paper Table I) or --config; options given here override them.",
    )
    add_robot(rep, "robot type (default: from config)")
    rep.add_argument("--metric", choices=tuple(METRICS), help="quality metric")
    rep.add_argument(
        "--bin-size",
        type=positive_float,
        metavar="M",
        help="side of a square archive cell in metres",
    )
    rep.add_argument(
        "--eval-time",
        type=positive_float,
        metavar="S",
        help="primitive evaluation time T in seconds",
    )
    rep.add_argument(
        "--initial-batch", type=count, metavar="N", help="random solutions in the first batch (S_G)"
    )
    rep.add_argument("--batch-size", type=count, metavar="N", help="mutants per iteration (S_B)")
    rep.add_argument(
        "--iterations", type=count, metavar="N", help="iterations after the initial batch (I)"
    )
    rep.add_argument("--seed", type=count, metavar="N", help="random seed")
    rep.add_argument(
        "--archive", choices=ARCHIVES, help="grid (the paper's) or cvt (Voronoi cells)"
    )
    rep.add_argument(
        "--variation",
        choices=VARIATIONS,
        help="paper (Gaussian mutation) or iso_line_dd (Iso+LineDD of two elites)",
    )
    rep.add_argument("--config", metavar="FILE.yaml", help="settings file (YAML)")
    rep.add_argument("--out", required=True, metavar="FILE", help="repertoire file to write (JSON)")
    rep.add_argument("--plot", metavar="FILE.png", help="also draw the repertoire (Fig. 8 style)")
    rep.add_argument("--csv", metavar="FILE.csv", help="also export the primitives as CSV")
    add_resume_options(rep, CHECKPOINT_SUFFIX, "iterations", every=CHECKPOINT_EVERY)
    rep.add_argument("--quiet", action="store_true", help="no progress lines")
    add_workers_option(rep)
    rep.set_defaults(func=cmd_repertoire)

    csv = sub.add_parser("export-csv", help="convert a repertoire file to CSV")
    csv.add_argument("repertoire", metavar="REPERTOIRE", help="repertoire file (JSON)")
    csv.add_argument("--out", metavar="FILE.csv", help="CSV file (default: next to the input)")
    csv.set_defaults(func=cmd_export_csv)


def cmd_repertoire(args: argparse.Namespace) -> int:
    """Generate a repertoire, write it (and optionally a plot and CSV), print a summary."""
    run = from_arguments(RepertoireRun, args)
    return terminal.repertoire(run, args.workers, args.quiet)


def cmd_export_csv(args: argparse.Namespace) -> int:
    """Convert a repertoire file to CSV."""
    repertoire = Repertoire.load(args.repertoire)
    if args.out is not None:
        out_option, out = "--out", args.out
    else:
        out_option, out = "the default --out", str(Path(args.repertoire).with_suffix(".csv"))
    check_output_file(out, out_option)
    check_distinct({"REPERTOIRE": args.repertoire, out_option: out})
    repertoire.to_csv(out)
    print(f"{len(repertoire)} primitives -> {out}")
    return 0
