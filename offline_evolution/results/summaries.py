"""Summary tables of docs/generalisation.md made from the compact tables of docs/results/.

Each function returns the text the page quotes; the commands of docs/results/README.md
print it.
"""

from __future__ import annotations

import json
from pathlib import Path

from offline_evolution.results.tables import TableError, number, read_table

#: Where a generated maze's target is, and its obstacle kinds (`evorbc-evolve mazes --json`).
MODES = ("wall", "behind", "anywhere", "open")
KINDS = ("baffle", "gap", "diagonal", "posts", "block", "dead_end", "chamber")


def load_results(results: Path) -> tuple[dict[str, dict], dict[str, list[dict]]]:
    """The runs by name and each report's per-maze rows (the ``all`` row last)."""
    runs_path = results / "arbitrator-runs.csv"
    mazes_path = results / "evaluation-mazes.csv.gz"
    runs = {r["run"]: r for r in read_table(runs_path, ("run", "post_reached", "post_episodes"))}
    reports: dict[str, list[dict]] = {}
    for row in read_table(mazes_path, ("report", "maze", "episodes", "reached")):
        reports.setdefault(row["report"], []).append(row)
    return runs, reports


def overall(reports: dict[str, list[dict]], report: str) -> dict[str, str] | None:
    """A report's ``all`` row, or None if there is no such report."""
    return next((r for r in reports.get(report, []) if r["maze"] == "all"), None)


def _rate(row: dict | None) -> float | None:
    return None if row is None else float(row["reached"]) / float(row["episodes"])


def training(run: dict[str, str]) -> str:
    """How a screening run trained, in the words of the generalisation table."""
    what = "none (paper protocol)"
    if run.get("training"):
        t = json.loads(run["training"])
        what = f"K {t['generated']} x S {t['starts']}, " + (
            f"pool {t['pool']}" if t["pool"] else "fresh"
        )
        if not t["task_mazes"]:
            what += ", no paper mazes"
        if t.get("perturb", "none") != "none":
            what += f", `{t['perturb']}`"
        if t.get("distance", "euclidean") != "euclidean":
            what += f", {t['distance']} fitness"
        if run["samples_per_maze"] not in ("", "1"):
            what += f", {run['samples_per_maze']} starts per paper maze"
    if run.get("sensors") and run["sensors"] != "4ws":
        what += f", sensors {run['sensors']}"
    if run.get("recurrent") == "1":
        what += ", recurrent"
    if run.get("episode_time") not in ("", None) and float(run["episode_time"]) != 120.0:
        what += f", {float(run['episode_time']):g} s episodes"
    return what


def screening_table(results: Path, prefix: str = "generalise/") -> str:
    """The table "Training on generated mazes" (markdown).

    One row per run directly under ``prefix`` with the paper and held-out suites
    (``RUN.paper``, ``RUN.held``, ``RUN.heldr``).

    Raises:
        TableError: a table is missing or malformed.
    """
    runs, reports = load_results(results)
    lines = [
        "| run | training | paper mazes reached | held-out reached | held-out, `realistic` "
        "| held-out fitness | post-selection reached | s / generation |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, run in sorted(runs.items()):
        held, paper = overall(reports, f"{name}.held"), overall(reports, f"{name}.paper")
        if not name.startswith(prefix) or "/" in name[len(prefix) :]:
            continue
        if held is None or paper is None:
            continue
        heldr = _rate(overall(reports, f"{name}.heldr"))
        post = number(run, "post_reached", results / "arbitrator-runs.csv")
        fitness = number(held, "mean_fitness", results / "evaluation-mazes.csv.gz")
        lines.append(
            f"| {name[len(prefix) :]} | {training(run)} | {_rate(paper):.0%} | "
            f"**{_rate(held):.1%}** | {'' if heldr is None else f'{heldr:.1%}'} | "
            f"{fitness:.3f} | {post:.0%} of {run['post_episodes']} | "
            f"{float(run['seconds_median']):.2f} |"
        )
    return "\n".join(lines) + "\n"


def report_lines(results: Path, names: list[str]) -> str:
    """One line per report: episodes, reached, reach %, stalls, fitness.

    Also the failures that stalled (the breakdowns "paper-seeds" and "heldout-one-at-a-time").

    Raises:
        TableError: a report is not in ``evaluation-mazes.csv.gz``.
    """
    _, reports = load_results(results)
    lines = [
        f"{'run':40s} {'episodes':>8s} {'reached':>7s} {'reach %':>7s} {'stalls':>6s} "
        f"{'failed, stalled':>15s} {'mean fitness':>12s}"
    ]
    for name in names:
        o = overall(reports, name)
        if o is None:
            raise TableError(f"{results / 'evaluation-mazes.csv.gz'}: no report {name}")
        episodes, reached = int(o["episodes"]), int(o["reached"])
        stalled = o["failed_stalled"] or "?"
        lines.append(
            f"{Path(name).name:40s} {episodes:8d} {reached:7d} "
            f"{100 * reached / episodes:7.1f} {int(o['stalls']):6d} "
            f"{stalled:>5s} of {episodes - reached:<6d} {float(o['mean_fitness']):12.3f}"
        )
    return "\n".join(lines) + "\n"


def _group(rows: list[dict]) -> dict:
    episodes = sum(int(r["episodes"]) for r in rows)
    reached = sum(int(r["reached"]) for r in rows)
    return {
        "mazes": len(rows),
        "reach_pct": round(100 * reached / episodes, 1) if episodes else None,
    }


def kinds_table(results: Path, mazes_json: Path, names: list[str]) -> str:
    """Each report's reach % by target mode and by obstacle kind (mazes in brackets).

    ``mazes_json``: ``evorbc-evolve mazes --json`` of the reports' generated mazes (each
    maze's ``kinds`` and ``target_mode``).

    Raises:
        TableError: a report is missing, or holds mazes that ``mazes_json`` lacks.
    """
    try:
        mazes = {m["name"]: m for m in json.loads(mazes_json.read_text())["mazes"]}
    except (OSError, ValueError, KeyError, TypeError) as e:
        raise TableError(
            f"{mazes_json}: expected `evorbc-evolve mazes --json` output ({e})"
        ) from None
    _, reports = load_results(results)
    out = []
    for title, key, groups in (("target", "target_mode", MODES), ("obstacle kind", "kinds", KINDS)):
        out.append(f"reach % by {title} (mazes in brackets)")
        out.append(f"{'run':40s} {'all':>6s} " + " ".join(f"{n:>14s}" for n in groups))
        for name in names:
            rows = [r for r in reports.get(name, []) if r["maze"] != "all"]
            if not rows:
                raise TableError(f"{results / 'evaluation-mazes.csv.gz'}: no report {name}")
            missing = [r["maze"] for r in rows if r["maze"] not in mazes]
            if missing:
                raise TableError(f"{mazes_json}: mazes of {name} not in it: {missing[:3]}")

            def has(row, group, key=key):
                value = mazes[row["maze"]][key]
                return group in value if key == "kinds" else value == group

            cells = []
            for g in groups:
                grp = _group([r for r in rows if has(r, g)])
                pct = "-" if grp["reach_pct"] is None else grp["reach_pct"]
                cells.append(f"{pct:>9} ({grp['mazes']:2d})")
            out.append(f"{Path(name).name:40s} {_group(rows)['reach_pct']:6.1f} " + " ".join(cells))
        out.append("")
    return "\n".join(out)
