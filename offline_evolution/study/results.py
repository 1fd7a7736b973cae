"""A study's results folder, read back: the finished runs of each setting."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.repertoire import Repertoire
from offline_evolution.study.run import RUN_FILE, read_json_xz
from offline_evolution.study.spec import Study


@dataclass
class FinishedRun:
    """One finished run: its ``run.json`` and, on demand, its files."""

    folder: Path
    record: dict

    @property
    def seed(self) -> int:
        """The run's seed."""
        return int(self.record["settings"]["seed"])

    @property
    def best_fitness(self) -> float:
        """The highest training fitness of the run (the paper's figure)."""
        return float(self.record["summary"]["best_fitness"])

    @cached_property
    def arbitrator_data(self) -> dict:
        """The arbitrator file's contents."""
        return read_json_xz(self.folder / "arbitrator.json.xz")

    def history(self, key: str = "best_so_far") -> np.ndarray:
        """``(generations,)`` per-generation values from the evolution history."""
        return np.array([h[key] for h in self.arbitrator_data["evolution"]["history"]])

    def arbitrator(self) -> ArbitratorFile:
        """The written controller."""
        return ArbitratorFile.from_dict(self.arbitrator_data, str(self.folder / "arbitrator"))

    def repertoire(self) -> Repertoire | None:
        """The run's repertoire (EvoRBC runs), else None."""
        path = self.folder / "repertoire.json.xz"
        if not path.exists():
            return None
        return Repertoire.from_dict(read_json_xz(path), str(path))


@dataclass
class SettingResults:
    """A setting of the study and its finished runs (by seed)."""

    setting_id: str
    values: dict[str, Any]
    runs: list[FinishedRun] = field(default_factory=list)

    @property
    def best(self) -> np.ndarray:
        """``(n,)`` best training fitness of each run."""
        return np.array([r.best_fitness for r in self.runs])

    def summary(self, key: str) -> np.ndarray:
        """``(n,)`` a summary value of each run (NaN where absent)."""
        out = []
        for r in self.runs:
            value: Any = r.record["summary"]
            for part in key.split("."):
                value = value.get(part) if isinstance(value, dict) else None
            out.append(np.nan if value is None else float(value))
        return np.array(out)


def load_results(study: Study, results: Path) -> list[SettingResults]:
    """Every setting of ``study`` with the runs finished in ``results`` (seed order)."""
    out = []
    for sid, values in study.settings():
        setting = SettingResults(sid, values)
        for path in sorted((results / sid).glob(f"seed-*/{RUN_FILE}")):
            record = json.loads(path.read_text(encoding="utf-8"))
            setting.runs.append(FinishedRun(path.parent, record))
        out.append(setting)
    return out


def protocol(settings: list[SettingResults]) -> dict:
    """The protocol the finished runs followed: seeds and generations found."""
    generations = sorted(
        {r.record["settings"].get("generations") for s in settings for r in s.runs} - {None}
    )
    counts = [len(s.runs) for s in settings]
    return {
        "generations": generations,
        "runs": sum(counts),
        "min_seeds": min(counts, default=0),
        "max_seeds": max(counts, default=0),
    }
