"""Compact the raw run files of a ``docs/runs`` folder into the tables of docs/results/.

The raw files (arbitrator run files with their per-generation history, ``evaluate``
reports, post-selection candidate lists, failure lists) were kept under ``docs/runs`` until
the commit named in docs/results/README.md; this reads such a folder (a checkout of that
commit) and writes the tables the docs' summary tables and curves are made from. Which
file is which is read from its content, not its name, so every file of a run folder may be
passed.
"""

from __future__ import annotations

import json
import lzma
import statistics
from collections.abc import Iterable, Iterator
from pathlib import Path

from evorbc_ros.atomic_io import atomic_write_text
from offline_evolution.results.tables import write_table

RUN_COLUMNS = [
    "run",
    "robot",
    "kind",
    "seed",
    "generations",
    "best_fitness",
    "best_generation",
    "best_reached",
    "post_rule",
    "post_fitness",
    "post_reached",
    "post_candidates",
    "post_episodes",
    "nodes",
    "connections",
    "enabled",
    "recurrent",
    "sensors",
    "episode_time",
    "samples_per_maze",
    "training",
    "neat_settings",
    "seconds_median",
    "history_of",
]
#: One file per run, ``histories/RUN.csv``. ``best_so_far`` is the running maximum of
#: ``best`` and the seconds per generation are in the run's row (median): neither is kept.
HISTORY_COLUMNS = tuple(["generation", "best", "mean", "species", "best_reached"])
REPORT_COLUMNS = [
    "report",
    "arbitrator",
    "robot",
    "kind",
    "mazes",
    "generated",
    "generated_seed",
    "starts_per_maze",
    "seed",
    "episode_time",
    "perturbation",
]
MAZE_COLUMNS = [
    "report",
    "maze",
    "episodes",
    "reached",
    "mean_fitness",
    "stalls",
    "collisions",
    "falls",
    "failed_stalled",
]
CANDIDATE_COLUMNS = [
    "run",
    "candidate",
    "key",
    "training_fitness",
    "nominal_all",
    "own_reached",
    "own_fitness",
    "validation_reached",
    "validation_fitness",
    "own_per_maze",
]
FAILURE_COLUMNS = [
    "report",
    "episode",
    "maze",
    "end_x",
    "end_y",
    "end_heading",
    "final_distance",
    "target_bearing_deg",
    "contact_share",
    "stalled",
    "fell",
]
#: Suffixes dropped from a file's path (relative to the raw folder) to name its run or report.
SUFFIXES = (".arbitrator.json", ".candidates.json", ".failures.json", ".json.xz", ".json")


def load(path: Path):
    """A JSON file, plain or ``.xz``-compressed (never pickle)."""
    if path.suffix != ".xz":
        return json.loads(path.read_bytes())
    with lzma.open(path) as f:
        raw = f.read()
    return json.loads(raw)


def name_of(path: Path, root: Path) -> str:
    """``generalise/ship/4ws-5-p8-p1m-seed4.held`` for ``ROOT/generalise/ship/...held.json``."""
    rel = path.relative_to(root).as_posix()
    for suffix in SUFFIXES:
        if rel.endswith(suffix):
            return rel[: -len(suffix)]
    return rel


def run_row(name: str, data: dict) -> dict:
    """One row of ``arbitrator-runs.csv`` from an arbitrator run file."""
    evo = data["evolution"]
    task = evo.get("task", {})
    post = evo.get("post_evaluation", {})
    net = data["network"]
    history = evo.get("history", [])
    return {
        "run": name,
        "robot": data.get("robot"),
        "kind": data.get("kind"),
        "seed": evo.get("seed"),
        "generations": evo.get("generations"),
        "best_fitness": evo.get("best_fitness"),
        "best_generation": evo.get("best_generation"),
        "best_reached": evo.get("best_reached"),
        "post_rule": post.get("rule"),
        "post_fitness": post.get("fitness"),
        "post_reached": post.get("reached"),
        "post_candidates": post.get("candidates"),
        # a finalist's episodes when there was a second round (docs/design.md section 8)
        "post_episodes": post.get("episodes_per_finalist", post.get("episodes_per_candidate")),
        "nodes": len(net.get("nodes", [])),
        "connections": len(net.get("connections", [])),
        "enabled": sum(1 for c in net.get("connections", []) if c.get("enabled", True)),
        "recurrent": bool(net.get("recurrent", False)),
        "sensors": Path(task["sensors"]).stem if task.get("sensors") else None,
        "episode_time": task.get("episode_time"),
        "samples_per_maze": task.get("samples_per_maze"),
        "training": json.dumps(task["training"], sort_keys=True) if task.get("training") else None,
        "neat_settings": evo.get("neat_settings"),
        "seconds_median": statistics.median(h["seconds"] for h in history) if history else None,
    }


def history_path(out: Path, run: str) -> Path:
    """Where run ``run``'s per-generation history is: ``OUT/histories/RUN.csv``."""
    return out / "histories" / f"{run}.csv"


def _curve(data: dict) -> list[tuple[float, float]]:
    return [(h["best"], h["mean"]) for h in data["evolution"].get("history", [])]


def shared_histories(runs: list[tuple[str, dict]]) -> dict[str, str]:
    """Runs whose history is the start of another run's (or the same): name -> that run.

    A run continued to more generations (``-g300`` and the full run), a rerun with the
    checkpoint kept, or a copy post-selected again repeats the generations of the run it
    comes from; its history is stored once, under the longest run (first by name).
    """
    kept: list[tuple[str, list]] = []
    shared = {}
    for name, data in sorted(runs, key=lambda r: (-len(_curve(r[1])), r[0])):
        curve = _curve(data)
        owner = next((k for k, c in kept if c[: len(curve)] == curve), None)
        if owner is None:
            kept.append((name, curve))
        else:
            shared[name] = owner
    return shared


def report_rows(name: str, report: dict, root: str = "") -> tuple[dict, list[dict]]:
    """A report's row of ``evaluation-reports.csv`` and its rows of ``evaluation-mazes.csv.gz``.

    ``failed_stalled`` (episodes that stalled and did not reach the target) is counted from
    the episodes when the report holds them, else taken from the per-maze rows if there.
    An arbitrator under ``root`` (the raw folder) is named relative to it, as the runs are.
    """
    arbitrator = report.get("arbitrator") or ""
    if root and arbitrator.startswith(f"{root}/"):
        arbitrator = arbitrator[len(root) + 1 :]
    generated = report.get("generated") or {}
    head = {
        "report": name,
        "arbitrator": arbitrator or None,
        "robot": report.get("robot"),
        "kind": report.get("kind"),
        "mazes": None if generated else " ".join(report.get("mazes", [])),
        "generated": generated.get("count"),
        "generated_seed": generated.get("seed"),
        "starts_per_maze": report.get("starts_per_maze"),
        "seed": report.get("seed"),
        "episode_time": report.get("episode_time"),
        "perturbation": report.get("perturbation", {}).get("name"),
    }
    failed_stalled = None
    if "episodes" in report:
        failed_stalled = {}
        for ep in report["episodes"]:
            if ep["stalled"] and not ep["reached"]:
                failed_stalled[ep["maze"]] = failed_stalled.get(ep["maze"], 0) + 1
    rows = []
    for row in [*report["per_maze"], report["overall"]]:
        out = {"report": name, **{k: row.get(k) for k in MAZE_COLUMNS[1:]}}
        if failed_stalled is not None:
            out["failed_stalled"] = (
                sum(failed_stalled.values())
                if row["maze"] == "all"
                else failed_stalled.get(row["maze"], 0)
            )
        rows.append(out)
    return head, rows


def candidate_rows(name: str, data: dict) -> Iterator[dict]:
    """The post-selection candidates of a ``.candidates.json`` list."""
    for c in data["candidates"]:
        per_maze = " ".join(f"{m}={r:.4g}" for m, r in c.get("own_per_maze", {}).items())
        yield {"run": name, **c, "own_per_maze": per_maze}


def failure_rows(name: str, data: dict) -> Iterator[dict]:
    """Where each failed episode of a ``.failures.json`` list ended (m, m, rad, maze frame)."""
    for f in data["failures"]:
        x, y, heading = f["end"]
        yield {"report": name, **f, "end_x": x, "end_y": y, "end_heading": heading}


def classify(data) -> str | None:
    """Which kind of raw file ``data`` is: run, report, candidates, failures or None."""
    if not isinstance(data, dict):
        return None
    if "network" in data and "history" in data.get("evolution", {}):
        return "run"
    if "per_maze" in data and "overall" in data:
        return "report"
    if "candidates" in data and "checkpoint" in data:
        return "candidates"
    if "failures" in data and "counts" in data:
        return "failures"
    return None


def raw_files(root: Path) -> list[Path]:
    """Every JSON (or JSON.xz) file under ``root`` except checkpoints, sorted."""
    return sorted(
        p
        for p in root.rglob("*")
        if p.is_file()
        and p.name.endswith((".json", ".json.xz"))
        and not p.name.endswith(".checkpoint.json")
    )


def extract(root: Path, out: Path, controllers: Iterable[str] = ()) -> dict[str, int]:
    """Write the tables of ``root``'s raw files to ``out``; the row count of each table.

    ``controllers``: run names whose controller is kept too, as
    ``out/controllers/BASENAME.arbitrator.json`` without its history (which is in
    ``arbitrator-histories.csv``): the runs whose replays make a figure.
    """
    found: dict[str, list] = {k: [] for k in ("run", "report", "candidates", "failures")}
    for path in raw_files(root):
        data = load(path)
        kind = classify(data)
        if kind is not None:
            found[kind].append((name_of(path, root), data))
    runs = found["run"]
    shared = shared_histories(runs)
    reports = [report_rows(n, r, root.as_posix()) for n, r in found["report"]]
    out.mkdir(parents=True, exist_ok=True)
    counts = {
        "arbitrator-runs.csv": write_table(
            out / "arbitrator-runs.csv",
            RUN_COLUMNS,
            (run_row(n, d) | {"history_of": shared.get(n)} for n, d in runs),
        ),
        "evaluation-reports.csv": write_table(
            out / "evaluation-reports.csv", REPORT_COLUMNS, (head for head, _ in reports)
        ),
        "evaluation-mazes.csv.gz": write_table(
            out / "evaluation-mazes.csv.gz", MAZE_COLUMNS, (r for _, rows in reports for r in rows)
        ),
        "candidates.csv.gz": write_table(
            out / "candidates.csv.gz",
            CANDIDATE_COLUMNS,
            (r for n, d in found["candidates"] for r in candidate_rows(n, d)),
        ),
        "failures.csv": write_table(
            out / "failures.csv",
            FAILURE_COLUMNS,
            (r for n, d in found["failures"] for r in failure_rows(n, d)),
        ),
    }
    for name, data in runs:
        if name not in shared:
            path = history_path(out, name)
            path.parent.mkdir(parents=True, exist_ok=True)
            counts[f"histories/{name}.csv"] = write_table(
                path, HISTORY_COLUMNS, data["evolution"]["history"]
            )
    by_name = dict(runs)
    for name in controllers:
        if name not in by_name:
            raise KeyError(f"{root}: no arbitrator run file {name}.arbitrator.json")
        data = json.loads(json.dumps(by_name[name]))
        data["evolution"]["history"] = []
        dest = out / "controllers" / f"{Path(name).name}.arbitrator.json"
        dest.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_text(dest, json.dumps(data, indent=1) + "\n")
    return counts


__all__ = ["classify", "extract"]
