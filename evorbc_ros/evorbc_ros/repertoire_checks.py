"""What the numbers of a repertoire may be, checked once at load (docs/design.md section 12).

A repertoire file can be well-formed JSON of the right shapes and still hold what no run
writes: a behaviour outside the archive, two primitives in one cell, a quality the metric
cannot give, a heading of a million radians, cells of 1e-300 m. Each is refused here, in
one line naming the key. Every check is a few numpy passes over the columns (linear in the
number of primitives) and runs once per load, never while a robot is driven.
"""

from __future__ import annotations

import math
import reprlib
from itertools import chain
from typing import Any

import numpy as np

from evorbc_ros.limits import ARCHIVE_CELLS

#: Quality metric -> (lowest, highest) quality it can give. The metrics themselves are
#: defined by the search (docs/design.md section 3), a layer this onboard package must not
#: import; it takes each metric's range from here, so the two cannot disagree. Heading metrics are
#: 1 - |angle error| / pi in [0, 1]; distance is reach / path, clipped to [0, 1]; a sum
#: of two is in [0, 2]; circular+tilt is (1 - tilt / 45 deg) + circular, tilt in [0, 45 deg].
QUALITY_RANGES: dict[str, tuple[float, float]] = {
    "circular": (0.0, 1.0),
    "radial": (0.0, 1.0),
    "distance": (0.0, 1.0),
    "distance+circular": (0.0, 2.0),
    "distance+radial": (0.0, 2.0),
    "circular+tilt": (0.0, 2.0),
}

#: Largest |final heading| (rad) a primitive may have. The heading is unwrapped, so it
#: counts whole turns: our robots turn at most a few rad/s, i.e. tens of radians in any
#: sensible evaluation time, and 1000 rad (about 160 turns) leaves a wide margin. Beyond it
#: a value means a broken simulation or an edit, and wrapping it to (-pi, pi] starts to lose
#: digits (the spacing of doubles is 1e-13 rad at 1000 rad, 1e-10 at 1e6, 2 rad at 1e16).
HEADING_LIMIT = 1000.0

#: Range of the evaluation time T (s): above 0, and at most an hour. The paper's primitives
#: run for seconds; an hour is far beyond any, and keeps times, speeds (m / T) and the
#: number of simulation steps sane numbers.
EVAL_TIME_RANGE = (0.0, 3600.0)

#: pyribs adds this to a scaled measure before flooring it to a grid index (GridArchive's
#: default epsilon); the same formula assigns cells here, so the check agrees with the run.
_GRID_EPSILON = 1e-6


def version_problem(version: Any, kind: str, expected: int) -> str | None:
    """Why ``version`` is not the format version ``expected`` of ``kind`` files, or None.

    It must be a JSON integer: ``1.0`` and ``true`` compare equal to 1 in Python, but no
    writer makes them, so a file holding them was made or edited by something else.
    """
    if type(version) is not int:
        return (
            f"version must be a whole number (the format version, {expected}), "
            f"got {reprlib.repr(version)}"
        )
    if version != expected:
        return (
            f"{kind} format version {version} is not supported (this evorbc reads "
            f"version {expected})"
        )
    return None


class ColumnError(ValueError):
    """A column of primitives holds something other than numbers (message: the problem)."""


def number_column(value: list, key: str, rows: bool, prefix: str = "primitives.") -> np.ndarray:
    """``value`` (a list of numbers, or of equal-length lists of numbers) as float64.

    Checks the type of every element first (in C, via ``map(type, ...)``), because numpy
    converts the strings "0.5" and booleans to floats without complaint.

    Raises:
        ColumnError: naming ``<prefix><key>`` (``primitives.<key>``) and what it holds
            instead.

    """
    try:
        if rows:
            kinds = set(map(type, value))
            if kinds - {list}:
                raise ColumnError(f"{prefix}{key} must be a list of lists of numbers")
            kinds = set(map(type, chain.from_iterable(value)))
        else:
            kinds = set(map(type, value))
        if kinds - {int, float}:
            names = ", ".join(sorted(k.__name__ for k in kinds - {int, float}))
            raise ColumnError(f"{prefix}{key} must hold only numbers, it holds {names}")
        return np.asarray(value, dtype=np.float64)
    except (ValueError, OverflowError) as e:
        if isinstance(e, ColumnError):
            raise
        raise ColumnError(
            f"{prefix}{key} must be a rectangular array of numbers within float range"
        ) from None


def _positive_int(value: Any) -> bool:
    """A JSON integer (not a boolean) > 0."""
    return isinstance(value, int) and not isinstance(value, bool) and value > 0


def _finite(value: Any) -> bool:
    """A JSON number (not a boolean) that is finite."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def archive_problem(archive: dict, bin_size: float) -> str | None:
    """The first problem with the archive layout (MAP-Elites' grid, docs/design.md section 6).

    The layout must be the one ``bin_size`` gives: a grid of ``dims`` cells of ``bin_size``
    m over ``[low, high]``, or a CVT with at most as many cells. The number of cells is
    bounded (:data:`~evorbc_ros.limits.ARCHIVE_CELLS`) before anything is made per cell.
    """
    if not archive:
        return None  # a repertoire made in memory without one: nothing reads it
    kind = archive.get("kind")
    if kind not in ("grid", "cvt"):
        return f"archive.kind must be grid or cvt, got {reprlib.repr(kind)}"
    for key in ("low", "high"):
        value = archive.get(key)
        if not (isinstance(value, list) and len(value) == 2 and all(map(_finite, value))):
            return f"archive.{key} must be 2 finite numbers (m), got {reprlib.repr(value)}"
    if not all(lo < hi for lo, hi in zip(archive["low"], archive["high"], strict=True)):
        return "archive.low must be below archive.high"
    spans = [hi - lo for lo, hi in zip(archive["low"], archive["high"], strict=True)]
    # Cells of bin_size over the archive, in floating point: 1e-300 m gives 1e600 (inf).
    implied = math.prod(s / bin_size for s in spans)
    if not implied <= ARCHIVE_CELLS.value():
        count = int(min(implied, 1e18))
        return ARCHIVE_CELLS.problem(count, f"in the archive (bin_size {bin_size!r} m)")
    if kind == "grid":
        dims = archive.get("dims")
        if not (isinstance(dims, list) and len(dims) == 2 and all(map(_positive_int, dims))):
            return f"archive.dims must be 2 positive integers, got {reprlib.repr(dims)}"
        for axis, (n, span) in enumerate(zip(dims, spans, strict=True)):
            # grid_layout makes span = n * bin_size exactly, up to rounding.
            if not math.isclose(n * bin_size, span, rel_tol=1e-9):
                return (
                    f"archive.dims[{axis}] is {n} cells of bin_size {bin_size!r} m = "
                    f"{n * bin_size!r} m, but archive.high - archive.low is {span!r} m"
                )
        return None
    cells = archive.get("cells")
    if not _positive_int(cells):
        return f"archive.cells must be a positive integer, got {reprlib.repr(cells)}"
    if cells > round(implied) + 1:  # cvt_layout: as many cells as the grid, to within one
        return (
            f"archive.cells is {cells}, more than the {round(implied)} cells of bin_size "
            f"{bin_size!r} m over the archive"
        )
    centroids = archive.get("centroids")
    if centroids is not None:
        if not (isinstance(centroids, list) and len(centroids) == cells):
            return f"archive.centroids must list archive.cells ({cells}) points"
        try:
            points = number_column(centroids, "", rows=True)
        except ColumnError:
            points = np.empty((0,))
        if points.shape != (cells, 2) or not np.all(np.isfinite(points)):
            return "archive.centroids must be [x, y] pairs of finite numbers (m)"
    return None


def contents_problem(r) -> str | None:
    """The first problem with a repertoire's values, or None (shapes already checked).

    Args:
        r: a :class:`~evorbc_ros.repertoire.Repertoire` whose columns have the right
            shapes and are finite.

    """
    low, high = EVAL_TIME_RANGE
    if not low < r.eval_time <= high:
        return f"eval_time must be in ({low:g}, {high:g}] s, got {r.eval_time!r}"
    n = len(r.quality)
    if n == 0:
        return None
    q_low, q_high = QUALITY_RANGES[r.metric]
    if r.quality.min() < q_low or r.quality.max() > q_high:
        bad = int(np.argmax((r.quality < q_low) | (r.quality > q_high)))
        return (
            f"primitives.quality[{bad}] is {float(r.quality[bad])!r}, outside "
            f"[{q_low:g}, {q_high:g}], the range of metric {r.metric}"
        )
    if np.abs(r.heading).max() > HEADING_LIMIT:
        bad = int(np.argmax(np.abs(r.heading) > HEADING_LIMIT))
        return (
            f"primitives.heading[{bad}] is {float(r.heading[bad])!r} rad, beyond the "
            f"+-{HEADING_LIMIT:g} rad any primitive turns"
        )
    if not r.archive:
        return None
    lo, hi = np.asarray(r.archive["low"], float), np.asarray(r.archive["high"], float)
    inside = np.all((r.behaviour >= lo) & (r.behaviour < hi), axis=1)
    if not inside.all():
        bad = int(np.argmin(inside))
        return (
            f"primitives.behaviour[{bad}] is {r.behaviour[bad].tolist()} m, outside the "
            f"archive [{lo.tolist()}, {hi.tolist()})"
        )
    cells = _cells(r.behaviour, r.archive, lo, hi)
    if cells is None:
        return None
    keep = cells >= 0  # -1: a behaviour as near to two CVT centroids (which pyribs chose)
    cells = np.where(keep, cells, -1 - np.arange(len(cells)))
    order = np.argsort(cells, kind="stable")
    same = np.flatnonzero(cells[order][1:] == cells[order][:-1])
    if same.size:
        a, b = sorted((int(order[same[0]]), int(order[same[0] + 1])))
        return f"primitives {a} and {b} are in the same archive cell; an archive keeps one"
    return None


#: Above this many distance computations (primitives x CVT cells) the one-per-cell check
#: of a CVT archive is left out: it is a brute-force nearest-centroid search.
_CVT_WORK = 50_000_000


def _cells(behaviour: np.ndarray, archive: dict, lo: np.ndarray, hi: np.ndarray):
    """Each behaviour's archive cell index as pyribs assigns it, or None if not computed."""
    if archive["kind"] == "grid":
        dims = np.asarray(archive["dims"], dtype=np.int64)
        grid = ((dims * (behaviour - lo) + _GRID_EPSILON) / (hi - lo)).astype(np.int64)
        grid = np.clip(grid, 0, dims - 1)
        return grid[:, 0] * dims[1] + grid[:, 1]
    centroids = archive.get("centroids")
    if centroids is None or len(behaviour) * len(centroids) > _CVT_WORK:
        return None
    c = np.asarray(centroids, dtype=np.float64)
    out = np.empty(len(behaviour), dtype=np.int64)
    step = max(1, 1_000_000 // len(c))  # rows per chunk: about 8 MB of distances
    for start in range(0, len(behaviour), step):
        b = behaviour[start : start + step]
        d = ((b[:, None, :] - c[None, :, :]) ** 2).sum(axis=2)
        nearest = d.argmin(axis=1)
        if len(c) > 1:
            # The centroids are mirrored (y -> -y), so a behaviour on the x axis is as near
            # to two of them; pyribs' k-d tree may take either, so such a one is left out.
            two = np.partition(d, 1, axis=1)[:, :2]
            nearest[two[:, 1] - two[:, 0] <= 1e-12 * (1.0 + two[:, 1])] = -1
        out[start : start + step] = nearest
    return out
