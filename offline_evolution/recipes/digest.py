"""What a recipe's output is, as hashes, and whether it is the shipped file.

An arbitrator file records how long its evolution took (``evolution.seconds``, and each
generation's ``seconds`` and ``evaluation_seconds`` in ``evolution.history``): wall-clock
times, which no rerun repeats. Everything else in it is determined by the recipe. So a
rerun is compared by its *content digest*: the sha256 of the file's JSON with those times
left out, written canonically (keys sorted, no spaces; Python's ``json`` writes each
float so that it reads back exactly). A repertoire file records no time: its content
digest still leaves nothing else out.
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass

from evorbc_ros.config import ConfigError
from evorbc_ros.json_files import load_json_file

#: Keys of ``evolution`` and of each ``evolution.history`` row that are wall-clock times.
WALL_CLOCK = ("seconds",)
HISTORY_WALL_CLOCK = ("seconds", "evaluation_seconds")


def file_sha256(path: str | os.PathLike) -> str:
    """sha256 of a file's bytes (what ``sha256sum`` prints)."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def without_wall_clock(data: dict) -> dict:
    """``data`` (a repertoire or arbitrator file's JSON) without its wall-clock times."""
    evolution = data.get("evolution")
    if not isinstance(evolution, dict):
        return data
    kept = {k: v for k, v in evolution.items() if k not in WALL_CLOCK}
    history = evolution.get("history")
    if isinstance(history, list):
        kept["history"] = [
            {k: v for k, v in row.items() if k not in HISTORY_WALL_CLOCK}
            if isinstance(row, dict)
            else row
            for row in history
        ]
    return {**data, "evolution": kept}


def content_sha256(path: str | os.PathLike) -> str:
    """The content digest of a JSON output file (see the module's docstring)."""
    data = load_json_file(path, "output", ConfigError)
    if not isinstance(data, dict):
        raise ConfigError(f"{path}: expected a JSON object, got {type(data).__name__}")
    text = json.dumps(without_wall_clock(data), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


@dataclass(frozen=True)
class Verdict:
    """How an output compares with the shipped file a recipe step states."""

    reproduced: bool  # the shipped file, but perhaps for its wall-clock times
    known: bool  # what the step states it makes (the shipped file, its stated other, or
    # anything when it states nothing)
    text: str  # one line for the user

    @staticmethod
    def of(
        path,
        sha256: str | None,
        content: str | None,
        recipe_content: str | None,
        shipped: str | None = None,
    ):
        """Compare the output ``path`` with the hashes a step states.

        ``shipped``, the shipped file itself if at hand, lets a file that is not it say
        where it differs.
        """
        got, got_content = file_sha256(path), content_sha256(path)
        if sha256 is not None and got == sha256:
            return Verdict(True, True, f"reproduced: the shipped file, byte for byte ({got})")
        if content is not None and got_content == content:
            return Verdict(
                True,
                True,
                "reproduced: the shipped file but for its wall-clock times "
                f"(content {got_content}; sha256 {got})",
            )
        if recipe_content is not None and got_content == recipe_content:
            return Verdict(
                False,
                True,
                "not the shipped file, but the file this recipe is known to make (see the "
                f"step's note; content {got_content})",
            )
        if sha256 is None and content is None:
            return Verdict(False, True, f"no shipped file stated (sha256 {got})")
        where = ""
        if shipped is not None and os.path.isfile(shipped):
            where = "; differs from the shipped file in " + differences(path, shipped)
        return Verdict(
            False,
            False,
            f"NOT reproduced: content {got_content}, expected {content or sha256}{where}",
        )


def differences(path: str | os.PathLike, shipped: str | os.PathLike, most: int = 6) -> str:
    """Where the JSON of ``path`` differs from ``shipped``'s, wall-clock times aside.

    A text listing at most ``most`` key paths (``evolution.post_evaluation.rule (not in
    the shipped file)``) and how many more there are.
    """
    found: list[str] = []

    def walk(a, b, where: str) -> None:
        if isinstance(a, dict) and isinstance(b, dict):
            for key in sorted(set(a) | set(b), key=str):
                at = f"{where}.{key}" if where else str(key)
                if key not in b:
                    found.append(f"{at} (not in the shipped file)")
                elif key not in a:
                    found.append(f"{at} (only in the shipped file)")
                else:
                    walk(a[key], b[key], at)
        elif isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
            for i, (x, y) in enumerate(zip(a, b, strict=True)):
                walk(x, y, f"{where}[{i}]")
        elif a != b:
            found.append(where or "the whole file")

    load = lambda p: without_wall_clock(load_json_file(p, "output", ConfigError))  # noqa: E731
    walk(load(path), load(shipped), "")
    more = f" and {len(found) - most} more" if len(found) > most else ""
    return (", ".join(found[:most]) or "nothing") + more
