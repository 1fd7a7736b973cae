"""Running a recipe: each step in order, in this process, resumable, then the verdicts.

A step runs the run of the ``evorbc-evolve`` subcommand it stands for (``repertoire``,
``arbitrator``: :mod:`offline_evolution.runs`), called in this process with the settings
the recipe gives, so it makes what that command makes: the same checks before any work,
the same checkpoints, locks and atomic writes, the same progress lines. Its output and
checkpoint are the command's defaults in the output folder (``OUT/<out>`` and
``OUT/<out>.checkpoint.*``), so:

* a step whose output exists and whose checkpoint does not is finished and is skipped (a
  command writes its output atomically, then deletes its checkpoint);
* an interrupted step resumes from its checkpoint when the recipe is run again.

The output folder records the recipe and budget it holds (``recipe-run.json``); a run of
another recipe or budget is refused there, so a small run's files never pass for a full
run's. It also records each step's wall and CPU time, summed over the runs that resumed
it (``recipe-times.json``): a profile's time per stage, as ``bench/bench_profiles.py``
reports it.
"""

from __future__ import annotations

import contextlib
import json
import resource
import shutil
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

from evorbc_ros.atomic_io import atomic_path, atomic_write_text
from evorbc_ros.config import ConfigError
from offline_evolution.recipes import budget as budgets
from offline_evolution.recipes import robot_steps
from offline_evolution.recipes.digest import Verdict
from offline_evolution.recipes.spec import (
    ArbitratorStep,
    CopyStep,
    DesignGaitStep,
    Recipe,
    RepertoireStep,
    RobotFromUrdfStep,
    SettledStep,
)
from offline_evolution.runs import arbitrator as arbitrator_runs
from offline_evolution.runs import repertoire as repertoire_runs

#: The file in an output folder that says which recipe and budget it holds.
STATE_FILE = "recipe-run.json"
#: Each step's time in an output folder: {step: {"wall_s", "cpu_s", "runs"}}.
TIMES_FILE = "recipe-times.json"
#: Checkpoint suffix of each kind of step (the runs' defaults).
CHECKPOINT_SUFFIX = {
    "repertoire": repertoire_runs.CHECKPOINT_SUFFIX,
    "arbitrator": arbitrator_runs.CHECKPOINT_SUFFIX,
    "design-gait": robot_steps.DESIGN_CHECKPOINT_SUFFIX,
}


@dataclass(frozen=True)
class StepOutcome:
    """What became of one step: its output and, at the full budget, its verdict."""

    step: str
    out: Path
    ran: bool  # False: found finished and skipped
    verdict: Verdict | None


def run_recipe(
    recipe: Recipe,
    out: Path,
    budget: str = "full",
    workers: int | None = None,
    quiet: bool = False,
    say: Callable[[str], None] | None = None,
) -> list[StepOutcome]:
    """Run every step of ``recipe`` into the folder ``out`` at ``budget``.

    Args:
        out: the output folder (created); a rerun resumes what is there.
        budget: ``full`` or ``small`` (:mod:`.budget`).
        workers: processes for PyBullet simulations (results do not depend on it).
        quiet: no per-generation or per-batch lines from the steps.
        say: where the recipe's own lines go (default: stderr).

    Raises:
        UserError: a step failed or was interrupted (its message says how to resume).
        ConfigError: ``out`` holds another recipe's or budget's run.
    """
    say = say or (lambda line: print(line, file=sys.stderr))
    out.mkdir(parents=True, exist_ok=True)
    _claim(out, recipe, budget)
    outcomes = []
    for i, step in enumerate(recipe.steps, 1):
        target = out / step.out
        head = f"[{i}/{len(recipe.steps)}] {step.step} ({step.run}) -> {target}"
        if _finished(step, target):
            say(f"{head}: done before, skipped")
            ran = False
        else:
            say(f"{head}: running")
            with _timed(out, step.step) as took:
                _run_step(recipe, step, out, budget, workers, quiet, say)
            say(f"{head}: done in {took[0] / 60:.1f} min (CPU {took[1] / 60:.1f} min)")
            ran = True
        verdict = None
        if budget == "full" and step.run in ("repertoire", "arbitrator", "copy", "settled"):
            verdict = Verdict.of(
                target, step.sha256, step.content_sha256, step.recipe_content_sha256, step.shipped
            )
            say(f"[{i}/{len(recipe.steps)}] {step.step}: {verdict.text}")
        outcomes.append(StepOutcome(step.step, target, ran, verdict))
    return outcomes


def _cpu_seconds() -> float:
    """CPU time (s) of this process and of its worker processes that have ended."""
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + children.ru_utime + children.ru_stime


@contextlib.contextmanager
def _timed(out: Path, step: str):
    """Add the block's wall and CPU time to ``step``'s in :data:`TIMES_FILE`.

    Also when it is interrupted, so that a resumed step's time is the sum of its runs.
    Yields a list that holds [wall s, CPU s] once the block ends.
    """
    took = [0.0, 0.0]
    wall, cpu = time.perf_counter(), _cpu_seconds()
    try:
        yield took
    finally:
        took[:] = time.perf_counter() - wall, _cpu_seconds() - cpu
        path = out / TIMES_FILE
        try:
            times = json.loads(path.read_text()) if path.is_file() else {}
        except (OSError, ValueError):
            times = {}  # a damaged record of times loses nothing a run needs
        held = times.get(step) if isinstance(times.get(step), dict) else {}
        try:
            row = {
                "wall_s": round(float(held.get("wall_s", 0)) + took[0], 1),
                "cpu_s": round(float(held.get("cpu_s", 0)) + took[1], 1),
                "runs": int(held.get("runs", 0)) + 1,
            }
        except (TypeError, ValueError):
            row = {"wall_s": round(took[0], 1), "cpu_s": round(took[1], 1), "runs": 1}
        times[step] = row
        atomic_write_text(path, json.dumps(times, indent=1) + "\n")


def _claim(out: Path, recipe: Recipe, budget: str) -> None:
    """Record in ``out`` the recipe and budget it holds; refuse another's folder."""
    state = {"recipe": recipe.as_dict(), "budget": budget}
    path = out / STATE_FILE
    if path.exists():
        try:
            held = json.loads(path.read_text())
        except (OSError, ValueError) as e:
            raise ConfigError(f"{path}: cannot read it ({e}); choose another --out") from None
        if _what_runs(held) != _what_runs(state):
            what = held.get("recipe", {}).get("recipe") if isinstance(held, dict) else None
            was = f"{what!r} at the {held.get('budget')} budget" if what else "another run"
            raise ConfigError(
                f"{out} holds {was}, not this recipe at the {budget} budget; choose another --out"
            )
        return
    atomic_write_text(path, json.dumps(state, indent=1) + "\n")


#: Step keys that only state what the shipped file is: editing them changes no output.
VERDICT_KEYS = ("sha256", "content_sha256", "recipe_content_sha256", "note", "shipped")


def _what_runs(state) -> object:
    """A folder's recorded state without :data:`VERDICT_KEYS` (what decides its files).

    Keys left at None are dropped too: a step key added in a later version (None unless
    given) does not make a folder written before it another recipe's.
    """
    try:
        steps = [
            {k: v for k, v in step.items() if k not in VERDICT_KEYS and v is not None}
            for step in state["recipe"]["steps"]
        ]
        return {**state, "recipe": {**state["recipe"], "steps": steps}}
    except (KeyError, TypeError, AttributeError):
        return state


def _finished(step, target: Path) -> bool:
    """Whether the step wrote its output and left no checkpoint to resume."""
    suffix = CHECKPOINT_SUFFIX.get(step.run)
    checkpoint = target.with_name(target.name + suffix) if suffix else None
    return target.is_file() and not (checkpoint and checkpoint.exists())


def _run_step(recipe: Recipe, step, out: Path, budget: str, workers, quiet: bool, say) -> None:
    from offline_evolution.runs import terminal

    target = out / step.out
    if isinstance(step, RepertoireStep | ArbitratorStep):
        robot_steps.register_robots(recipe, out)
    if isinstance(step, RobotFromUrdfStep):
        robot_steps.run_robot_from_urdf(step, out, say)
    elif isinstance(step, DesignGaitStep):
        robot_steps.run_design_gait(recipe, step, out, budget, say)
    elif isinstance(step, CopyStep):
        source = out / recipe.step(step.source).out
        with atomic_path(target) as tmp:
            shutil.copyfile(source, tmp)
    elif isinstance(step, RepertoireStep):
        run = _repertoire_run(step, robot_steps.robot_name(recipe, step), budget, target)
        terminal.repertoire(run, workers, quiet)
    elif isinstance(step, ArbitratorStep):
        terminal.arbitrator(_arbitrator_run(recipe, step, out, budget, target), workers, quiet)
    elif isinstance(step, SettledStep):
        from offline_evolution.runs.settled import write_settled

        write_settled(
            step.repertoire_file or str(out / recipe.step(step.repertoire).out), str(target)
        )
    else:  # pragma: no cover - the loader knows no other kind
        raise ConfigError(f"{recipe.path}: step {step.step}: unknown kind {step.run!r}")


def _repertoire_run(step: RepertoireStep, robot: str, budget: str, target: Path):
    """The ``RepertoireRun`` of ``step`` for ``robot`` at ``budget``, written to ``target``."""
    from offline_evolution.runs.repertoire import RepertoireRun

    run = RepertoireRun(
        robot=robot,
        config=step.settings,
        seed=step.seed,
        iterations=step.iterations,
        initial_batch=step.initial_batch,
        batch_size=step.batch_size,
        archive=step.archive,
        variation=step.variation,
        out=str(target),
    )
    return replace(run, **budgets.SMALL_REPERTOIRE) if budget == "small" else run


def _arbitrator_run(recipe: Recipe, step: ArbitratorStep, out: Path, budget: str, target: Path):
    """The ``ArbitratorRun`` of ``step`` at ``budget``, written to ``target``."""
    from evorbc_ros.controller_kinds import EVORBC
    from offline_evolution.runs.arbitrator import ArbitratorRun

    files = {"config": step.settings, "neat_config": step.neat, "task": step.task}
    generations = step.generations
    if budget == "small":
        folder = out / "small-settings" / step.step
        files = budgets.small_arbitrator_files(step.settings, step.neat, step.task, folder)
        generations = budgets.SMALL_GENERATIONS
    init = step.init_from_file or (
        str(out / recipe.step(step.init_from).out) if step.init_from else None
    )
    repertoire = step.repertoire_file or str(out / recipe.step(step.repertoire).out)
    episode_time = None
    if step.robot_episode_time and budget != "small":  # the small budget's tasks are short
        from evorbc_ros.repertoire import Repertoire
        from evorbc_ros.robots.registry import lookup

        episode_time = lookup(Repertoire.load(repertoire).robot).episode_time
    return ArbitratorRun(
        kind=EVORBC,
        repertoire=repertoire,
        seed=step.seed,
        generations=generations,
        out=str(target),
        **{key: str(path) for key, path in files.items() if path is not None},
        episode_time=episode_time,
        init_from=init,
    )
