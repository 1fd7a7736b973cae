"""Reading the JSON files users exchange, with one-line errors that name the file.

A number beyond float range (``10**400`` as a weight, ``1e400`` as an archive bound, a
checkpoint's RNG state) is refused while parsing, with the key that holds it: Python reads
such an integer exactly and such a float as infinity, so it would otherwise fail later,
far from the file, as an internal error.
"""

from __future__ import annotations

import json
import math
import os
import re
import reprlib
import sys
from typing import Any

from evorbc_ros.input_files import DATA_LIMIT, read_regular_text


def load_json_file(
    path: str | os.PathLike, what: str, error: type[Exception], limit: int = DATA_LIMIT
) -> Any:
    """Parse the JSON file at ``path``.

    Args:
        what: what the file should be (``"repertoire"``), for the messages.
        error: the exception class to raise.
        limit: the largest file (bytes) accepted for ``what``.

    Raises:
        ``error``: missing, not a regular file, too large, unreadable, not UTF-8, or
        truncated/corrupt (also absurdly nested) JSON, in one line that starts with the
        path. Numbers beyond float range are refused where they are used (they load as
        Python integers or infinity).
    """
    source = str(path)
    text = read_regular_text(path, what, error, limit)
    return parse_json(text, source, what, error)


#: The largest integer a float can hold (to within rounding): larger ones overflow.
_FLOAT_MAX_INT = int(sys.float_info.max)
#: An exponent of 100 or more: the only floats that may be beyond float range.
_BIG_EXPONENT = re.compile(r"[eE]\+?0*[1-9]\d\d")


class _BeyondFloat:
    """A JSON number beyond float range, kept as its text until its key is found."""

    __slots__ = ("text",)

    def __init__(self, text: str) -> None:
        self.text = text


def parse_json(text: str, source: str, what: str, error: type[Exception], range_error=None) -> Any:
    """Parse JSON ``text`` read from ``source`` (see :func:`load_json_file` for errors).

    Args:
        range_error: what to raise for a number beyond float range (default ``error``).
    """
    seen = []

    def parse_int(digits: str):
        # No int() of a 5000-digit literal: Python refuses it with a ValueError of its own.
        n = len(digits.lstrip("-"))
        if n < 309 or (n == 309 and abs(int(digits)) <= _FLOAT_MAX_INT):
            return int(digits)
        seen.append(True)
        return _BeyondFloat(digits)

    def parse_float(digits: str):
        value = float(digits)
        if math.isinf(value):  # 1e400: a literal "Infinity" is parse_constant's
            seen.append(True)
            return _BeyondFloat(digits)
        return value

    # A hook costs a Python call per number. Integers are few in our files (counts,
    # keys, seeds); floats are many, and only one with an exponent of 100 or more can
    # overflow, which a quick search rules out.
    hooks = {"parse_int": parse_int}
    if _BIG_EXPONENT.search(text):
        hooks["parse_float"] = parse_float
    try:
        data = json.loads(text, **hooks)
    except RecursionError:
        # The decoder recurses once per nesting level; no file of ours nests this deeply.
        raise error(f"{source}: corrupt {what} file (invalid JSON: nested too deeply)") from None
    except json.JSONDecodeError as e:
        kind = "truncated" if e.pos >= len(text.rstrip()) else "corrupt"
        raise error(
            f"{source}: {kind} {what} file (invalid JSON at line {e.lineno}, "
            f"column {e.colno}: {e.msg})"
        ) from None
    if seen:
        where, number = find_value(data, lambda v: isinstance(v, _BeyondFloat))
        raise (range_error or error)(
            f"{source}: {where or 'the top level'}: {reprlib.repr(number.text)} is beyond "
            "float range (at most about 1.8e308)"
        )
    return data


def find_value(data: Any, wanted, where: str = "") -> tuple[str, Any] | None:
    """``(key path, value)`` of the first value in nested ``data`` with ``wanted(value)``.

    Paths read like the files' keys: ``network.connections[3].weight``; None if none.
    """
    if wanted(data):
        return where, data
    if isinstance(data, dict):
        items = ((f"{where}.{k}" if where else str(k), v) for k, v in data.items())
    elif isinstance(data, list):
        items = ((f"{where}[{i}]", v) for i, v in enumerate(data))
    else:
        return None
    for key, value in items:
        found = find_value(value, wanted, key)
        if found:
            return found
    return None


def first_difference(saved: dict, current: dict, where: str) -> str | None:
    """Describe the first key whose value differs between a saved record and now.

    Nested dicts are compared key by key, so the message names the innermost setting
    (``geometry.max_joint_velocity is 10.0 in <where> but 5.0 now``); None if equal.
    """
    for key in sorted(set(saved) | set(current)):
        old, new = saved.get(key), current.get(key)
        if isinstance(old, dict) and isinstance(new, dict):
            inner = first_difference(old, new, where)
            if inner:
                return f"{key}.{inner}"
        elif old != new:
            return f"{key} is {old!r} in {where} but {new!r} now"
    return None
