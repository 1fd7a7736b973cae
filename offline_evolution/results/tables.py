"""Read and write the compact result tables of docs/results/ (CSV, one header row).

Numbers are written with 4 significant digits: the tables feed summary tables and curves
that print 2-3 digits, and the full precision of every run stays in the commit named in
docs/results/README.md. A table whose name ends in ``.csv.gz`` is the same CSV gzipped
(the two largest: their rows repeat long report and run names, a tenth of the bytes
gzipped); reading one stops at :data:`MAX_TABLE_BYTES` of text, so a hostile file cannot
fill memory.
"""

from __future__ import annotations

import csv
import gzip
import io
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

from evorbc_ros.atomic_io import atomic_write, atomic_write_text

#: Bytes of CSV text a gzipped table may hold (the largest holds 0.5 MB).
MAX_TABLE_BYTES = 64 * 2**20


def cell(value) -> str:
    """One CSV cell: floats with 4 significant digits, booleans as 0/1, None empty."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return str(int(value))
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def write_table(path: str | os.PathLike, columns: Sequence[str], rows: Iterable[Mapping]) -> int:
    """Write ``rows`` (mappings; missing keys empty) as CSV atomically; the row count."""
    buf = io.StringIO()
    out = csv.writer(buf, lineterminator="\n")
    out.writerow(columns)
    n = 0
    for row in rows:
        out.writerow([cell(row.get(c)) for c in columns])
        n += 1
    if str(path).endswith(".gz"):
        # mtime 0: the same rows give the same bytes, so an unchanged table is no change
        data = gzip.compress(buf.getvalue().encode(), compresslevel=9, mtime=0)
        atomic_write(path, lambda f: f.write(data), binary=True)
    else:
        atomic_write_text(path, buf.getvalue())
    return n


class TableError(ValueError):
    """A result table is missing, malformed or lacks a needed column."""


def read_table(path: str | os.PathLike, needed: Sequence[str] = ()) -> list[dict[str, str]]:
    """The rows of a CSV table as dicts of strings.

    Raises:
        TableError: the file is missing or unreadable, or lacks a column of ``needed``.
    """
    path = Path(path)
    try:
        text = _text(path)
        reader = csv.DictReader(io.StringIO(text, newline=""))
        rows = list(reader)
        header = reader.fieldnames or []
    except (OSError, EOFError, gzip.BadGzipFile, UnicodeDecodeError, csv.Error) as e:
        raise TableError(f"{path}: cannot read the table ({e})") from None
    missing = [c for c in needed if c not in header]
    if missing:
        raise TableError(f"{path}: expected columns {', '.join(missing)} in the header row")
    return rows


def _text(path: Path) -> str:
    """The CSV text of ``path``, gunzipped if its name ends in ``.gz`` (bounded)."""
    if not str(path).endswith(".gz"):
        with path.open(newline="") as f:
            return f.read()
    with gzip.open(path, "rb") as f:
        data = f.read(MAX_TABLE_BYTES + 1)
    if len(data) > MAX_TABLE_BYTES:
        raise TableError(f"{path}: more than {MAX_TABLE_BYTES} bytes of CSV; expected a table")
    return data.decode()


def number(row: Mapping[str, str], key: str, path: str | os.PathLike = "") -> float | None:
    """A numeric cell (None if empty).

    Raises:
        TableError: the cell is not a number.
    """
    text = row.get(key, "")
    if text == "":
        return None
    try:
        return float(text)
    except ValueError:
        raise TableError(f"{path}: column {key} must be a number, got {text!r}") from None
