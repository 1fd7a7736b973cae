"""Settings of a MAP-Elites repertoire run (paper Algorithm 1 and Table I).

Each robot's defaults live in the repertoire settings file its registration names
(``config/repertoire/4ws.yaml`` for the 4WS robots); the CLI loads that file and applies
command-line overrides on top.
"""

from __future__ import annotations

import dataclasses
import os
import typing
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from evorbc_ros.config import (
    ConfigError,
    build_settings,
    load_yaml_mapping,
    setting,
)
from evorbc_ros.robots.registry import DEFAULT_ROBOT, ROBOT_NAMES, lookup
from offline_evolution import bounds
from offline_evolution.quality import METRICS

ARCHIVES = ("grid", "cvt")
VARIATIONS = ("paper", "iso_line_dd")


@dataclass(frozen=True)
class MapElitesSettings:
    """Everything that determines a repertoire run's result (seed included)."""

    robot: str = setting(doc="robot type", choices=ROBOT_NAMES)
    metric: str = setting(doc="quality metric", choices=tuple(METRICS))
    bin_size: float = setting(doc="side of a square archive cell (m)", minimum=1e-4)
    eval_time: float = setting(doc="primitive evaluation time T (s)", minimum=0.1)
    initial_batch: int = setting(
        doc="random solutions in the first batch (S_G)", minimum=1, maximum=bounds.INITIAL_BATCH
    )
    # Bounded by memory (offline_evolution/memory.py) and by bounds.EVALUATIONS.
    batch_size: int = setting(doc="mutants per iteration (S_B)", minimum=1)
    iterations: int = setting(
        doc="iterations after the initial batch (I)", minimum=0, maximum=bounds.ITERATIONS
    )
    mutation_probability: float = setting(
        0.25, doc="per-gene mutation probability", minimum=0.0, maximum=1.0
    )
    mutation_sigma: float = setting(0.5, doc="sd of the Gaussian gene mutation", minimum=0.0)
    seed: int = setting(0, doc="seed of every random choice of the run", minimum=0)
    archive: str = setting("grid", doc="archive kind", choices=ARCHIVES)
    variation: str = setting("paper", doc="variation operator", choices=VARIATIONS)
    iso_sigma: float = setting(0.02, doc="Iso+LineDD: sd of the isotropic gene noise", minimum=0.0)
    line_sigma: float = setting(
        0.2, doc="Iso+LineDD: sd of the step along the line between two elites", minimum=0.0
    )

    @property
    def evaluations(self) -> int:
        """Primitive evaluations the full run makes (S_G + I * S_B)."""
        return self.initial_batch + self.iterations * self.batch_size

    def as_dict(self) -> dict:
        """Plain-data form (for repertoire metadata and checkpoints)."""
        return dataclasses.asdict(self)


def default_settings_file(robot: str) -> Path:
    """The repertoire settings file ``robot``'s registration names.

    Raises:
        evorbc_ros.robots.registry.UnknownRobot: naming the known robots.
    """
    return lookup(robot).settings_file("repertoire")


class SettingError(ConfigError):
    """A well-formed setting that does not suit the robot (checked once the robot is built).

    ``key`` names the setting and ``problem`` says what is wrong, so the caller can blame
    the command-line option or the settings file it came from (:func:`blame`).
    """

    def __init__(self, key: str, problem: str) -> None:
        super().__init__(f"{key} {problem}")
        self.key = key
        self.problem = problem


def blame(error: SettingError, path: str | os.PathLike, options: Mapping[str, str]) -> ConfigError:
    """``error`` in one line naming where the setting came from.

    Args:
        path: the settings file the run read.
        options: setting key -> the command-line option that set it (only those given).

    """
    option = options.get(error.key)
    if option:
        return ConfigError(f"{option}: {error.problem}")
    return ConfigError(f"{path}: {error.key} {error.problem}")


def settings_path(path: str | os.PathLike | None, robot: str | None) -> Path:
    """The settings file a run reads: ``path``, or ``robot``'s default settings file."""
    return Path(path) if path is not None else default_settings_file(robot or DEFAULT_ROBOT)


def load_settings(
    path: str | os.PathLike | None = None,
    options: Mapping[str, str] | None = None,
    **overrides,
) -> MapElitesSettings:
    """Settings from a YAML file with ``overrides`` (``None`` values are ignored) on top.

    Without ``path`` the robot's default settings file is used; the robot comes from
    ``overrides`` or the file.

    Args:
        options: setting key -> command-line option, so that a bad override is blamed on
            its option (``--bin-size: must be >= 0.0001, got 1e-09``), not on the file.

    Raises:
        evorbc_ros.config.ConfigError: naming the file and the offending key, or the option.

    """
    overrides = {k: v for k, v in overrides.items() if v is not None}
    options = options or {}
    for key, value in overrides.items():
        _check_override(key, value, options.get(key, f"override {key}"))
    path = settings_path(path, overrides.get("robot"))
    values = load_yaml_mapping(path)
    values.update(overrides)
    return build_settings(MapElitesSettings, values, str(path))


def check_budget(
    settings: MapElitesSettings, path: str | os.PathLike, options: Mapping[str, str]
) -> None:
    """Refuse a run of more than :data:`~offline_evolution.bounds.EVALUATIONS` evaluations.

    Args:
        path: the settings file the run read.
        options: setting key -> the command-line option that set it (only those given).

    Raises:
        ConfigError: one line with the count, the bound and the settings to lower.
    """
    if settings.evaluations > bounds.EVALUATIONS:
        keys = ("iterations", "batch_size", "initial_batch")
        names = [options.get(k) or f"{k} in {path}" for k in keys]
        raise ConfigError(
            f"initial_batch + iterations x batch_size = {settings.evaluations:,} evaluations, "
            f"more than the bound of {bounds.EVALUATIONS:,} a run (docs/design.md section "
            f"12); lower {', '.join(names[:-1])} or {names[-1]}"
        )


def _check_override(key: str, value, label: str) -> None:
    """Check one override alone, so that its error names ``label`` rather than the file."""
    fields = {f.name: f for f in dataclasses.fields(MapElitesSettings)}
    if key not in fields:
        raise ConfigError(f"{label}: unknown setting {key!r}")
    hint = typing.get_type_hints(MapElitesSettings)[key]
    single = dataclasses.make_dataclass(
        "Override", [(key, hint, dataclasses.field(metadata=fields[key].metadata))]
    )
    try:
        build_settings(single, {key: value}, label)
    except ConfigError as e:
        # build_settings says "<label>: <key> must be ..."; the option alone is clearer.
        raise ConfigError(str(e).replace(f"{label}: {key} ", f"{label}: ", 1)) from None
