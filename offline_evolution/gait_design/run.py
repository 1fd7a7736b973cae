"""A gait design search from a settings file to a new settings file (``design-gait``)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from evorbc_ros.atomic_io import atomic_write_text
from evorbc_ros.config import load_yaml_mapping
from offline_evolution.gait_design.maze_needs import MazeNeeds, maze_needs
from offline_evolution.gait_design.objective import FORMULA, Budget
from offline_evolution.gait_design.search import DesignSearch, SearchResult
from offline_evolution.gait_design.space import DesignSpace
from offline_evolution.runs.errors import UserError


def _rounded(measures: dict) -> dict:
    return {k: (round(v, 4) if isinstance(v, float) else v) for k, v in measures.items()}


def record(
    result: SearchResult, space: DesignSpace, seed: int, budget: str, needs: MazeNeeds
) -> dict:
    """The ``design_search:`` record of the written settings file."""
    old = space.current()
    return {
        "command": "evorbc-evolve design-gait",
        "seed": seed,
        "budget": budget,
        "objective": FORMULA,
        "maze": _rounded(needs.as_dict()),
        "score": round(result.chosen_validation.score, 4),
        "measures": _rounded(result.chosen_validation.measures.as_dict()),
        "search_score": round(result.chosen_search.score, 4),
        "candidates_evaluated": len(result.candidates),
        "replaced": {
            "servo.gain": old["gain"],
            "gait.frequency_hz": old["frequency_hz"],
            "physics.rate_hz": old["rate_hz"],
            "ranges_deg": space.ranges_deg(old),
            "score": round(result.current_validation.score, 4),
            "measures": _rounded(result.current_validation.measures.as_dict()),
        },
    }


def legged_settings(path: Path) -> tuple[str, dict]:
    """The text and mapping of a legged robot's settings file.

    Raises:
        UserError: no such file, or not a legged robot's settings.

    """
    if not path.is_file():
        raise UserError(f"{path}: no such settings file")
    data = load_yaml_mapping(path)
    if "oscillators" not in data or "joints" not in data:
        raise UserError(
            f"{path}: not a legged robot's settings file (no oscillators/joints); "
            "design-gait designs the gait of a robot of docs/legged.md"
        )
    return path.read_text(encoding="utf-8"), data


def design_gait(
    settings: Path,
    out: Path,
    seed: int,
    budget_name: str,
    budget: Budget,
    checkpoint: Path | None = None,
    restart: bool = False,
    every: int = 1,
    progress: Callable[[str], None] = print,
    should_stop: Callable[[], bool] = lambda: False,
) -> SearchResult:
    """Search ``settings``' gait design and write it to ``out``.

    Args:
        settings, out: the settings file read and the one written (may be the same).
        seed: of the random primitives, the Sobol scramble and the refinement.
        budget_name, budget: the budget (its name is recorded).
        checkpoint: the JSON checkpoint (default ``OUT.checkpoint.json``); removed once
            ``out`` is written.
        restart: discard an existing checkpoint first.
        every: designs scored between checkpoints.
        progress: called with each progress line.
        should_stop: polled between designs.

    Raises:
        UserError, ConfigError, CheckpointError: one line each.
        Interrupted: ``should_stop`` said stop; the checkpoint holds every design scored.

    """
    text, data = legged_settings(settings)
    space = DesignSpace.of(data, settings)
    checkpoint = checkpoint or out.with_name(out.name + ".checkpoint.json")
    needs = maze_needs(space.settings)
    progress(
        f"{space.settings.name}: searching servo gain 2-45/s, gait frequency "
        f"{0.4 * space.settings.gait.frequency:g}-{2 * space.settings.gait.frequency:g} Hz, "
        f"physics {', '.join(f'{r:g}' for r in space.rates)} Hz, ranges "
        + ", ".join(f"{g} x0.2-{m:g}" for g, m in zip(space.groups, space.scale_max, strict=True))
        + f"; {budget_name} budget, seed {seed}; maze {needs.maze}: {needs.path:.2f} m of path "
        f"in {needs.episode_time:g} s needs {needs.required_speed:.2f} m/s, switching in a "
        f"{needs.room:.2f} m room"
    )
    search = DesignSearch(
        space, text, budget, seed, needs, checkpoint, progress, should_stop, every
    )
    search.load(restart)
    result = search.run()
    from offline_evolution.gait_design.settings_file import design_text

    new = design_text(text, space, result.chosen,
                      record(result, space, seed, budget_name, needs), settings, out)  # fmt: skip
    atomic_write_text(out, new)
    checkpoint.unlink(missing_ok=True)
    kept = "kept the current design" if result.chosen == space.current() else "chose a new design"
    progress(
        f"{kept}: score {result.chosen_validation.score:.3f} on fresh primitives (current "
        f"design {result.current_validation.score:.3f}); best searched design "
        f"{result.best_searched.score:.3f} against the current "
        f"{result.current_search.score:.3f} on the search's primitives; "
        f"{len(result.candidates)} designs scored; wrote {out}"
    )
    return result
