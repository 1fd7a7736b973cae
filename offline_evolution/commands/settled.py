"""``evorbc-evolve settled``: a repertoire's settled outcomes, for the onboard node.

Onboard adaptation compares observations with what each primitive does once its actuators
hold its command, or for a legged robot what a whole execution after other primitives does
(docs/design/adaptation.md, "What an observation is compared with"). Only the robot's
simulation can compute that, and the arbitrator node must not import it, so
this command computes the outcomes offline, exactly as ``evaluate --adapt-expected
settled`` does, and writes them beside the repertoire for the node to read
(:mod:`offline_evolution.runs.settled`, :mod:`evorbc_ros.adaptation.settled`).
"""

from __future__ import annotations

import argparse

from evorbc_ros.adaptation.settled import settled_path
from offline_evolution.runs.outputs import check_distinct
from offline_evolution.runs.settled import write_settled
from sim_bridge.cli_support import check_output_file


def add_parsers(sub) -> None:
    """Register ``settled``."""
    p = sub.add_parser(
        "settled",
        help="a 4WS or legged repertoire's settled outcomes, for the arbitrator node's adaptation",
        description="Compute what each primitive of a 4WS repertoire does once its actuators "
        "hold its command, or of a legged repertoire what a whole execution after other "
        "primitives observes (PyBullet, seeded; about half a minute for the shipped "
        "hexapod's), the outcomes evaluate --adapt-expected settled compares "
        "observations with, and write them for the arbitrator node's adaptation_expected "
        "settled (docs/design/adaptation.md).",
    )
    p.add_argument("repertoire", metavar="REPERTOIRE", help="repertoire file (JSON)")
    p.add_argument(
        "--out",
        metavar="FILE",
        help="settled-outcomes file (default: beside REPERTOIRE, NAME.settled.json, where the "
        "arbitrator node looks for it)",
    )
    p.set_defaults(func=cmd_settled)


def cmd_settled(args: argparse.Namespace) -> int:
    """Compute and write the settled outcomes of ``args.repertoire``."""
    if args.out is not None:
        out_option, out = "--out", args.out
    else:
        out_option, out = "the default --out", str(settled_path(args.repertoire))
    check_output_file(out, out_option)
    check_distinct({"REPERTOIRE": args.repertoire, out_option: out})
    repertoire = write_settled(args.repertoire, out)
    print(f"{len(repertoire)} settled outcomes of {repertoire.robot} -> {out}")
    return 0
