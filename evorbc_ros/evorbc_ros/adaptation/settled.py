"""The settled-outcomes file: what each primitive does once its actuators hold its command.

Onboard adaptation compares each observation with the primitive's *expected* outcome
(docs/design/adaptation.md, "What an observation is compared with"). The repertoire's
recorded outcomes are measured from rest and include the actuators' ramp; the settled
ones do not, and only the robot's motion model can compute them. ``evorbc-evolve settled
REPERTOIRE`` computes them offline and writes this file beside the repertoire
(``NAME.settled.json`` for ``NAME.repertoire.json``); the arbitrator node only reads it
(parameter ``adaptation_expected: settled``).

The file is JSON (docs/design/file-formats.md, "Settled outcomes"): ``format``,
``version``, the repertoire's ``robot``, ``count``, ``eval_time`` and ``fingerprint``,
and the outcomes as three columns ``dx`` (m), ``dy`` (m), ``dheading`` (rad) over
``eval_time`` in each primitive's start frame (x forward, y left). Floats round-trip
exactly through JSON, so the node compares observations with the very numbers the offline
tools compute. A file made for another repertoire is refused.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from evorbc_ros.atomic_io import atomic_write_text
from evorbc_ros.json_files import load_json_file
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.repertoire_checks import ColumnError, number_column, version_problem

#: What an observation may be compared with: the repertoire's recorded outcomes, or the
#: settled ones (the arbitrator node's ``adaptation_expected``, ``evaluate --adapt-expected``).
EXPECTED = ("recorded", "settled")
FORMAT = "evorbc-settled-outcomes"
VERSION = 1
#: The outcome columns, in the order of an outcome row ``(dx m, dy m, dheading rad)``.
COLUMNS = ("dx", "dy", "dheading")
#: The command that makes the file (for the messages).
COMMAND = "evorbc-evolve settled REPERTOIRE"


class SettledError(ValueError):
    """A settled-outcomes file that cannot be used (message: one line naming the file)."""


def settled_path(repertoire_path: str | os.PathLike) -> Path:
    """The settled-outcomes file beside ``repertoire_path``.

    ``dir/NAME.repertoire.json`` -> ``dir/NAME.settled.json``; any other ``dir/NAME.json``
    -> ``dir/NAME.settled.json``.
    """
    path = Path(repertoire_path)
    name = path.name.removesuffix(".json").removesuffix(".repertoire")
    return path.with_name(f"{name}.settled.json")


def save_settled(path: str | os.PathLike, outcomes: np.ndarray, repertoire: Repertoire) -> None:
    """Write ``outcomes`` of ``repertoire`` to ``path``, atomically.

    Args:
        outcomes: ``(n, 3)`` finite settled outcomes ``(dx m, dy m, dheading rad)`` over
            the repertoire's ``eval_time``, one row per primitive in repertoire order.

    Raises:
        ValueError: ``outcomes`` of another shape, or not finite (a bug of the caller).
    """
    outcomes = np.asarray(outcomes, dtype=np.float64)
    if outcomes.shape != (len(repertoire), 3) or not np.isfinite(outcomes).all():
        raise ValueError(f"settled outcomes must be finite, ({len(repertoire)}, 3)")
    head = {
        "format": FORMAT,
        "version": VERSION,
        "robot": repertoire.robot,
        "count": len(repertoire),
        "eval_time": repertoire.eval_time,
        "fingerprint": repertoire.fingerprint(),
    }
    # One line per key and per column: compact (about 15 kB for 258 primitives) and
    # still diffable; repr floats read back to the same bits.
    lines = [f"{json.dumps(k)}: {json.dumps(v)}" for k, v in head.items()]
    pairs = zip(COLUMNS, outcomes.T, strict=True)
    columns = [f"  {json.dumps(c)}: {json.dumps(col.tolist())}" for c, col in pairs]
    text = "{\n" + ",\n".join([*lines, '"outcomes": {\n' + ",\n".join(columns) + "\n}"]) + "\n}\n"
    atomic_write_text(path, text)


def load_settled(path: str | os.PathLike, repertoire: Repertoire) -> np.ndarray:
    """The ``(n, 3)`` settled outcomes the file at ``path`` holds for ``repertoire``.

    Checked: the format and version, the fingerprint (the file was made for this very
    repertoire: robot, parameters, genes, behaviours and headings), ``count`` and
    ``eval_time``, three columns of ``n`` JSON numbers each, all finite.

    Raises:
        SettledError: one line naming ``path`` and the first problem found.
    """
    source = str(path)
    data = load_json_file(path, "settled outcomes", SettledError)
    try:
        return _outcomes(data, repertoire)
    except (SettledError, ColumnError) as e:
        raise SettledError(f"{source}: {e}") from None


def _outcomes(data, repertoire: Repertoire) -> np.ndarray:
    """The outcome rows of a parsed file (errors without the file name)."""
    if not isinstance(data, dict):
        raise SettledError("expected a JSON object at the top level")
    if data.get("format") != FORMAT:
        raise SettledError(
            f"not a settled-outcomes file (format is {data.get('format')!r}, expected {FORMAT!r})"
        )
    problem = version_problem(data.get("version"), "settled outcomes", VERSION)
    if problem:
        raise SettledError(problem)
    fingerprint = data.get("fingerprint")
    if fingerprint != repertoire.fingerprint():
        made = fingerprint[:12] if isinstance(fingerprint, str) else repr(fingerprint)
        raise SettledError(
            f"made for another repertoire (fingerprint {made}, the repertoire's is "
            f"{repertoire.fingerprint()[:12]}): make it again with {COMMAND}"
        )
    n = len(repertoire)
    if type(data.get("count")) is not int or data["count"] != n:
        raise SettledError(
            f"count must be the repertoire's {n} primitives, got {data.get('count')!r}"
        )
    if data.get("eval_time") != repertoire.eval_time:
        raise SettledError(
            f"eval_time must be the repertoire's {repertoire.eval_time} s, "
            f"got {data.get('eval_time')!r}"
        )
    columns = data.get("outcomes")
    if not isinstance(columns, dict) or sorted(columns) != sorted(COLUMNS):
        raise SettledError(f"outcomes must be an object of the columns {', '.join(COLUMNS)}")
    rows = []
    for c in COLUMNS:
        if not isinstance(columns[c], list):
            raise SettledError(f"outcomes.{c} must be a list of numbers")
        values = number_column(columns[c], c, rows=False, prefix="outcomes.")
        if values.shape != (n,):
            raise SettledError(
                f"outcomes.{c} must hold {n} values, one per primitive, got {len(values)}"
            )
        if not np.isfinite(values).all():
            raise SettledError(f"outcomes.{c} must be finite numbers")
        rows.append(values)
    return np.ascontiguousarray(np.stack(rows, axis=1))
