"""Settings files: YAML mappings checked against a frozen dataclass.

Each settings dataclass declares its keys as fields; a field's ``metadata`` (see
:func:`setting`) may carry allowed ``choices``, inclusive ``min``/``max`` and ``help``. Loading
rejects unknown keys, wrong types and out-of-range values with a one-line
:class:`ConfigError` that names the file and the key.

Used by the offline CLI and by the ROS nodes, so it depends on pyyaml only.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import os
import sys
import types
import typing
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from evorbc_ros.input_files import SETTINGS_LIMIT, read_regular_text
from evorbc_ros.json_files import find_value
from evorbc_ros.limits import Limit
from evorbc_ros.yaml_files import parse_yaml

#: The largest integer a float can hold; a larger one cannot be any setting.
_FLOAT_MAX_INT = int(sys.float_info.max)
#: The largest integer setting (numpy's int64).
INT_LIMIT = 2**63 - 1


class ConfigError(ValueError):
    """A settings file or value is not valid; the message names the file and key."""


def load_yaml_mapping(
    path: str | os.PathLike, counts: Mapping[str, Limit] | None = None
) -> dict[str, Any]:
    """Read a YAML file whose top level is a mapping.

    Args:
        counts: limits on the items of top-level lists, by key (a maze's ``walls``),
            checked from the count before the items are built.

    Raises:
        ConfigError: the file is missing, not a regular file, too large, not UTF-8, not
            YAML, or not a mapping; or it holds an anchor, alias or merge key, a key given
            twice or nesting too deep (:func:`evorbc_ros.yaml_files.parse_yaml`).

    """
    source = str(path)
    text = read_regular_text(path, "settings", ConfigError, SETTINGS_LIMIT)
    data = parse_yaml(text, source, ConfigError, counts)
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ConfigError(
            f"{source}: expected a mapping of settings at the top level, got {type(data).__name__}"
        )
    # YAML reads 10**400 exactly (a float that large reads as infinity, which settings
    # refuse as not finite): no setting can hold it.
    found = find_value(
        data, lambda v: isinstance(v, int) and not isinstance(v, bool) and abs(v) > _FLOAT_MAX_INT
    )
    if found:
        raise ConfigError(
            f"{source}: {found[0]} is beyond float range (at most about 1.8e308): no setting "
            "can hold it"
        )
    return data


def _field_types(cls) -> dict[str, Any]:
    return typing.get_type_hints(cls, vars(sys.modules[cls.__module__]))


def _check_value(name: str, value: Any, expected: Any, meta: dict, source: str) -> Any:
    """Coerce and check one value against its declared type and metadata."""
    origin = typing.get_origin(expected)
    if origin in (typing.Union, types.UnionType):
        options = [t for t in typing.get_args(expected) if t is not type(None)]
        if value is None:
            return None
        expected = options[0]
    if expected is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(f"{source}: {name} must be a number, got {value!r}")
        value = float(value)
        if not math.isfinite(value):
            raise ConfigError(f"{source}: {name} must be finite, got {value!r}")
    elif expected is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"{source}: {name} must be an integer, got {value!r}")
        if abs(value) > INT_LIMIT:  # numpy's int64 cannot hold it, nor any count we run
            raise ConfigError(f"{source}: {name} must be at most {INT_LIMIT:,} in size")
    elif expected is bool:
        if not isinstance(value, bool):
            raise ConfigError(f"{source}: {name} must be true or false, got {value!r}")
    elif expected is str:
        if not isinstance(value, str):
            raise ConfigError(f"{source}: {name} must be a string, got {value!r}")
    elif typing.get_origin(expected) is tuple:
        item = typing.get_args(expected)[0]
        if not isinstance(value, (list, tuple)):
            raise ConfigError(f"{source}: {name} must be a list, got {value!r}")
        value = tuple(
            _check_value(f"{name}[{i}]", v, item, {}, source) for i, v in enumerate(value)
        )
    choices = meta.get("choices")
    if choices is not None and value not in choices:
        raise ConfigError(
            f"{source}: {name} must be one of {', '.join(map(str, choices))}; got {value!r}"
        )
    low, high = meta.get("min"), meta.get("max")
    if low is not None and value < low:
        raise ConfigError(f"{source}: {name} must be >= {low}, got {value!r}")
    if high is not None and value > high:
        raise ConfigError(f"{source}: {name} must be <= {high}, got {value!r}")
    return value


def build_settings(cls, values: dict[str, Any], source: str):
    """Instantiate the settings dataclass ``cls`` from ``values``, checking every key.

    Raises:
        ConfigError: unknown key (with a suggestion), missing key, bad type or range.

    """
    fields = {f.name: f for f in dataclasses.fields(cls)}
    hints = _field_types(cls)
    for key in values:
        if key not in fields:
            close = difflib.get_close_matches(str(key), fields, n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise ConfigError(
                f"{source}: unknown setting {key!r}{hint}; known settings: {', '.join(fields)}"
            )
    kwargs = {}
    for name, f in fields.items():
        if name in values:
            kwargs[name] = _check_value(name, values[name], hints[name], dict(f.metadata), source)
        elif f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
            raise ConfigError(f"{source}: missing setting {name!r}")
    return cls(**kwargs)


def setting(
    default: Any = dataclasses.MISSING, *, doc: str = "", choices=None, minimum=None, maximum=None
):
    """Declare a settings field with its documentation and allowed values (inclusive)."""
    meta = {"help": doc, "choices": choices, "min": minimum, "max": maximum}
    return dataclasses.field(default=default, metadata=meta)


def config_dir() -> Path:
    """Folder holding the shipped settings files (the project's ``config/``).

    They are package data of :mod:`evorbc_ros` (``evorbc_ros/settings``; in a checkout a
    link to ``config/``), so an editable install, a wheel and a colcon install all find them
    the same way, beside this module (docs/design.md section 10).
    """
    return (Path(__file__).parent / "settings").resolve()
