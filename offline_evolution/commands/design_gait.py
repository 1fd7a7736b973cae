"""``evorbc-evolve design-gait``: a legged robot's gait design found by search."""

from __future__ import annotations

import argparse
from pathlib import Path

from offline_evolution.commands.common import add_resume_options, count

HELP = (
    "search a legged robot's servo gain, joint ranges, gait frequency and physics "
    "rate; write the chosen design into a settings file"
)
DESCRIPTION = (
    "Score designs of a legged robot's gait (servo gain, joint ranges, gait "
    "frequency, physics rate) by the share of random gaits upright, the survival of a "
    "maze episode when gaits switch every 0.1 s (half the time against the maze's walls), "
    "the endpoint error against 1 kHz physics, the speed against what the robot's mazes "
    "need and the cost per evaluation; search them (Sobol, then local refinement, then the "
    "best measured again) and write the chosen one into OUT with a design_search "
    "record (docs/legged.md, 'The gait design search')."
)


def add_parsers(sub) -> None:
    """Register ``design-gait``."""
    p = sub.add_parser("design-gait", help=HELP, description=DESCRIPTION)
    p.add_argument("settings", metavar="SETTINGS", help="the robot's settings file (.yaml)")
    p.add_argument(
        "--out", required=True, metavar="FILE", help="the settings file to write (may be SETTINGS)"
    )
    p.add_argument("--seed", type=count, default=1, help="seed of the search (default 1)")
    p.add_argument(
        "--budget",
        choices=("quick", "full"),
        default="quick",
        help="quick: about 10 min on one core for the A1, then a trial repertoire for each of "
        "4 validated designs (1-3 min each on 2 cores); full: more primitives, episodes and "
        "designs (default quick)",
    )
    add_resume_options(p, ".checkpoint.json (removed once OUT is written)", "designs", 1)
    p.set_defaults(func=cmd_design_gait)


def cmd_design_gait(args: argparse.Namespace) -> int:
    """Run the search; print one line per design scored."""
    from offline_evolution.gait_design.objective import BUDGETS
    from offline_evolution.gait_design.run import design_gait
    from offline_evolution.runs.errors import UserError
    from offline_evolution.runs.frame import StopOnSignal, explained, listening

    out = Path(args.out)
    if out.is_dir():
        raise UserError(f"--out {out}: a folder; expected a settings file to write")
    if not out.parent.is_dir():
        raise UserError(f"--out {out}: no folder {out.parent}")
    stop = StopOnSignal("design")
    with explained("design"), listening(stop):
        design_gait(
            Path(args.settings),
            out,
            args.seed,
            args.budget,
            BUDGETS[args.budget],
            Path(args.checkpoint) if args.checkpoint else None,
            args.restart,
            args.checkpoint_every,
            lambda line: print(line, flush=True),
            stop,
        )
    return 0
