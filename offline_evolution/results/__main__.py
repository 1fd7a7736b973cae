"""``python -m offline_evolution.results``: the docs' tables and curves from docs/results/.

docs/results/README.md lists which command makes which table or figure.

    extract RAW --out DIR [--controller RUN ...]   raw docs/runs files -> the tables
    screening                                      the table "Training on generated mazes"
    reports REPORT ...                             one line per evaluation report
    kinds MAZES.json REPORT ...                    reach by target mode and obstacle kind
    curve RUN --out FILE.png                       a run's fitness curve
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from offline_evolution.results.tables import TableError

DEFAULT = Path("docs/results")


def parser() -> argparse.ArgumentParser:
    """The command line: one sub-command per regenerated table or figure."""
    p = argparse.ArgumentParser(
        prog="python -m offline_evolution.results",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--results", type=Path, default=DEFAULT, help="the tables' folder")
    sub = p.add_subparsers(dest="command", required=True)
    e = sub.add_parser("extract", help="write the tables of a raw docs/runs folder")
    e.add_argument("raw", type=Path)
    e.add_argument("--out", type=Path, default=DEFAULT)
    e.add_argument(
        "--controller",
        action="append",
        default=[],
        metavar="RUN",
        help="keep this run's controller (no history) under OUT/controllers/",
    )
    s = sub.add_parser("screening", help="the screening table of docs/generalisation.md")
    s.add_argument("--prefix", default="generalise/")
    r = sub.add_parser("reports", help="one line per evaluation report")
    r.add_argument("report", nargs="+")
    k = sub.add_parser("kinds", help="reach by target mode and obstacle kind")
    k.add_argument("mazes", type=Path, help="`evorbc-evolve mazes --json` of the mazes")
    k.add_argument("report", nargs="+")
    c = sub.add_parser("curve", help="a run's fitness curve")
    c.add_argument("run")
    c.add_argument("--out", type=Path, required=True)
    return p


def run(args: argparse.Namespace) -> str:
    """Do the sub-command; the text to print."""
    from offline_evolution.results import curves, extract, summaries

    if args.command == "extract":
        if not args.raw.is_dir():
            raise TableError(f"{args.raw}: expected a folder of raw run files")
        try:
            counts = extract.extract(args.raw, args.out, args.controller)
        except KeyError as e:
            raise TableError(e.args[0]) from None
        return "".join(f"{rows:7d} rows  {args.out / name}\n" for name, rows in counts.items())
    if args.command == "screening":
        return summaries.screening_table(args.results, args.prefix)
    if args.command == "reports":
        return summaries.report_lines(args.results, args.report)
    if args.command == "kinds":
        return summaries.kinds_table(args.results, args.mazes, args.report)
    curves.plot_run(args.results, args.run, args.out)
    return f"wrote {args.out}\n"


def main(argv: list[str] | None = None) -> None:
    """Entry point: bad input is one line on stderr and exit status 2."""
    args = parser().parse_args(argv)
    try:
        sys.stdout.write(run(args))
    except TableError as e:
        sys.exit(f"offline_evolution.results: {e}")


if __name__ == "__main__":
    main()
