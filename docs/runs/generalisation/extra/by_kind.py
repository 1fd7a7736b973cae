"""Summaries and tables for docs/runs/generalisation/extra/make.sh (see its header).

by_kind.py summarise < FULL.json > SUMMARY.json
An `evorbc-evolve evaluate --json` report without its episodes, as
docs/runs/generalise/summary.py keeps it, plus one count read from the episodes
before they are dropped: "failed_stalled" (episodes that did not reach the target
and stalled), in each per_maze row and in overall.

by_kind.py runs SUMMARY.json ...
One line per run: episodes, reached, reach %, stalls, failures that stall, mean
fitness.

by_kind.py kinds MAZES.json SUMMARY.json ... [--json OUT.json]
Each run's reach % by where the maze's target is (target_mode: wall, open, behind,
anywhere) and by obstacle kind (the mazes holding at least one obstacle of that
kind), from the run's per_maze rows and MAZES.json (`evorbc-evolve mazes --json`,
which records each generated maze's kinds and target_mode).
"""

import json
import sys
from pathlib import Path

MODES = ("wall", "behind", "anywhere", "open")
KINDS = ("baffle", "gap", "diagonal", "posts", "block", "dead_end", "chamber")


def summarise() -> None:
    """Read a full evaluate report on stdin; print its summary (see the module docstring)."""
    report = json.load(sys.stdin)
    episodes = report.pop("episodes")
    failed_stalled: dict[str, int] = {}
    for ep in episodes:
        if ep["stalled"] and not ep["reached"]:
            failed_stalled[ep["maze"]] = failed_stalled.get(ep["maze"], 0) + 1
    for row in report["per_maze"]:
        row["failed_stalled"] = failed_stalled.get(row["maze"], 0)
    report["overall"]["failed_stalled"] = sum(failed_stalled.values())
    json.dump(report, sys.stdout, indent=1)
    print()


def _label(path: str) -> str:
    return Path(path).name.removesuffix(".json")


def runs(paths: list[str]) -> None:
    """Print one line per summary file: episodes, reach, stalls, fitness."""
    print(
        f"{'run':40s} {'episodes':>8s} {'reached':>7s} {'reach %':>7s} {'stalls':>6s} "
        f"{'failed, stalled':>15s} {'mean fitness':>12s}"
    )
    for path in paths:
        o = json.loads(Path(path).read_text())["overall"]
        print(
            f"{_label(path):40s} {o['episodes']:8d} {o['reached']:7d} "
            f"{100 * o['reach_rate']:7.1f} {o['stalls']:6d} "
            f"{o['failed_stalled']:>5d} of {o['episodes'] - o['reached']:<6d} "
            f"{o['mean_fitness']:12.3f}"
        )


def _group(rows: list[dict]) -> dict:
    episodes = sum(r["episodes"] for r in rows)
    reached = sum(r["reached"] for r in rows)
    return {
        "mazes": len(rows),
        "episodes": episodes,
        "reached": reached,
        "reach_pct": round(100 * reached / episodes, 1) if episodes else None,
    }


def kinds(mazes_path: str, paths: list[str], json_out: str | None) -> None:
    """Print (and optionally write) each run's reach by target mode and obstacle kind."""
    mazes = {m["name"]: m for m in json.loads(Path(mazes_path).read_text())["mazes"]}
    out = {"mazes": mazes_path, "runs": {}}
    for path in paths:
        report = json.loads(Path(path).read_text())
        rows = report["per_maze"]
        missing = [r["maze"] for r in rows if r["maze"] not in mazes]
        if missing:
            sys.exit(f"{path}: mazes not in {mazes_path}: {missing[:3]}")
        o = report["overall"]
        out["runs"][_label(path)] = {
            "arbitrator": report["arbitrator"],
            "perturbation": report["perturbation"]["name"],
            "overall": _group(rows)
            | {
                "failed": o["episodes"] - o["reached"],
                "failed_stalled": o["failed_stalled"],
                "stalls": o["stalls"],
            },
            "target": {
                m: _group([r for r in rows if mazes[r["maze"]]["target_mode"] == m]) for m in MODES
            },
            "obstacle": {
                k: _group([r for r in rows if k in mazes[r["maze"]]["kinds"]]) for k in KINDS
            },
        }
    for title, key, names in (("target", "target", MODES), ("obstacle kind", "obstacle", KINDS)):
        print(f"reach % by {title} (mazes in brackets)")
        print(
            f"{'run':40s} {'all':>6s} {'failed, stalled':>15s} "
            + " ".join(f"{n:>14s}" for n in names)
        )
        for label, run in out["runs"].items():
            o = run["overall"]
            cells = " ".join(
                f"{run[key][n]['reach_pct'] if run[key][n]['mazes'] else '-':>9} "
                f"({run[key][n]['mazes']:2d})"
                for n in names
            )
            print(
                f"{label:40s} {o['reach_pct']:6.1f} {o['failed_stalled']:>5d} of "
                f"{o['failed']:<6d} {cells}"
            )
        print()
    if json_out:
        Path(json_out).write_text(json.dumps(out, indent=1) + "\n")


def main() -> None:
    """Dispatch on the first argument: summarise, runs or kinds."""
    args = sys.argv[1:]
    if args[:1] == ["summarise"]:
        summarise()
    elif args[:1] == ["runs"]:
        runs(args[1:])
    elif args[:1] == ["kinds"] and len(args) >= 3:
        json_out = None
        if "--json" in args:
            i = args.index("--json")
            json_out = args[i + 1]
            del args[i : i + 2]
        kinds(args[1], args[2:], json_out)
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
