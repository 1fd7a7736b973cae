"""Run-level settings of arbitrator evolution (``config/arbitrator/*.yaml``)."""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass
from pathlib import Path

from evorbc_ros.config import ConfigError, build_settings, config_dir, load_yaml_mapping, setting
from evorbc_ros.mapping import MAPPINGS
from evorbc_ros.robots.registry import DEFAULT_ROBOT, lookup
from evorbc_ros.settings_paths import resolve_beside
from offline_evolution import bounds
from offline_evolution.arbitrator.selection import RULES


@dataclass(frozen=True)
class ArbitratorRunSettings:
    """Defaults of ``evorbc-evolve arbitrator`` and ``standard`` for a robot."""

    generations: int = setting(doc="NEAT generations", minimum=1, maximum=bounds.GENERATIONS)
    mapping: str = setting("polar", doc="mapping function", choices=MAPPINGS)
    neat: str = setting("neat/4ws.ini", doc="NEAT settings file, from this file's folder")
    task: str = setting("tasks/maze-4ws.yaml", doc="task settings file, from this file's folder")
    checkpoint_every: int = setting(10, doc="generations between checkpoints", minimum=1)
    hall_of_fame: int = setting(25, doc="genomes kept for the post-evaluation", minimum=1)
    post_samples: int = setting(
        10,
        doc="post-evaluation draws of the task's random starts (samples_per_maze a maze each)",
        minimum=0,
    )
    post_rule: str = setting(
        "mean", doc="how the post-evaluation picks the controller to write", choices=RULES
    )
    nominal_watch: int = setting(
        0,
        doc="each generation's best genomes also run from every nominal start; "
        "those that reach join the hall of fame",
        minimum=0,
    )
    snapshot_every: int = setting(
        0,
        doc="the champion of every N-th generation joins the hall of fame for good, so that "
        "the post-evaluation chooses from the whole run (0: none)",
        minimum=0,
    )

    post_finalists: int = setting(
        0,
        doc="the post-evaluation's best N candidates (by post_rule) run post_final_samples "
        "more draws, and the rule picks among them over both rounds (0: one round)",
        minimum=0,
    )
    post_final_samples: int = setting(
        0, doc="the finalists' further draws of the task's random starts", minimum=0
    )

    def selection(self) -> dict:
        """The keys that choose the genome written (``EvolutionSettings`` fields)."""
        return {
            "hall_of_fame": self.hall_of_fame,
            "post_samples": self.post_samples,
            "post_rule": self.post_rule,
            "nominal_watch": self.nominal_watch,
            "snapshot_every": self.snapshot_every,
            "post_finalists": self.post_finalists,
            "post_final_samples": self.post_final_samples,
        }

    def neat_path(self) -> Path:
        """The NEAT settings file."""
        return _resolve(self.neat)

    def task_path(self) -> Path:
        """The task settings file."""
        return _resolve(self.task)


def _resolve(name: str) -> Path:
    path = Path(name)
    return path if path.is_absolute() or path.exists() else config_dir() / name


def load_run_settings(
    path: str | os.PathLike | None = None, robot: str = DEFAULT_ROBOT
) -> ArbitratorRunSettings:
    """Settings from ``path``, by default the arbitrator settings file of ``robot``.

    Relative ``neat`` and ``task`` paths are from this file's folder, so a robot in its
    own package ships its settings together (docs/your-robot.md); one found only where
    they were taken from before (the working directory, then ``config/``) still works,
    with a deprecation line (:func:`~evorbc_ros.settings_paths.resolve_beside`).
    """
    if path is None:
        path = lookup(robot).settings_file("arbitrator")
    values = load_yaml_mapping(path)
    settings = build_settings(ArbitratorRunSettings, values, str(path))
    if (settings.post_finalists > 0) != (settings.post_final_samples > 0):
        # One without the other would run one round and say nothing.
        raise ConfigError(
            f"{path}: post_finalists and post_final_samples go together: both above 0 for "
            f"a second post-selection round, or both 0 (got {settings.post_finalists} and "
            f"{settings.post_final_samples})"
        )
    old = (Path.cwd(), config_dir())
    beside = {
        key: resolve_beside(getattr(settings, key), path, key, old, config_dir())
        for key in ("neat", "task")
        if key in values
    }
    settings = dataclasses.replace(settings, **beside)
    # The files it refers to, checked here so that an error names this file and key.
    for key, target in (("neat", settings.neat_path()), ("task", settings.task_path())):
        if not target.is_file():
            raise ConfigError(
                f"{path}: {key}: no such file {target} (relative paths are from this file's folder)"
            )
    return settings
