"""An evaluation run: a controller on a suite of mazes, from many starts, perturbed.

:func:`evaluate_run` is what ``evorbc-evolve evaluate`` does, without its console: the
suite gathered (training mazes, files, folders, generated held-out mazes), the memory
estimate, the episodes from seeded random starts in perturbed worlds, the report written
atomically, and the suite's picture (docs/design.md section 21).
"""

from __future__ import annotations

import json
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.atomic_io import atomic_write_text
from evorbc_ros.config import ConfigError
from evorbc_ros.defaults import (
    PAPER_WITH_FILE,
    default_arbitrator,
    no_shipped_controller,
    paper_arbitrator,
    ships_controller,
)
from evorbc_ros.robots.registry import DEFAULT_ROBOT
from offline_evolution.mazes.held_out import HELD_OUT_SEED  # never trained on
from offline_evolution.reporters import Reporter, Reporters
from offline_evolution.runs.errors import UserError
from offline_evolution.runs.outputs import check_distinct, check_outputs, exclusive_outputs
from offline_evolution.runs.replay import check_task, controller_inputs

#: The suite word for the mazes the controller was trained on (its task's mazes).
PAPER = "paper"


@dataclass(frozen=True, kw_only=True)
class EvaluateRun:
    """What to evaluate on which suite (``evorbc-evolve evaluate``'s options)."""

    arbitrator: str | None = None  # default: the shipped one for robot
    robot: str = DEFAULT_ROBOT
    paper: bool = False  # the shipped paper-protocol controller
    repertoire: str | None = None  # default: the one it names, next to it, or the shipped
    mazes: Sequence[str] | None = None  # PAPER, maze names, files or folders
    generated: int | None = None  # mazes generated for the robot, added to the suite
    generated_seed: int = HELD_OUT_SEED
    starts: int = 20  # random starts per maze
    seed: int = 0  # of the starts and worlds
    perturb: str = "none"  # perturbation set: a shipped one or a file
    task: str | None = None  # task settings (episode time, sensors)
    plot: str | None = None  # picture of the suite (PNG)
    out: str | None = None  # the report (JSON)
    allow_mismatch: bool = False  # another repertoire fingerprint or sensor layout
    adapt: bool = False  # the suite again with the controller adapting onboard
    adapt_expected: str = "recorded"  # what observations are compared with (or settled)


@dataclass(frozen=True)
class EvaluateOutcome:
    """A finished evaluation: its report (as ``--out`` writes it) and what it ran."""

    report: dict  # per maze, overall and per episode
    path: Path  # of the arbitrator file
    arbitrator: ArbitratorFile
    perturbation: str  # the set's name


def evaluate_run(run: EvaluateRun, reporters: Sequence[Reporter] = ()) -> EvaluateOutcome:
    """Evaluate; write the report (``run.out``) and the suite's picture (``run.plot``).

    Args:
        run: the settings.
        reporters: told of warnings (a waived mismatch, perturbations the robot's
            simulation cannot model) and of episodes (``episodes_done``; legged robots).

    Raises:
        UserError: a bad option, combination or output (one line).
        ConfigError, RepertoireError, ArbitratorError: a bad input file.
    """
    written = {"--plot": run.plot, "--out": run.out}
    check_outputs(written)
    check_distinct(written)
    with exclusive_outputs(written):
        return _evaluate(run, Reporters(reporters))


@dataclass(frozen=True)
class SuiteRuns:
    """What :func:`run_suites` ran: the controller, the suite and its episodes."""

    arbitrator: ArbitratorFile
    path: Path  # of the arbitrator file
    repertoire: object  # the EvoRBC controller's Repertoire (None: standard)
    repertoire_path: object  # as the report records it
    base: object  # the arbitrator's task settings (episode time)
    task: object  # the suite's maze task (closed)
    perturbation: object  # the PerturbationSet
    suite: object  # SuiteResult without adaptation
    adapted: object  # SuiteResult with adaptation (``run.adapt``), or None
    settings: object  # the AdaptationSettings with ``run.adapt``, or None


def run_suites(run: EvaluateRun, report: Reporters) -> SuiteRuns:
    """The suite's episodes, and with ``run.adapt`` the same ones adapting (no outputs).

    Raises:
        UserError, ConfigError, RepertoireError, ArbitratorError: as :func:`evaluate_run`.
    """
    from offline_evolution.maze_task.evaluation import evaluate_suite
    from offline_evolution.maze_task.perturbation import load_perturbations

    perturbation = load_perturbations(run.perturb)
    arb, arb_path = load_arbitrator(run)
    repertoire, rep_path, base = controller_inputs(arb, arb_path, run, report)
    task = _suite_task(run, arb, base)
    for w in task.warnings:  # a maze of the suite scaled to fit the robot
        report.warning(w)
    try:
        check_task(task, arb, arb_path, repertoire, rep_path, run.allow_mismatch)
        controller = task.controller(arb.kind, repertoire, arb.mapping)
        adaptation = _adaptation(run, arb, task, repertoire)  # checked before any episode
        task.progress = report.episodes_done  # PyBullet suites take minutes
        try:
            suite = evaluate_suite(
                task, arb.network, controller, run.starts, run.seed, perturbation
            )
        except ValueError as e:
            raise UserError(f"--perturb {run.perturb}: {e}") from None
        adapted = settings = None
        if adaptation is not None:
            settings, arrays = adaptation
            task.adapt(arrays)
            try:
                adapted = evaluate_suite(
                    task, arb.network, controller, run.starts, run.seed, perturbation
                )
            finally:
                task.adapt(None)
    finally:
        task.close()
    return SuiteRuns(
        arb, arb_path, repertoire, rep_path, base, task, perturbation, suite, adapted, settings
    )


def _evaluate(run: EvaluateRun, report: Reporters) -> EvaluateOutcome:
    """:func:`evaluate_run` once its outputs are checked and locked."""
    runs = run_suites(run, report)
    arb, arb_path, rep_path, base = runs.arbitrator, runs.path, runs.repertoire_path, runs.base
    task, perturbation, suite = runs.task, runs.perturbation, runs.suite
    adapted = None
    if runs.adapted is not None:
        adapted = _adapted_section(run, runs.settings, runs.adapted, perturbation)
    if suite.not_applicable:
        report.warning(
            f"--perturb {perturbation.name}: {arb.robot}'s simulation cannot model "
            f"{', '.join(suite.not_applicable)}; applied: {', '.join(suite.applied) or 'nothing'}"
        )
    data = {
        "arbitrator": str(arb_path),
        "kind": arb.kind.name,
        "robot": arb.robot,
        "repertoire": rep_path,
        "mazes": [m.name for m in task.mazes],
        # Each maze's factor when one was scaled up to fit the robot (docs/design.md s. 21).
        **({"maze_scale": list(task.settings.maze_scale)} if task.settings.maze_scale else {}),
        "generated": (
            {"count": run.generated, "seed": run.generated_seed} if run.generated else None
        ),
        "starts_per_maze": run.starts,
        "seed": run.seed,
        "episode_time": base.episode_time,
        "perturbation": perturbation.as_dict(),
        "applied": list(suite.applied),
        "not_applicable": list(suite.not_applicable),
        "per_maze": suite.per_maze(),
        "overall": suite.overall(),
        # Per damaged wheel, leg or side, for a set with damage (docs/perturbations.md).
        **({"per_damage": suite.per_damage()} if perturbation.damage else {}),
        "episodes": [e.as_dict() for e in suite.episodes],
        **({"adaptation": adapted} if adapted else {}),
    }
    if run.out:
        atomic_write_text(run.out, json.dumps(data, indent=1) + "\n")
    if run.plot:
        _plot(task, suite, run.plot, f"{arb_path.name}, perturbations: {perturbation.name}")
    return EvaluateOutcome(data, arb_path, arb, perturbation.name)


def _adaptation(run: EvaluateRun, arb, task, repertoire):
    """``--adapt``: ``(settings, kernel arrays)`` of the controller adapting; None without.

    Raises:
        UserError: a standard controller, a robot whose episodes do not adapt, or
            ``--adapt-expected settled`` for a robot that is neither 4WS nor legged.
    """
    if not run.adapt:
        return None
    from offline_evolution.maze_task.adapting import task_adapting

    if not arb.kind.uses_repertoire:
        raise UserError("--adapt: adaptation corrects a repertoire; this is a standard controller")
    if not hasattr(task, "adapt"):
        raise UserError(f"--adapt: {arb.robot}'s episodes do not adapt yet (4WS, differential"
                        "-drive and legged robots do; docs/design/adaptation.md)")  # fmt: skip
    try:
        return task_adapting(task, repertoire, run.adapt_expected, arb.robot)
    except ValueError as e:
        raise UserError(f"--adapt-expected {run.adapt_expected}: {e}") from None


def _adapted_section(run, settings, suite, perturbation) -> dict:
    """The report's ``adaptation`` section of an adapted suite.

    The settings, the figures as without, and each episode as without (in the same order,
    so that its reach compares one to one).
    """
    from dataclasses import asdict

    return {
        "settings": asdict(settings),
        "expected": run.adapt_expected,
        "per_maze": suite.per_maze(),
        "overall": suite.overall(),
        **({"per_damage": suite.per_damage()} if perturbation.damage else {}),
        "episodes": [e.as_dict() for e in suite.episodes],
    }


def _suite_task(run: EvaluateRun, arb: ArbitratorFile, base):
    """The task of the suite (mazes generated into a folder that is gone once loaded)."""
    from offline_evolution.maze_task.base import MazeTaskSettings
    from offline_evolution.maze_task.task import CONTROL_PERIOD, make_task
    from offline_evolution.memory import check_replay_memory
    from sim_bridge.robots.base import control_steps

    with tempfile.TemporaryDirectory(prefix="evorbc-suite-") as tmp:
        names = suite_mazes(run.mazes, base.mazes, bool(run.generated))
        # Checked before the mazes are generated, which takes about 0.1 s each.
        check_replay_memory(
            (len(names) + (run.generated or 0)) * run.starts,
            control_steps(base.episode_time, CONTROL_PERIOD),
            len(arb.network.output_keys),
            arb.robot,
            f"episode_time {base.episode_time} s; --starts {run.starts}",
        )
        warning = ""
        if run.generated:
            files, warning = _generated_files(arb.robot, run.generated, run.generated_seed, tmp)
            names += files
        settings = MazeTaskSettings(tuple(names), base.episode_time, 1, base.sensors)
        try:
            task = make_task(settings, arb.robot)
        except ConfigError as e:
            raise UserError(f"--mazes: {e}") from None
        if warning:
            task.warnings.append(warning)  # the robot's maze scaled to size the generated
        return task


def suite_mazes(given: list[str] | None, trained: tuple[str, ...], generated: bool) -> list[str]:
    """Maze names and files of the suite, in order; folders give their ``*.yaml`` sorted."""
    if not given:
        return [] if generated else list(trained)
    out = []
    for item in given:
        if item == PAPER:
            out += trained
        elif Path(item).is_dir():
            files = sorted(str(f) for f in Path(item).glob("*.yaml"))
            if not files:
                raise UserError(f"--mazes {item}: the folder holds no .yaml maze files")
            out += files
        else:
            out.append(item)
    return out


def load_arbitrator(run: EvaluateRun) -> tuple[ArbitratorFile, Path]:
    """The arbitrator to evaluate and its path."""
    if run.arbitrator and run.paper:
        raise UserError(PAPER_WITH_FILE)
    if run.arbitrator:
        path = Path(run.arbitrator)
    else:
        if not ships_controller(run.robot):
            raise UserError(f"{no_shipped_controller(run.robot)}; pass --arbitrator FILE")
        path = (paper_arbitrator if run.paper else default_arbitrator)(run.robot)
    return ArbitratorFile.load(path), path


def _generated_files(robot: str, n: int, seed: int, folder: str) -> tuple[list[str], str]:
    """Generate ``n`` mazes of ``seed`` for ``robot`` into ``folder``.

    Returns:
        Their files, and the sizing's warning ("" unless the robot's maze was scaled).
    """
    from offline_evolution.mazes.files import save_maze
    from offline_evolution.mazes.generator import generate_maze, spec_for_robot

    spec = spec_for_robot(robot)
    files = []
    for k in range(n):
        maze = generate_maze(spec, seed, k).maze
        path = Path(folder) / f"{maze.name}.yaml"
        save_maze(maze, path)
        files.append(str(path))
    return files, spec.warning


def _plot(task, suite, path: str, title: str) -> None:
    from offline_evolution.plots.suite import plot_suite

    names = [m.name for m in task.mazes]
    paths = [
        [p for p, e in zip(suite.paths, suite.episodes, strict=True) if e.maze == n] for n in names
    ]
    reached = [[e.reached for e in suite.episodes if e.maze == n] for n in names]
    rows = {r["maze"]: r for r in suite.per_maze()}
    titles = [f"{n}: {rows[n]['reached']}/{rows[n]['episodes']} reached" for n in names]
    plot_suite(task.mazes, path, titles=titles, paths=paths, reached=reached, title=title)
