"""A study's results as the report reads them.

The report and its figures need, per setting: each run's record (seed, generations, times,
summary) and per-generation highest fitness so far, the first run's repertoire as the
figure draws it (:class:`ExampleRepertoire`), and, for the selection heatmaps, the pooled
replay counts (:class:`SelectionCounts`). ``offline_evolution/study/folder.py`` reads
them from a results folder; ``offline_evolution/study/table.py`` writes and reads them as
one compact file (docs/study.md, "Compact result tables"). The report is made from these
objects alone, so a report from the folder and one from its table are the same.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.repertoire import Repertoire
from offline_evolution.study.run import read_json_xz

#: Units of the example repertoire's integer columns in a table (value = integer x unit):
#: 0.1 mm is a fifth of a pixel in the repertoire figure's smallest panel (0.2 m over about
#: 390 pixels at 150 dpi), 1 mrad moves a heading line's tip by at most 0.2 mm (lines are
#: half a bin, at most 0.4 m, long), 0.001 of quality is below one step of its colour map.
EXAMPLE_UNITS = {"x": 1e-4, "y": 1e-4, "heading": 1e-3, "quality": 1e-3}
#: Bins of the selection heatmaps: mapping outputs over [0, 1]^2, chosen displacements
#: over [-reach, reach]^2 (m).
OUTPUT_BINS, CHOSEN_BINS = 25, 40


@dataclass
class FinishedRun:
    """One finished run folder: its ``run.json`` and, on demand, its files."""

    folder: Path
    record: dict

    @cached_property
    def arbitrator_data(self) -> dict:
        """The arbitrator file's contents."""
        return read_json_xz(self.folder / "arbitrator.json.xz")

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
class RunResult:
    """What the report uses of one finished run."""

    seed: int
    generations: int | None  # NEAT generations asked (the run's settings)
    seconds: float  # wall, summed over resumes
    cpu_seconds: float
    machine: str
    summary: dict  # run.json's summary (best_fitness, post_fitness, repertoire counts)
    evolution_seconds: float | None  # the arbitrator file's evolution time, if recorded
    best_so_far: np.ndarray  # (generations run,) highest training fitness so far

    @property
    def best_fitness(self) -> float:
        """The highest training fitness of the run (the paper's figure)."""
        return float(self.summary["best_fitness"])

    @classmethod
    def from_folder(cls, run: FinishedRun) -> RunResult:
        """Read from a run folder (its ``run.json`` and arbitrator file)."""
        record = run.record
        evolution = run.arbitrator_data["evolution"]
        try:
            evolution_seconds = float(evolution["seconds"])
        except (KeyError, TypeError, ValueError):
            evolution_seconds = None
        return cls(
            seed=int(record["settings"]["seed"]),
            generations=record["settings"].get("generations"),
            seconds=float(record["seconds"]),
            cpu_seconds=float(record["cpu_seconds"]),
            machine=str(record.get("machine", "")),
            summary=record.get("summary", {}),
            evolution_seconds=evolution_seconds,
            best_so_far=np.array([h["best_so_far"] for h in evolution["history"]], dtype=float),
        )


@dataclass
class ExampleRepertoire:
    """A setting's example repertoire, as much as the repertoire figure draws.

    ``behaviour (n, 2)`` m, ``heading (n,)`` rad and ``quality (n,)``, at the precision
    of :data:`EXAMPLE_UNITS`; the attributes :func:`draw_repertoire` reads.
    """

    seed: int
    metric: str
    bin_size: float  # m
    archive: dict  # {"low": [x, y], "high": [x, y]} m
    behaviour: np.ndarray
    heading: np.ndarray
    quality: np.ndarray

    def __len__(self) -> int:
        return len(self.quality)

    @classmethod
    def from_columns(cls, seed, metric, bin_size, low, high, columns: dict) -> ExampleRepertoire:
        """From integer ``columns`` (x, y, heading, quality) in :data:`EXAMPLE_UNITS`."""
        scaled = {k: np.asarray(columns[k], dtype=float) * u for k, u in EXAMPLE_UNITS.items()}
        return cls(
            seed, metric, float(bin_size), {"low": list(low), "high": list(high)},
            np.column_stack([scaled["x"], scaled["y"]]).reshape(-1, 2),
            scaled["heading"], scaled["quality"],
        )  # fmt: skip

    @classmethod
    def of(cls, r: Repertoire, seed: int) -> ExampleRepertoire:
        """Rounded from a whole repertoire."""
        low = r.archive.get("low", [-0.5, -0.5])
        high = r.archive.get("high", [0.5, 0.5])
        columns = _integer_columns(r.behaviour, r.heading, r.quality)
        return cls.from_columns(seed, r.metric, r.bin_size, low, high, columns)

    def columns(self) -> dict[str, list[int]]:
        """The integer columns of the table (see :data:`EXAMPLE_UNITS`)."""
        columns = _integer_columns(self.behaviour, self.heading, self.quality)
        return {k: v.tolist() for k, v in columns.items()}


def _integer_columns(behaviour, heading, quality) -> dict[str, np.ndarray]:
    """Integer columns in :data:`EXAMPLE_UNITS`.

    From ``behaviour (n, 2)`` m, ``heading (n,)`` rad and ``quality (n,)``.
    """
    values = {"x": behaviour[:, 0], "y": behaviour[:, 1], "heading": heading, "quality": quality}
    return {k: np.round(values[k] / u).astype(np.int64) for k, u in EXAMPLE_UNITS.items()}


@dataclass
class SelectionCounts:
    """The selection heatmaps of one setting, pooled over ``runs`` replayed controllers.

    ``outputs (OUTPUT_BINS, OUTPUT_BINS)`` counts of mapping outputs (m1 along axis 0,
    m2 along axis 1) over [0, 1]^2; ``chosen (CHOSEN_BINS, CHOSEN_BINS)`` counts of the
    chosen primitives' displacements (x, y) over [-reach, reach]^2 m.
    """

    runs: int
    reach: float  # m
    outputs: np.ndarray
    chosen: np.ndarray


@dataclass
class SettingResults:
    """A setting of the study, its finished runs (seed order) and its figures' data."""

    setting_id: str
    values: dict[str, Any]
    runs: list[RunResult] = field(default_factory=list)
    example: ExampleRepertoire | None = None  # the first run's repertoire (EvoRBC)
    selection: SelectionCounts | None = None

    @property
    def best(self) -> np.ndarray:
        """``(n,)`` best training fitness of each run."""
        return np.array([r.best_fitness for r in self.runs])

    def summary(self, key: str) -> np.ndarray:
        """``(n,)`` a summary value of each run (NaN where absent)."""
        out = []
        for r in self.runs:
            value: Any = r.summary
            for part in key.split("."):
                value = value.get(part) if isinstance(value, dict) else None
            out.append(np.nan if value is None else float(value))
        return np.array(out)


def protocol(settings: list[SettingResults]) -> dict:
    """The protocol the finished runs followed: seeds and generations found."""
    generations = sorted({r.generations for s in settings for r in s.runs} - {None})
    counts = [len(s.runs) for s in settings]
    return {
        "generations": generations,
        "runs": sum(counts),
        "min_seeds": min(counts, default=0),
        "max_seeds": max(counts, default=0),
    }
