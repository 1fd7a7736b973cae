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
from itertools import chain
from typing import Any

from evorbc_ros.input_files import DATA_LIMIT, gc_paused, read_regular_text
from evorbc_ros.limits import NESTING


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
#: An exponent of 100 or more: the only floats that may be beyond float range. One
#: pattern per letter: a pattern that starts with a literal is searched for nine times as
#: fast as one that starts with ``[eE]`` (0.05 s for 92 MB, docs/performance.md).
_BIG_EXPONENTS = (re.compile(r"e\+?0*[1-9]\d\d"), re.compile(r"E\+?0*[1-9]\d\d"))


class _BeyondFloat:
    """A JSON number beyond float range, kept as its text until its key is found."""

    __slots__ = ("text",)

    def __init__(self, text: str) -> None:
        self.text = text


class _Duplicated(dict):
    """An object in which ``key`` appears twice, kept until its key path is found."""

    __slots__ = ("key",)


def duplicate_key_hook(found: list):
    """An ``object_pairs_hook`` that marks an object in which a key appears twice.

    The marked object is appended to ``found`` too, so that the data is searched for its
    key path only when there is one.
    """

    def pairs(items: list) -> dict:
        obj = dict(items)
        if len(obj) == len(items):
            return obj
        seen = set()
        marked = _Duplicated(obj)
        marked.key = next(k for k, _ in items if k in seen or seen.add(k))
        found.append(marked)
        return marked

    return pairs


#: A ``\uD800``-``\uDFFF`` escape: the only way a lone surrogate gets into decoded text.
_SURROGATE_ESCAPE = re.compile(r"\\u[dD][89a-fA-F]")


def _lone_surrogate(value: Any) -> bool:
    """Whether ``value`` is text holding a lone surrogate, or an object with such a key."""
    if isinstance(value, dict):
        return any(isinstance(k, str) and _lone_surrogate(k) for k in value)
    if not isinstance(value, str):
        return False
    try:
        value.encode("utf-8")
    except UnicodeEncodeError:
        return True
    return False


def parse_json(text: str, source: str, what: str, error: type[Exception], range_error=None) -> Any:
    r"""Parse JSON ``text`` read from ``source`` (see :func:`load_json_file` for errors).

    Besides invalid JSON, refused in one line naming the key path: a key that appears
    twice in one object (JSON keeps the last silently), text with a lone surrogate (a
    ``"\ud800"`` escape; such text cannot be printed or written as UTF-8), a number
    beyond float range, and nesting deeper than :data:`evorbc_ros.limits.NESTING`.

    Args:
        range_error: what to raise for a value the file holds but no writer makes (a
            number beyond float range, a key twice, a lone surrogate); default ``error``.
    """
    refuse = range_error or error
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
    # overflow, which a quick search rules out. Objects are few too (columns are lists):
    # the duplicate-key hook costs little (docs/performance.md).
    duplicated = []
    hooks = {"parse_int": parse_int, "object_pairs_hook": duplicate_key_hook(duplicated)}
    if any(p.search(text) for p in _BIG_EXPONENTS):
        hooks["parse_float"] = parse_float
    try:
        with gc_paused():
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
    except MemoryError:
        raise error(f"{source}: cannot parse: the {what} file does not fit in memory") from None
    depth = nesting_depth(data)
    if depth > _bound(source, error):
        raise error(f"{source}: corrupt {what} file: {NESTING.problem(depth)}")
    if duplicated:
        where, obj = find_value(data, lambda v: isinstance(v, _Duplicated))
        raise refuse(f"{source}: key {_path(where, obj.key)!r} appears twice")
    if _SURROGATE_ESCAPE.search(text):
        found = find_value(data, _lone_surrogate)
        if found:
            where, value = found
            name = "text"
            if isinstance(value, dict):
                name, value = "a key", next(k for k in value if _lone_surrogate(k))
            raise refuse(
                f"{source}: {where or 'the top level'}: {name} with a lone surrogate "
                f"({ascii(value)[:60]}), which is no character; expected UTF-8 text"
            )
    if seen:
        where, number = find_value(data, lambda v: isinstance(v, _BeyondFloat))
        raise refuse(
            f"{source}: {where or 'the top level'}: {reprlib.repr(number.text)} is beyond "
            "float range (at most about 1.8e308)"
        )
    return data


def _path(where: str, key: str) -> str:
    name = key if key.isidentifier() else json.dumps(key)
    return f"{where}.{name}" if where else name


def _bound(source: str, error: type[Exception]) -> int:
    try:
        return NESTING.value()
    except ValueError as e:  # its environment variable is not a positive integer
        raise error(f"{source}: {e}") from None


_CONTAINERS = (list, dict, _Duplicated)


def nesting_depth(data: Any) -> int:
    """How many lists and objects deep ``data`` nests (0 for a number or text).

    Level by level, with the iteration in C (``chain``, ``map(type, ...)``): the 4 million
    numbers of a 200,000-primitive repertoire's columns cost one pass, not a Python call
    each (docs/performance.md).
    """
    if data.__class__ not in _CONTAINERS:
        return 0
    depth = 0
    level = [data]
    while True:
        depth += 1
        kinds = set(map(type, _children(level)))  # the deepest level is never listed
        if list not in kinds and dict not in kinds and _Duplicated not in kinds:
            return depth
        level = [v for v in _children(level) if v.__class__ in _CONTAINERS]


def _children(level: list):
    """The items of the lists and the values of the objects in ``level``, lazily."""
    lists = [v for v in level if v.__class__ is list]
    dicts = [v for v in level if v.__class__ is not list]
    return chain(chain.from_iterable(lists), chain.from_iterable(map(dict.values, dicts)))


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

    Nested dicts are compared key by key and lists of equal length entry by entry, so the
    message names the innermost setting (``geometry.max_joint_velocity is 10.0 in <where>
    but 5.0 now``, ``oscillators[3].phase is ...``); lists of other lengths say so, and a
    long value is shortened, so the line stays short whatever the records hold. None if
    equal.
    """
    for key in sorted(set(saved) | set(current)):
        inner = _value_difference(saved.get(key), current.get(key), where)
        if inner:
            return f"{key}{inner}"
    return None


#: Characters of a value a difference shows before shortening it.
_SHOWN = 60


def _value_difference(old, new, where: str) -> str | None:
    """How ``old`` (saved) and ``new`` differ, as a suffix to their key; None if equal."""
    if isinstance(old, dict) and isinstance(new, dict):
        inner = first_difference(old, new, where)
        return f".{inner}" if inner else None
    if isinstance(old, list) and isinstance(new, list):
        if len(old) != len(new):
            return f" has {len(old)} entries in {where} but {len(new)} now"
        for k, (a, b) in enumerate(zip(old, new, strict=True)):
            inner = _value_difference(a, b, where)
            if inner:
                return f"[{k}]{inner}"
        return None
    if old != new:
        return f" is {_shown(old)} in {where} but {_shown(new)} now"
    return None


def _shown(value) -> str:
    """``repr(value)``, shortened past :data:`_SHOWN` characters."""
    text = repr(value)
    return text if len(text) <= _SHOWN else f"{text[: _SHOWN - 5]}...{text[-2:]}"
