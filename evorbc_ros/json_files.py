"""Reading the JSON files users exchange, with one-line errors that name the file."""

from __future__ import annotations

import json
import os
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
    try:
        return json.loads(text)
    except RecursionError:
        # The decoder recurses once per nesting level; no file of ours nests this deeply.
        raise error(f"{source}: corrupt {what} file (invalid JSON: nested too deeply)") from None
    except json.JSONDecodeError as e:
        kind = "truncated" if e.pos >= len(text.rstrip()) else "corrupt"
        raise error(
            f"{source}: {kind} {what} file (invalid JSON at line {e.lineno}, "
            f"column {e.colno}: {e.msg})"
        ) from None


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
