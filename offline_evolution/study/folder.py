"""A study's results read from its results folder (one ``seed-N/run.json`` per finished run).

Kept apart from ``results.py`` (the objects) because the selection counts replay the
runs' controllers through ``selection.py``, which builds on those objects.
"""

from __future__ import annotations

import json
from pathlib import Path

from offline_evolution.study.results import (
    ExampleRepertoire,
    FinishedRun,
    RunResult,
    SettingResults,
)
from offline_evolution.study.run import RUN_FILE
from offline_evolution.study.selection import selection_counts
from offline_evolution.study.spec import Study


def finished_runs(study: Study, results: Path) -> list[tuple[str, dict, list[FinishedRun]]]:
    """``(setting id, values, finished runs in seed order)`` of every setting of ``study``."""
    out = []
    for sid, values in study.settings():
        runs = [
            FinishedRun(path.parent, json.loads(path.read_text(encoding="utf-8")))
            for path in sorted((results / sid).glob(f"seed-*/{RUN_FILE}"))
        ]
        out.append((sid, values, runs))
    return out


def load_results(
    study: Study, results: Path, selection: bool = False, replay_runs: int | None = None
) -> list[SettingResults]:
    """Every setting of ``study`` with the runs finished in ``results`` (seed order).

    Args:
        selection: replay the EvoRBC settings' controllers for the selection heatmaps.
        replay_runs: at most this many runs per setting are replayed (default: all).
    """
    out = []
    for sid, values, runs in finished_runs(study, results):
        setting = SettingResults(sid, values, [RunResult.from_folder(r) for r in runs])
        if runs:
            repertoire = runs[0].repertoire()
            if repertoire is not None:
                setting.example = ExampleRepertoire.of(repertoire, setting.runs[0].seed)
            if selection and values.get("approach", "evorbc") == "evorbc":
                setting.selection = selection_counts(runs[:replay_runs])
        out.append(setting)
    return out
