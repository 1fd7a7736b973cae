"""Repertoire files: the locomotion primitives that MAP-Elites found, and how they were made.

A repertoire file is plain JSON (never pickled), versioned, and validated on load. It holds,
per primitive, the genes (in [-1, 1]), the behaviour (displacement after T seconds, m, in
the start frame: x forward, y left), the final heading (rad, unwrapped) and the quality;
and, as metadata, the robot, the parameter names/units/ranges, the archive layout, the
metric, the evaluation time, the seed, the algorithm settings and summary statistics.

Layout (version 1)::

    {"format": "evorbc-repertoire", "version": 1, "robot": "4ws-5",
     "parameters": [{"name", "unit", "low", "high"}, ...],
     "metric": "circular", "eval_time": 2.0, "bin_size": 0.04, "seed": 1,
     "archive": {"kind": "grid", "dims": [21, 21], "low": [..], "high": [..]},
     "algorithm": {...}, "summary": {"count", "mean_quality", "qd_score", ...},
     "primitives": {"genes": [[..], ..], "behaviour": [[x, y], ..],
                    "heading": [..], "quality": [..]}}

Columns are stored as lists so the file stays readable and diffable; floats round-trip
exactly through JSON.
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import math
import os
import reprlib
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from evorbc_ros.atomic_io import atomic_write_text
from evorbc_ros.json_files import load_json_file
from evorbc_ros.limits import PRIMITIVES
from evorbc_ros.repertoire_checks import (
    QUALITY_RANGES,
    ColumnError,
    archive_problem,
    contents_problem,
    number_column,
    version_problem,
)
from evorbc_ros.robots import registry
from evorbc_ros.robots.primitive import GENE_HIGH, GENE_LOW, ParameterSpec

FORMAT = "evorbc-repertoire"
VERSION = 1

#: Names of the quality metrics, with their ranges in repertoire_checks.QUALITY_RANGES
#: (the search defines the metrics, docs/design.md section 3, and takes their ranges from
#: there).
METRICS = tuple(QUALITY_RANGES)


class RepertoireError(ValueError):
    """A repertoire file or object is not valid; the message names the file and problem."""


@dataclass
class Repertoire:
    """A repertoire of locomotion primitives (arrays are row-aligned, one row each)."""

    robot: str
    parameters: tuple[ParameterSpec, ...]
    genes: np.ndarray  # (n, d) in [-1, 1]
    behaviour: np.ndarray  # (n, 2) m, displacement after eval_time, start frame
    heading: np.ndarray  # (n,) rad, final heading after eval_time, unwrapped
    quality: np.ndarray  # (n,)
    metric: str
    eval_time: float  # s
    bin_size: float  # m
    seed: int
    archive: dict[str, Any] = field(default_factory=dict)
    algorithm: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.parameters = tuple(self.parameters)
        self.genes = np.asarray(self.genes, dtype=np.float64)
        self.behaviour = np.asarray(self.behaviour, dtype=np.float64)
        self.heading = np.asarray(self.heading, dtype=np.float64)
        self.quality = np.asarray(self.quality, dtype=np.float64)
        problem = _problem(self)
        if problem:
            raise RepertoireError(f"invalid repertoire: {problem}")

    def __len__(self) -> int:
        return len(self.quality)

    @property
    def n_parameters(self) -> int:
        """Number of locomotion parameters of each primitive."""
        return len(self.parameters)

    def physical_parameters(self) -> np.ndarray:
        """``(n, d)`` parameters in their physical units (genes mapped onto the ranges)."""
        if len(self) == 0:
            return np.empty((0, self.n_parameters))
        return np.column_stack(
            [p.to_physical(self.genes[:, k]) for k, p in enumerate(self.parameters)]
        )

    def summary(self) -> dict[str, float | int]:
        """Count, mean/sd/min/max quality, QD-score and coverage of the archive.

        The QD-score is the sum of qualities (every metric is >= 0, so no offset is
        needed); coverage is the fraction of the archive's cells that hold a primitive.
        """
        n = len(self)
        cells = int(np.prod(self.archive.get("dims", [0]))) or None
        q = self.quality
        return {
            "count": n,
            "mean_quality": float(q.mean()) if n else 0.0,
            "sd_quality": float(q.std()) if n else 0.0,
            "min_quality": float(q.min()) if n else 0.0,
            "max_quality": float(q.max()) if n else 0.0,
            "qd_score": float(q.sum()),
            "coverage": n / cells if cells else None,
        }

    def fingerprint(self) -> str:
        """SHA-256 over what an arbitrator depends on: robot, parameters and primitives."""
        h = hashlib.sha256()
        h.update(json.dumps([self.robot, [p.as_dict() for p in self.parameters]]).encode())
        for a in (self.genes, self.behaviour, self.heading):
            h.update(np.ascontiguousarray(a, dtype="<f8").tobytes())
        return h.hexdigest()

    def to_dict(self) -> dict[str, Any]:
        """The plain-data form written to files."""
        return {
            "format": FORMAT,
            "version": VERSION,
            "robot": self.robot,
            "parameters": [p.as_dict() for p in self.parameters],
            "metric": self.metric,
            "eval_time": self.eval_time,
            "bin_size": self.bin_size,
            "seed": self.seed,
            "archive": self.archive,
            "algorithm": self.algorithm,
            "summary": self.summary(),
            "primitives": {
                "genes": self.genes.tolist(),
                "behaviour": self.behaviour.tolist(),
                "heading": self.heading.tolist(),
                "quality": self.quality.tolist(),
            },
        }

    def save(self, path: str | os.PathLike) -> None:
        """Write the repertoire to ``path`` as JSON, atomically."""
        atomic_write_text(path, json.dumps(self.to_dict(), indent=1) + "\n")

    def to_csv(self, path: str | os.PathLike) -> None:
        """Write one row per primitive for pandas and spreadsheets, atomically.

        Columns: ``x_m, y_m, heading_rad, quality``, the genes ``gene_<name>`` and the
        physical parameters ``<name>_<unit>``.
        """
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        units = [p.unit.replace("/", "p") for p in self.parameters]
        writer.writerow(
            ["x_m", "y_m", "heading_rad", "quality"]
            + [f"gene_{p.name}" for p in self.parameters]
            + [f"{p.name}_{u}" for p, u in zip(self.parameters, units, strict=True)]
        )
        physical = self.physical_parameters()
        for i in range(len(self)):
            writer.writerow(
                [repr(float(v)) for v in (*self.behaviour[i], self.heading[i], self.quality[i])]
                + [repr(float(v)) for v in self.genes[i]]
                + [repr(float(v)) for v in physical[i]]
            )
        atomic_write_text(path, buf.getvalue())

    @classmethod
    def from_dict(cls, data: Any, source: str = "repertoire") -> Repertoire:
        """Build and validate a repertoire from its plain-data form.

        Raises:
            RepertoireError: naming ``source`` and the first problem found.

        """
        if not isinstance(data, dict):
            raise RepertoireError(f"{source}: expected a JSON object at the top level")
        fmt = data.get("format")
        if fmt != FORMAT:
            raise RepertoireError(
                f"{source}: not a repertoire file (format is {fmt!r}, expected {FORMAT!r})"
            )
        problem = version_problem(data.get("version"), "repertoire", VERSION)
        if problem:
            raise RepertoireError(f"{source}: {problem}")
        try:
            prims = _require(data, "primitives", dict, source)
            params = _require(data, "parameters", list, source)
            parameters = []
            for k, p in enumerate(params):
                if not isinstance(p, dict):
                    raise RepertoireError(f"{source}: parameters[{k}] must be an object")
                parameters.append(
                    ParameterSpec(
                        name=str(_require(p, "name", str, source, f"parameters[{k}].")),
                        unit=str(_require(p, "unit", str, source, f"parameters[{k}].")),
                        low=float(_require(p, "low", (int, float), source, f"parameters[{k}].")),
                        high=float(_require(p, "high", (int, float), source, f"parameters[{k}].")),
                    )
                )
            arrays = _columns(prims, source)
            if len(arrays["quality"]) == 0:
                arrays["genes"] = arrays["genes"].reshape(0, len(parameters))
                arrays["behaviour"] = arrays["behaviour"].reshape(0, 2)
            fields = {
                "robot": _require(data, "robot", str, source),
                "parameters": tuple(parameters),
                "metric": _require(data, "metric", str, source),
                "eval_time": float(_require(data, "eval_time", (int, float), source)),
                "bin_size": float(_require(data, "bin_size", (int, float), source)),
                "seed": int(_require(data, "seed", int, source)),
                "archive": _require(data, "archive", dict, source),
                "algorithm": _require(data, "algorithm", dict, source),
            }
        except (ValueError, TypeError, OverflowError) as e:
            if isinstance(e, RepertoireError):
                raise
            raise RepertoireError(f"{source}: {e}") from None
        repertoire = cls.__new__(cls)
        for key, value in {**fields, **arrays}.items():
            setattr(repertoire, key, value)
        problem = _problem(repertoire)
        if problem:
            raise RepertoireError(f"{source}: {problem}")
        return repertoire

    @classmethod
    def load(cls, path: str | os.PathLike) -> Repertoire:
        """Load and validate a repertoire file.

        Raises:
            RepertoireError: one line naming the file and what is wrong with it (missing,
                truncated, not JSON, wrong format or version, inconsistent shapes, ...).

        """
        data = load_json_file(path, "repertoire", RepertoireError)
        repertoire = cls.from_dict(data, str(path))
        # Valid as data, but nothing can run on it: every arbitrator needs a primitive.
        if len(repertoire) == 0:
            raise RepertoireError(f"{path}: the repertoire has no primitives")
        return repertoire


def _require(data: dict, key: str, kind, source: str, prefix: str = ""):
    if key not in data:
        raise RepertoireError(f"{source}: missing key {prefix}{key}")
    value = data[key]
    # bool is an int subclass; a true/false where a number belongs is a mistake.
    if not isinstance(value, kind) or (isinstance(value, bool) and kind is not bool):
        names = kind.__name__ if isinstance(kind, type) else "/".join(k.__name__ for k in kind)
        raise RepertoireError(
            f"{source}: {prefix}{key} must be {names}, got {type(value).__name__}"
        )
    return value


#: Robots declared by :func:`declare_robot` in this process: name -> genes per primitive.
#: They are known to files only; the registry holds the robots the CLI and nodes drive.
_DECLARED: dict[str, int] = {}


def declare_robot(name: str, n_parameters: int) -> None:
    """Let repertoires and arbitrator files in this process name ``name``, a robot of yours.

    For a robot whose primitives you evaluate yourself (``MapElites``' ask/tell loop,
    docs/design.md section 20): its repertoire then loads and saves like any other, with
    ``n_parameters`` genes per primitive. The CLI and the nodes still drive only the
    robots they know.

    Raises:
        ValueError: ``name`` is empty, or known with another number of parameters.

    """
    if not isinstance(name, str) or not name:
        raise ValueError(f"a robot needs a name, got {name!r}")
    if isinstance(n_parameters, bool) or not isinstance(n_parameters, int) or n_parameters < 1:
        raise ValueError(f"robot {name} needs a whole number of parameters >= 1")
    if registry.known(name):
        known = registry.lookup(name).n_parameters
    else:
        known = _DECLARED.setdefault(name, n_parameters)
    if known != n_parameters:
        raise ValueError(f"robot {name} is known with {known} parameters, not {n_parameters}")


def robot_problem(robot: Any, n_parameters: int | None = None) -> str | None:
    """Why ``robot`` (with ``n_parameters`` genes, if given) is no robot we know, or None.

    Known robots are those of the robot registry (:mod:`evorbc_ros.robots.registry`),
    plugins included.
    """
    if isinstance(robot, str) and robot in _DECLARED and not registry.known(robot):
        expected = _DECLARED[robot]
    elif not registry.known(robot):
        return f"robot {robot!r} is not known; known robots: {', '.join(registry.names())}"
    else:
        expected = registry.lookup(robot).n_parameters
    if n_parameters is not None and n_parameters != expected:
        return f"robot {robot} has {expected} parameters, the file has {n_parameters}"
    return None


def _problem(r: Repertoire) -> str | None:
    """The first problem with robot, metric, shapes, finiteness or ranges, or None."""
    n = r.quality.shape[0] if r.quality.ndim == 1 else -1
    d = len(r.parameters)
    checks = [
        (
            r.metric in METRICS,
            f"metric must be one of {', '.join(METRICS)}, got {reprlib.repr(r.metric)}",
        ),
        (
            r.quality.ndim == 1,
            f"primitives.quality must be a list of numbers, got shape {r.quality.shape}",
        ),
        (
            r.genes.shape == (n, d),
            f"primitives.genes has shape {r.genes.shape}, expected "
            f"({n}, {d}) (primitives x parameters)",
        ),
        (
            r.behaviour.shape == (n, 2),
            f"primitives.behaviour has shape {r.behaviour.shape}, expected ({n}, 2)",
        ),
        (
            r.heading.shape == (n,),
            f"primitives.heading has shape {r.heading.shape}, expected ({n},)",
        ),
        (
            math.isfinite(r.eval_time) and r.eval_time > 0,
            f"eval_time must be > 0 s, got {r.eval_time!r}",
        ),
        (
            math.isfinite(r.bin_size) and r.bin_size > 0,
            f"bin_size must be > 0 m, got {r.bin_size!r}",
        ),
    ]
    for ok, message in checks:
        if not ok:
            return message
    # After the shapes, so that genes and parameters that disagree are named as such.
    problem = robot_problem(r.robot, d)
    if problem:
        return problem
    for name in ("genes", "behaviour", "heading", "quality"):
        if not np.all(np.isfinite(getattr(r, name))):
            return f"primitives.{name} contains NaN or infinity"
    if n and (r.genes.min() < GENE_LOW or r.genes.max() > GENE_HIGH):
        return f"primitives.genes must lie in [{GENE_LOW}, {GENE_HIGH}]"
    for k, p in enumerate(r.parameters):
        if not (math.isfinite(p.low) and math.isfinite(p.high) and p.low < p.high):
            return f"parameters[{k}] ({p.name}) needs low < high"
    simulation = r.algorithm.get("simulation")  # compared key by key with the robot's
    if simulation is not None and not isinstance(simulation, dict):
        return f"algorithm.simulation must be a mapping, got {reprlib.repr(simulation)}"
    return archive_problem(r.archive, r.bin_size) or contents_problem(r)


def _columns(prims: dict, source: str) -> dict[str, np.ndarray]:
    """The four columns of ``primitives`` as arrays, counted before they are converted.

    The count comes from the lists' lengths, so a file of millions of primitives is
    refused (over :data:`~evorbc_ros.limits.PRIMITIVES`) before any per-primitive work.
    """
    lists = {key: _require(prims, key, list, source, "primitives.") for key in _COLUMNS}
    PRIMITIVES.check(max(map(len, lists.values())), source, RepertoireError, "in the file")
    try:
        return {key: number_column(lists[key], key, rows) for key, rows in _COLUMNS.items()}
    except ColumnError as e:
        raise RepertoireError(f"{source}: {e}") from None


#: The columns of ``primitives`` and whether each is a list of rows (or of numbers).
_COLUMNS = {"genes": True, "behaviour": True, "heading": False, "quality": False}
