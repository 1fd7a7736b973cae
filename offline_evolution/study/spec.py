"""Study files: a grid of run settings times seeds (``config/studies/*.yaml``).

A study reproduces one part of the paper's experimental study. Its file names the grid
(every combination of the listed values is one *setting*), the settings every run shares,
the combinations the paper left out, and the number of seeds. Each (setting, seed) pair is
one *run*: an ordinary ``evorbc-evolve`` repertoire + arbitrator run (EvoRBC) or a
``standard`` run (the baseline), written into its own folder of the results folder.

The file states the full protocol (30 seeds, Table I budgets). A reduced protocol is an
override given when the study runs (``--seeds``, ``--generations``); the override is part
of every run's recorded settings, so runs of two protocols never mix in one folder.
"""

from __future__ import annotations

import itertools
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from evorbc_ros.config import ConfigError, config_dir, load_yaml_mapping
from offline_evolution import bounds
from offline_evolution.runs import repertoire as repertoire_runs

#: The two approaches the paper compares (Sec. IV-C).
APPROACHES = ("evorbc", "standard")

#: Keys of a run setting. Repertoire keys apply to EvoRBC runs only: a repertoire run's
#: settings but its robot and seed, which every run has.
REPERTOIRE_KEYS = tuple(k for k in repertoire_runs.SETTING_KEYS if k not in ("robot", "seed"))
ARBITRATOR_KEYS = ("mapping", "generations")
STANDARD_KEYS = ("generations", "equal_budget")
SETTING_KEYS = ("approach", "robot", *REPERTOIRE_KEYS, *ARBITRATOR_KEYS, "equal_budget")
TOP_KEYS = {"study", "title", "paper", "seeds", "grid", "fixed", "exclude", "compare", "figures"}
#: The largest value of each count a setting holds.
COUNT_BOUNDS = {
    "generations": bounds.GENERATIONS,
    "initial_batch": bounds.INITIAL_BATCH,
    "iterations": bounds.ITERATIONS,
}
#: Figures ``evorbc-study report`` can draw (see :mod:`offline_evolution.study.figures`).
FIGURES = ("curves", "boxplots", "repertoires", "heatmaps", "selection")


@dataclass(frozen=True)
class Run:
    """One (setting, seed) of a study.

    Attributes:
        setting_id: folder name of the setting, from its grid values (``robot-4ws-5__...``).
        seed: the run's seed; the repertoire and the arbitrator both use it.
        values: every setting key of the run (grid values, fixed values, overrides).
    """

    setting_id: str
    seed: int
    values: dict[str, Any] = field(hash=False, compare=False)

    @property
    def path(self) -> Path:
        """The run's folder inside the results folder."""
        return Path(self.setting_id) / f"seed-{self.seed:03d}"

    @property
    def approach(self) -> str:
        """``evorbc`` or ``standard``."""
        return self.values.get("approach", "evorbc")

    def recorded_settings(self) -> dict[str, Any]:
        """What identifies the run's result: its settings and seed (JSON-ready)."""
        return {**{k: self.values[k] for k in sorted(self.values)}, "seed": self.seed}


@dataclass(frozen=True)
class Study:
    """A parsed study file."""

    name: str
    title: str
    paper: str
    seeds: int
    grid: dict[str, list]
    fixed: dict[str, Any]
    exclude: list[dict[str, Any]]
    compare: list[dict[str, Any]]
    source: str
    figures: tuple[str, ...] = ()

    def settings(self) -> list[tuple[str, dict[str, Any]]]:
        """``(setting_id, values)`` of every grid combination that is not excluded."""
        keys = list(self.grid)
        out = []
        for combo in itertools.product(*(self.grid[k] for k in keys)):
            chosen = dict(zip(keys, combo, strict=True))
            if any(all(chosen.get(k) == v for k, v in ex.items()) for ex in self.exclude):
                continue
            values = {**self.fixed, **chosen}
            # Keep only the keys that mean something to the run's approach, so that a
            # run's recorded settings are exactly what it ran with.
            if values.get("approach", "evorbc") == "standard":
                unused = (*REPERTOIRE_KEYS, "mapping")
            else:
                unused = ("equal_budget",)
            values = {k: v for k, v in values.items() if k not in unused}
            out.append((setting_id(chosen), values))
        return out

    def check_runs(self, seeds: int, option: str) -> None:
        """Refuse more than :data:`~offline_evolution.bounds.STUDY_RUNS` runs, before listing them.

        Args:
            seeds: seeds per setting; ``option`` names where they came from.

        Raises:
            ConfigError: naming the study file, the count and what to lower.
        """
        runs = len(self.settings()) * seeds
        if runs > bounds.STUDY_RUNS:
            raise ConfigError(
                f"{self.source}: {len(self.settings()):,} settings x {seeds:,} seeds = "
                f"{runs:,} runs, more than the bound of {bounds.STUDY_RUNS:,} a study "
                f"(docs/design.md section 12); lower {option} or list fewer grid values"
            )

    def runs(
        self,
        seeds: int | None = None,
        generations: int | None = None,
        only: dict[str, Any] | None = None,
    ) -> list[Run]:
        """Every run, setting by setting, seeds 1..``seeds`` (default: the file's).

        Args:
            seeds: a reduced protocol's number of seeds.
            generations: a reduced protocol's NEAT generations (replaces the file's).
            only: keep the settings whose values match these (e.g. ``{"robot": "4ws-5"}``).
        """
        n = self.seeds if seeds is None else seeds
        self.check_runs(n, "seeds (or give --seeds)" if seeds is None else "--seeds")
        out = []
        seen: set[str] = set()
        for sid, values in self.settings():
            if only and any(values.get(k) != v for k, v in only.items()):
                continue
            if sid in seen:
                continue
            seen.add(sid)
            if generations is not None:
                values = {**values, "generations": generations}
            out.extend(Run(sid, seed, values) for seed in range(1, n + 1))
        return out


def setting_id(chosen: dict[str, Any]) -> str:
    """Folder name of a setting from its grid values: ``robot-4ws-5__approach-evorbc``."""
    return "__".join(f"{k}-{_text(v)}" for k, v in chosen.items())


def _text(value) -> str:
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, float):
        return repr(value)
    return str(value)


def studies_dir() -> Path:
    """``config/studies``."""
    return config_dir() / "studies"


def study_names() -> list[str]:
    """Names of the shipped studies."""
    return sorted(p.stem for p in studies_dir().glob("*.yaml"))


def load_study(name_or_path: str | os.PathLike) -> Study:
    """A shipped study by name, or a study file.

    Raises:
        ConfigError: one line naming the file and key.
    """
    text = str(name_or_path)
    path = Path(text)
    if not text.endswith((".yaml", ".yml")):
        path = studies_dir() / f"{text}.yaml"
        if not path.exists():
            raise ConfigError(
                f"no study called {text!r}; expected one of {', '.join(study_names())} "
                "or a study file (.yaml)"
            )
    data = load_yaml_mapping(path)
    return parse_study(data, str(path))


def parse_study(data: dict, source: str) -> Study:
    """Validate a study's mapping.

    Raises:
        ConfigError: naming ``source`` and the key.
    """
    unknown = set(data) - TOP_KEYS
    if unknown:
        raise ConfigError(
            f"{source}: unknown key {sorted(unknown)[0]!r}; expected {', '.join(sorted(TOP_KEYS))}"
        )
    name = data.get("study")
    if not isinstance(name, str) or not name or "/" in name:
        raise ConfigError(f"{source}: study must be a name (a non-empty string without '/')")
    seeds = data.get("seeds")
    if isinstance(seeds, bool) or not isinstance(seeds, int) or not 1 <= seeds <= bounds.SEEDS:
        raise ConfigError(
            f"{source}: seeds must be an integer from 1 to {bounds.SEEDS:,}, got {seeds!r}"
        )
    grid = data.get("grid")
    if not isinstance(grid, dict) or not grid:
        raise ConfigError(f"{source}: grid must be a mapping of setting keys to lists of values")
    for key, values in grid.items():
        if not isinstance(values, list) or not values:
            raise ConfigError(f"{source}: grid.{key} must be a non-empty list")
        for v in values:
            check_value(key, v, f"{source}: grid.{key}")
    # Counted before the combinations are listed: a grid of six 100-value lists is 10^12.
    combinations = math.prod(len(v) for v in grid.values())
    if combinations > bounds.STUDY_SETTINGS:
        raise ConfigError(
            f"{source}: grid has {combinations:,} combinations of settings, more than the "
            f"bound of {bounds.STUDY_SETTINGS:,} (docs/design.md section 12); list fewer values"
        )
    fixed = data.get("fixed", {}) or {}
    if not isinstance(fixed, dict):
        raise ConfigError(f"{source}: fixed must be a mapping of setting keys to values")
    for key, v in fixed.items():
        check_value(key, v, f"{source}: fixed.{key}")
        if key in grid:
            raise ConfigError(f"{source}: fixed.{key} is also a grid key")
    exclude = _combination_list(data.get("exclude", []), "exclude", grid, source)
    compare = data.get("compare", []) or []
    if not isinstance(compare, list) or not all(isinstance(c, dict) for c in compare):
        raise ConfigError(f"{source}: compare must be a list of mappings")
    figs = data.get("figures", []) or []
    if not isinstance(figs, list) or any(f not in FIGURES for f in figs):
        raise ConfigError(f"{source}: figures must be a list of {', '.join(FIGURES)}")
    study = Study(
        name=name,
        title=str(data.get("title", name)),
        paper=str(data.get("paper", "")),
        seeds=seeds,
        grid={k: list(v) for k, v in grid.items()},
        fixed=dict(fixed),
        exclude=exclude,
        compare=compare,
        source=source,
        figures=tuple(figs),
    )
    if not study.settings():
        raise ConfigError(f"{source}: exclude leaves no setting to run")
    return study


def _combination_list(value, key: str, grid: dict, source: str) -> list[dict]:
    if value is None:
        return []
    if not isinstance(value, list) or not all(isinstance(v, dict) and v for v in value):
        raise ConfigError(f"{source}: {key} must be a list of mappings of grid keys to values")
    for i, combo in enumerate(value):
        for k, v in combo.items():
            if k not in grid:
                raise ConfigError(f"{source}: {key}[{i}].{k} is not a grid key")
            if v not in grid[k]:
                raise ConfigError(f"{source}: {key}[{i}].{k} = {v!r} is not among grid.{k}")
    return list(value)


def check_value(key: str, value, where: str) -> None:
    """Check one setting value.

    Raises:
        ConfigError: ``where`` and what was expected.
    """
    from evorbc_ros.mapping import MAPPINGS
    from evorbc_ros.robots.registry import ROBOT_NAMES
    from offline_evolution.quality import METRICS
    from offline_evolution.repertoire.settings import ARCHIVES, VARIATIONS

    choices = {
        "approach": APPROACHES,
        "robot": ROBOT_NAMES,
        "metric": tuple(METRICS),
        "mapping": MAPPINGS,
        "archive": ARCHIVES,
        "variation": VARIATIONS,
    }
    if key not in SETTING_KEYS:
        raise ConfigError(
            f"{where}: unknown setting key; expected one of {', '.join(SETTING_KEYS)}"
        )
    if key in choices:
        if value not in choices[key]:
            raise ConfigError(f"{where}: {value!r} is not one of {', '.join(choices[key])}")
    elif key in ("bin_size", "eval_time"):
        if (
            isinstance(value, bool)
            or not isinstance(value, (int, float))
            or not math.isfinite(value)
            or value <= 0
        ):
            raise ConfigError(f"{where}: expected a positive number, got {value!r}")
    elif key == "equal_budget":
        if not isinstance(value, bool):
            raise ConfigError(f"{where}: expected true or false, got {value!r}")
    elif isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ConfigError(f"{where}: expected an integer >= 1, got {value!r}")
    elif value > COUNT_BOUNDS.get(key, value):
        raise ConfigError(
            f"{where}: expected an integer from 1 to {COUNT_BOUNDS[key]:,} "
            f"(docs/design.md section 12), got {value:,}"
        )
