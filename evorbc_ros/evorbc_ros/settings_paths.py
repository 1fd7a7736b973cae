"""Files named in settings files: relative paths resolve beside the file that names them.

One rule for every settings file (docs/design.md section 12): a relative path is taken from
the folder of the file that names it. Files written before the rule named some paths from
another folder (a task's ``sensors`` from evorbc's ``config/``, its maze files from the
working directory); such a path still works when only that old location has the file,
with one deprecation line on stderr naming the file and the key. evorbc's own files in
``config/`` keep naming each other from ``config/`` (so that a copy of one, edited
elsewhere, still works, with the line).

This module depends on the standard library only.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

#: Deprecation lines already printed in this process (one per file and key).
_SAID: set[str] = set()
#: A path naming one of evorbc's own settings files wherever evorbc is installed
#: (``config:tasks/maze-a1.yaml``), as ``pybullet_data:`` names a URDF of pybullet's.
SHIPPED_PREFIX = "config:"


def resolve_beside(
    value: str,
    source: str | os.PathLike,
    key: str,
    old: Path | tuple[Path, ...],
    shipped: Path | None = None,
) -> str:
    """The file ``value`` named by key ``key`` of settings file ``source``.

    Args:
        value: the path as written (an absolute one is only written as below).
        source: the settings file that names it (its folder is where ``value`` is looked
            for first).
        key: how the deprecation line names the key (``sensors``, ``mazes[2]``).
        old: the folder (or folders, in the order they were tried) the key's relative
            paths used to be taken from.
        shipped: a folder (evorbc's ``config/``) that files within its parent folder (the
            checkout) are written relative to, as recorded files name them; None: every
            path found is written absolute.

    Returns:
        For ``config:NAME`` (:data:`SHIPPED_PREFIX`), ``NAME`` relative to ``shipped``
        (absolute if it has no such file, so that "no such file" names where it was
        looked for). Else the file beside ``source`` (or ``value`` if absolute): relative
        to ``shipped`` if it lies within its parent folder, else absolute. Else, if only an
        old location has it, ``value`` unchanged (so that whatever reads it from there
        still does), after the deprecation line unless ``source`` is one of ``shipped``'s
        own files.
        Else the absolute path beside ``source``, so that "no such file" names where it
        was looked for.
    """
    if value.startswith(SHIPPED_PREFIX) and shipped is not None:
        name = value[len(SHIPPED_PREFIX) :]
        target = (shipped / name).resolve()
        inside = target.is_relative_to(shipped.resolve()) and target.is_file()
        return (
            Path(os.path.relpath(target, shipped.resolve())).as_posix() if inside else str(target)
        )
    path = Path(value).expanduser()
    beside = (Path(source).resolve().parent / path).resolve()  # an absolute path: itself
    if beside.exists():
        if shipped is not None and beside.is_relative_to(shipped.resolve().parent):
            # Written as files recorded before the rule name it (``sensors/4ws.yaml``,
            # ``../docs/...`` in a checkout), so that a run records the same task.
            return Path(os.path.relpath(beside, shipped.resolve())).as_posix()
        return str(beside)
    # evorbc's own files in config/ name each other from config/, as files copied from
    # them do: those stay as they are, without a line, so that copies keep working.
    own = shipped is not None and Path(source).resolve().is_relative_to(shipped.resolve())
    if path.is_absolute():
        return str(path)
    for folder in old if isinstance(old, tuple) else (old,):
        if (folder / path).exists():
            if own:
                return value
            line = (
                f"{source}: {key}: {value} is not beside this file; taken from {folder} "
                "(deprecated: relative paths in settings files are from the file's folder)"
            )
            if line not in _SAID:
                _SAID.add(line)
                print(f"evorbc: warning: {line}", file=sys.stderr)
            return value
    return str(beside)
