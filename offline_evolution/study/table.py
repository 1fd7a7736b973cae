"""A study's compact result table: everything its report draws and computes, in one file.

``evorbc-study compact`` writes it from a results folder and ``evorbc-study report
--results TABLE`` reads it in place of the folder. JSON (``FORMAT``, ``VERSION``), laid out
in docs/study.md, "Compact result tables":

* per setting its id and values (checked against the study file), and per finished run
  its seed, the generations asked, wall and CPU seconds, machine, ``run.json``'s summary,
  the arbitrator's evolution seconds, and the highest fitness so far of every generation,
  run-length coded (``at``: the generations where it changes, ``value``: its value from
  there on; exact);
* the example repertoire of each EvoRBC setting (its first run's): archive bounds, bin
  size, metric, its ``count`` of primitives and one integer column per drawn quantity
  (``units``: x and y in 0.1 mm, heading in mrad, quality in thousandths), each packed as
  base64 of zlib-compressed little-endian int32 (:func:`pack_column`): a third of the bytes
  of a JSON list, and a table of 37,000 primitives stays far below 1 MB;
* the selection heatmaps' counts, pooled over ``replay_runs`` runs per setting.

A malformed table is refused in one line naming the file and the key.
"""

from __future__ import annotations

import base64
import binascii
import json
import zlib
from pathlib import Path
from typing import Any

import numpy as np

from evorbc_ros.atomic_io import atomic_write
from offline_evolution.study.results import (
    CHOSEN_BINS,
    EXAMPLE_UNITS,
    OUTPUT_BINS,
    ExampleRepertoire,
    RunResult,
    SelectionCounts,
    SettingResults,
)
from offline_evolution.study.spec import Study

FORMAT = "evorbc-study-results"
VERSION = 2  # 1: example columns as JSON lists (docs/study.md, "Compact result tables")
#: The example columns' packing: base64 of zlib-compressed little-endian int32.
COLUMN_DTYPE = np.dtype("<i4")


#: Most primitives an example repertoire may hold (a 1 cm grid over 10 x 10 m).
MAX_EXAMPLE = 1_000_000


class TableError(ValueError):
    """A result table that cannot be read: one line naming the file and key."""


def write_table(
    study: Study,
    settings: list[SettingResults],
    path: Path,
    results: str,
    source: str = "",
    replay_runs: int | None = None,
) -> None:
    """Write ``settings`` as the table of ``study`` at ``path`` (atomically).

    Args:
        results: the results folder the table is made from, as given (for the page's
            commands).
        source: where the raw run folders are kept, for the page (may be empty).
        replay_runs: the ``--replay-runs`` the selection counts were made with.
    """
    data = {
        "format": FORMAT,
        "version": VERSION,
        "study": study.name,
        "results": results,
        "source": source,
        "replay_runs": replay_runs,
        "units": {f"example.{k}": u for k, u in EXAMPLE_UNITS.items()},
        "settings": [_setting_dict(s) for s in settings],
    }
    text = json.dumps(data, separators=(",", ":"))
    # One setting per line: a table diffs by setting and reads in an editor.
    text = text.replace(',{"id":', ',\n{"id":').replace('[{"id":', '[\n{"id":')
    atomic_write(path, lambda f: f.write(text + "\n"))


def _setting_dict(s: SettingResults) -> dict:
    out: dict[str, Any] = {"id": s.setting_id, "values": s.values}
    out["runs"] = [_run_dict(r) for r in s.runs]
    if s.example is not None:
        e = s.example
        out["example"] = {
            "seed": e.seed, "metric": e.metric, "bin_size": e.bin_size,
            "low": list(e.archive["low"]), "high": list(e.archive["high"]),
            "count": len(e), **{k: pack_column(v) for k, v in e.columns().items()},
        }  # fmt: skip
    if s.selection is not None:
        c = s.selection
        out["selection"] = {
            "runs": c.runs, "reach": c.reach,
            "outputs": c.outputs.tolist(), "chosen": c.chosen.tolist(),
        }  # fmt: skip
    return out


def pack_column(values: list[int]) -> str:
    """``values`` (n,) integers as base64 of zlib-compressed little-endian int32."""
    raw = np.asarray(values, dtype=np.int64)
    if raw.size and (raw.min() < -(2**31) or raw.max() >= 2**31):
        raise ValueError("an example column does not fit int32")
    return base64.b64encode(zlib.compress(raw.astype(COLUMN_DTYPE).tobytes(), 9)).decode()


def unpack_column(text: str, count: int) -> np.ndarray | None:
    """The ``(count,)`` int64 column packed by :func:`pack_column`, or None if it is not one.

    Never inflates more than ``count`` values: a hostile table cannot make it allocate more.
    """
    try:
        packed = base64.b64decode(text.encode("ascii"), validate=True)
        inflate = zlib.decompressobj()
        raw = inflate.decompress(packed, count * COLUMN_DTYPE.itemsize + 1)
    except (binascii.Error, UnicodeEncodeError, zlib.error):
        return None
    if len(raw) != count * COLUMN_DTYPE.itemsize or not inflate.eof or inflate.unused_data:
        return None
    return np.frombuffer(raw, dtype=COLUMN_DTYPE).astype(np.int64)


def _run_dict(r: RunResult) -> dict:
    h = r.best_so_far
    at = [0, *(np.flatnonzero(h[1:] != h[:-1]) + 1).tolist()] if len(h) else []
    return {
        "seed": r.seed,
        "generations": r.generations,
        "seconds": r.seconds,
        "cpu_seconds": r.cpu_seconds,
        "machine": r.machine,
        "evolution_seconds": r.evolution_seconds,
        "summary": r.summary,
        "best_so_far": {"length": len(h), "at": at, "value": h[at].tolist()},
    }


def read_table(path: Path, study: Study) -> tuple[dict, list[SettingResults]]:
    """Read and check the table of ``study`` at ``path``.

    Returns:
        The table's header (``results``, ``source``, ``replay_runs``) and its settings.

    Raises:
        TableError: naming the file and the first key that is wrong.
    """
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as e:
        raise TableError(f"{path}: not a JSON result table ({e})") from None
    c = _Checker(path)
    c.dict(data, "")
    if data.get("format") != FORMAT:
        c.fail("format", f"expected {FORMAT!r}", data.get("format"))
    if data.get("version") != VERSION:
        c.fail("version", f"expected {VERSION}", data.get("version"))
    if data.get("study") != study.name:
        c.fail("study", f"expected {study.name!r} (the study asked for)", data.get("study"))
    header = {
        "results": c.field(data, "results", str, ""),
        "source": c.field(data, "source", str, ""),
        "replay_runs": c.field(data, "replay_runs", (int, type(None)), ""),
    }
    units = {f"example.{k}": u for k, u in EXAMPLE_UNITS.items()}
    if data.get("units") != units:
        c.fail("units", f"expected {units}", data.get("units"))
    rows = c.field(data, "settings", list, "")
    expected = study.settings()
    if len(rows) != len(expected):
        c.fail("settings", f"expected the {len(expected)} settings of {study.name}", len(rows))
    return header, [
        _read_setting(c, row, f"settings[{i}].", sid, values)
        for i, (row, (sid, values)) in enumerate(zip(rows, expected, strict=True))
    ]


def _read_setting(c: _Checker, row, where: str, sid: str, values: dict) -> SettingResults:
    c.dict(row, where[:-1])
    if c.field(row, "id", str, where) != sid:
        c.fail(f"{where}id", f"expected {sid!r} (the study's settings, in order)", row["id"])
    if c.field(row, "values", dict, where) != values:
        c.fail(f"{where}values", f"expected {values} (the study file's)", row["values"])
    runs = [
        _read_run(c, run, f"{where}runs[{k}].")
        for k, run in enumerate(c.field(row, "runs", list, where))
    ]
    setting = SettingResults(sid, values, runs)
    if "example" in row:
        setting.example = _read_example(c, row["example"], f"{where}example.")
    if "selection" in row:
        setting.selection = _read_selection(c, row["selection"], f"{where}selection.")
    return setting


def _read_run(c: _Checker, run, where: str) -> RunResult:
    c.dict(run, where[:-1])
    summary = c.field(run, "summary", dict, where)
    c.numbers_in(summary, f"{where}summary")
    c.number(summary, "best_fitness", f"{where}summary.")
    h = c.field(run, "best_so_far", dict, where)
    length = c.field(h, "length", int, f"{where}best_so_far.")
    at = c.array(h, "at", f"{where}best_so_far.", integer=True)
    value = c.array(h, "value", f"{where}best_so_far.")
    ok = len(at) == len(value) and (length == 0 or (len(at) and at[0] == 0))
    if not ok or np.any(np.diff(at) <= 0) or (len(at) and at[-1] >= length):
        c.fail(
            f"{where}best_so_far.at",
            f"expected increasing generations from 0 below length {length}, one per value",
            at.tolist(),
        )
    return RunResult(
        seed=c.field(run, "seed", int, where),
        generations=c.field(run, "generations", (int, type(None)), where),
        seconds=c.number(run, "seconds", where),
        cpu_seconds=c.number(run, "cpu_seconds", where),
        machine=c.field(run, "machine", str, where),
        summary=summary,
        evolution_seconds=c.number(run, "evolution_seconds", where, optional=True),
        best_so_far=np.repeat(value, np.diff([*at.tolist(), length])),
    )


def _read_example(c: _Checker, e, where: str) -> ExampleRepertoire:
    c.dict(e, where[:-1])
    n = c.field(e, "count", int, where)
    if not 0 <= n <= MAX_EXAMPLE:
        c.fail(f"{where}count", f"expected 0 to {MAX_EXAMPLE} primitives", n)
    columns = {}
    for k in EXAMPLE_UNITS:
        columns[k] = unpack_column(c.field(e, k, str, where), n)
        if columns[k] is None:
            expected = f"expected {n} integers packed as base64 of zlib int32 (count)"
            c.fail(f"{where}{k}", expected, e[k])
    bounds = [c.array(e, k, where) for k in ("low", "high")]
    for k, b in zip(("low", "high"), bounds, strict=True):
        if b.shape != (2,):
            c.fail(f"{where}{k}", "expected [x, y] in m", b.tolist())
    return ExampleRepertoire.from_columns(
        c.field(e, "seed", int, where), c.field(e, "metric", str, where),
        c.number(e, "bin_size", where), *(b.tolist() for b in bounds), columns,
    )  # fmt: skip


def _read_selection(c: _Checker, s, where: str) -> SelectionCounts:
    c.dict(s, where[:-1])
    counts = {}
    for key, bins in (("outputs", OUTPUT_BINS), ("chosen", CHOSEN_BINS)):
        a = c.array(s, key, where, integer=True, ndim=2)
        if a.shape != (bins, bins) or np.any(a < 0):
            c.fail(f"{where}{key}", f"expected {bins} x {bins} counts >= 0", f"shape {a.shape}")
        counts[key] = a
    runs = c.field(s, "runs", int, where)
    return SelectionCounts(runs, c.number(s, "reach", where), counts["outputs"], counts["chosen"])


class _Checker:
    """Type checks of a table's values, each failing as ``FILE: KEY: expected ..., got ...``."""

    def __init__(self, path: Path):
        self.path = path

    def fail(self, key: str, expected: str, got: Any):
        shown = repr(got)
        shown = shown if len(shown) <= 60 else shown[:57] + "..."
        raise TableError(f"{self.path}: {key or 'top level'}: {expected}, got {shown}")

    def dict(self, value, key: str) -> None:
        if not isinstance(value, dict):
            self.fail(key, "expected an object", value)

    def field(self, obj: dict, key: str, kind, where: str):
        if key not in obj:
            self.fail(f"{where}{key}", "missing", None)
        value = obj[key]
        kinds = kind if isinstance(kind, tuple) else (kind,)
        if not isinstance(value, kinds) or (isinstance(value, bool) and bool not in kinds):
            names = " or ".join(k.__name__.replace("NoneType", "null") for k in kinds)
            self.fail(f"{where}{key}", f"expected {names}", value)
        return value

    def number(self, obj: dict, key: str, where: str, optional: bool = False) -> float | None:
        kinds = (int, float, type(None)) if optional else (int, float)
        value = self.field(obj, key, kinds, where)
        return None if value is None else float(value)

    def numbers_in(self, obj: dict, where: str) -> None:
        """Every leaf of ``obj`` is a number or null (a run's summary)."""
        for key, value in obj.items():
            if isinstance(value, dict):
                self.numbers_in(value, f"{where}.{key}")
            elif value is not None and (
                isinstance(value, bool) or not isinstance(value, (int, float))
            ):
                self.fail(f"{where}.{key}", "expected a number", value)

    def array(
        self, obj: dict, key: str, where: str, integer: bool = False, ndim: int = 1
    ) -> np.ndarray:
        value = self.field(obj, key, list, where)
        try:
            a = np.array(value, dtype=float)
        except (TypeError, ValueError):
            a = None
        if a is None or a.ndim != ndim:
            what = "a list of numbers" if ndim == 1 else f"a {ndim}-D list of numbers"
            self.fail(f"{where}{key}", f"expected {what}", value)
        if integer and not np.all(np.isfinite(a) & (a == np.round(a))):
            self.fail(f"{where}{key}", "expected a list of integers", value)
        if not integer and np.any(np.isinf(a)):
            self.fail(f"{where}{key}", "expected finite numbers", value)
        return a.astype(np.int64) if integer else a
