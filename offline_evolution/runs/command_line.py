"""A run's settings and the ``evorbc-evolve`` options that state them, one name each.

A settings field is named as its option's destination (``bin_size`` is ``--bin-size``),
so a command builds the settings from its parsed arguments, and a study records the
command line a run is equivalent to, with no table of option names in between.
"""

from __future__ import annotations

import argparse
from dataclasses import fields


def option(field: str) -> str:
    """The option of a settings field: ``--bin-size`` for ``bin_size``."""
    return "--" + field.replace("_", "-")


def from_arguments(cls, args: argparse.Namespace, **given):
    """An instance of the settings class ``cls`` from parsed ``args`` (and ``given``).

    Fields the command has no option for keep their defaults.
    """
    values = {f.name: getattr(args, f.name) for f in fields(cls) if hasattr(args, f.name)}
    return cls(**{**values, **given})


def command_line(run) -> list[str]:
    """The ``evorbc-evolve`` arguments equivalent to the settings ``run``.

    ``[run.command, options...]``: each field that is set (not None, not False), in
    field order; True is a flag, anything else ``--option VALUE``.
    """
    out = [run.command]
    for f in fields(run):
        value = getattr(run, f.name)
        if f.name == "kind" or value is None or value is False:
            continue
        out += [option(f.name)] if value is True else [option(f.name), str(value)]
    return out


def as_dict(run) -> dict:
    """The settings ``run`` as plain JSON data (a controller kind by its name)."""
    return {f.name: _plain(getattr(run, f.name)) for f in fields(run)}


def _plain(value):
    return value if value is None or isinstance(value, (bool, int, float, str)) else str(value)
