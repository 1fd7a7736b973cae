"""An arbitrator run: NEAT from a repertoire (or the standard baseline) to a written file.

:func:`arbitrator_run` is what ``evorbc-evolve arbitrator`` and ``standard`` do, without
their console: the checks before any work (outputs, held-out mazes and seeds, start
poses, NEAT settings, memory), the run settings resolved from the robot's files (paper
Table I) and the options, the evolution resumed from its checkpoint, and the arbitrator
file and fitness curve written atomically before the checkpoint is deleted
(docs/design.md sections 8, 12, 13, 15 and 22).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from evorbc_ros.controller_kinds import ControllerKind
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.registry import lookup
from offline_evolution.reporters import Reporter, Reporters
from offline_evolution.runs.errors import UserError
from offline_evolution.runs.frame import listening
from offline_evolution.runs.outputs import (
    check_distinct,
    check_outputs,
    checkpoint_option,
    default_checkpoint,
    exclusive_outputs,
    restart_from_scratch,
    write_then_discard,
)

#: The checkpoint's name after the output's.
CHECKPOINT_SUFFIX = ".checkpoint.json"


@dataclass(frozen=True, kw_only=True)
class ArbitratorRun:
    """What an arbitrator run makes and from what (``evorbc-evolve arbitrator``'s options).

    ``kind`` EVORBC needs ``repertoire`` (its robot is the repertoire's), STANDARD needs
    ``robot``. Unset (None) settings come from the run settings file: ``config``, else
    the robot's (``config/arbitrator/*.yaml``). Field order is the option order of the
    command line it is equivalent to (:func:`~.command_line.command_line`).
    """

    kind: ControllerKind
    repertoire: str | None = None  # repertoire file (EvoRBC)
    robot: str | None = None  # robot type (standard NEAT)
    seed: int = 0
    mapping: str | None = None  # EvoRBC's mapping function
    equal_budget: bool = False  # standard NEAT: + the robot's equal-budget generations
    generations: int | None = None
    out: str  # the arbitrator file (JSON)
    plot: str | None = None  # fitness curve (PNG; default OUT with .fitness.png)
    population: int | None = None  # in place of the NEAT file's pop_size
    hall_of_fame: int | None = None  # genomes kept for the post-selection
    post_samples: int | None = None  # random starts per maze in the post-selection
    config: str | None = None  # run settings (YAML)
    neat_config: str | None = None  # NEAT settings (neat-python INI)
    task: str | None = None  # task settings (YAML)
    episode_time: float | None = None  # s, in place of the task's episode_time
    checkpoint: str | None = None  # default: OUT.checkpoint.json
    checkpoint_every: int | None = None  # generations (default: the run settings')
    restart: bool = False  # discard an existing checkpoint
    keep_checkpoint: bool = False  # keep the finished run's, to continue it later
    init_from: str | None = None  # arbitrator file whose network seeds the population

    @property
    def command(self) -> str:
        """The subcommand it is (``arbitrator``, ``standard``)."""
        return self.kind.command


@dataclass(frozen=True)
class ArbitratorOutcome:
    """A finished arbitrator run: the result written to ``out``, its curve ``plot``."""

    result: object  # EvolutionResult
    robot: str
    generations: int
    out: Path
    plot: Path


@dataclass(frozen=True)
class _Outputs:
    """The files a run writes, and each by the option that names it (for messages)."""

    out: Path
    plot: Path
    checkpoint: Path
    files: dict  # option -> path

    @classmethod
    def of(cls, run: ArbitratorRun) -> _Outputs:
        """``run``'s outputs, checked: every one can be written (before any work)."""
        from sim_bridge.cli_support import check_output_file

        check_output_file(run.out, "--out")
        out = Path(run.out)
        plot = Path(run.plot) if run.plot is not None else out.with_name(out.stem + ".fitness.png")
        checkpoint = default_checkpoint(out, run.checkpoint, CHECKPOINT_SUFFIX)
        files = {
            "--out": out,
            "--plot" if run.plot is not None else "the default --plot": plot,
            checkpoint_option(run.checkpoint): checkpoint,
        }
        check_outputs(files)
        return cls(out, plot, checkpoint, files)


@dataclass(frozen=True)
class _Plan:
    """A run's resolved inputs, every check passed."""

    settings: object  # EvolutionSettings
    repertoire: Repertoire | None
    task_settings: object  # MazeTaskSettings
    initial_network: object  # NetworkSpec or None
    checkpoint_every: int
    outputs: _Outputs


def arbitrator_run(
    run: ArbitratorRun,
    reporters: Sequence[Reporter] = (),
    should_stop: Callable[[], bool] | None = None,
    workers: int | None = None,
) -> ArbitratorOutcome:
    """Evolve an arbitrator or a standard-NEAT controller; write its file and curve.

    Args:
        run: the settings.
        reporters: told of the run (``search_start`` with the ``EvolutionSettings``,
            then as :func:`~offline_evolution.arbitrator.evolve.evolve` tells them).
        should_stop: polled after every generation and post-evaluation batch; True
            saves the checkpoint and raises ``Interrupted``. A ``frame.StopOnSignal``
            catches Ctrl-C/SIGTERM meanwhile.
        workers: processes for PyBullet simulations (default: every core); the result
            does not depend on it.

    Raises:
        UserError: a bad output, setting or combination (one line).
        ConfigError, RepertoireError, ArbitratorError: a bad input file.
        CheckpointError, Interrupted: as ``evolve``.
    """
    from offline_evolution.arbitrator.evolve import CHECKPOINT_KIND, evolve

    report = Reporters(reporters)
    plan = _plan(run, report)
    checkpoint = plan.outputs.checkpoint
    with exclusive_outputs(plan.outputs.files):
        if run.restart:
            restart_from_scratch(checkpoint, CHECKPOINT_KIND, "NEAT evolution checkpoint")
        report.search_start(plan.settings)
        with listening(should_stop):
            result = evolve(
                plan.settings,
                plan.repertoire,
                checkpoint=checkpoint,
                checkpoint_every=plan.checkpoint_every,
                reporters=[report],
                should_stop=should_stop,
                workers=workers,
                repertoire_source=run.repertoire if plan.repertoire else "the repertoire",
                keep_checkpoint=True,  # deleted only once the files are written
                initial_network=plan.initial_network,
            )
        write_then_discard(
            checkpoint,
            lambda: _write(run, plan, result),
            discard=not run.keep_checkpoint,
        )
    settings, outputs = plan.settings, plan.outputs
    return ArbitratorOutcome(
        result, settings.robot, settings.generations, outputs.out, outputs.plot
    )


def _plan(run: ArbitratorRun, report: Reporter) -> _Plan:
    """Check everything and resolve the settings, before any work (warnings to ``report``)."""
    from evorbc_ros.config import config_dir
    from evorbc_ros.sensors import SensorLayout
    from offline_evolution.arbitrator.evolve import EvolutionSettings, file_sha256
    from offline_evolution.arbitrator.neat_config import load_neat_config
    from offline_evolution.arbitrator.settings import load_run_settings
    from offline_evolution.arbitrator.warm_start import load_initial_network, network_fingerprint
    from offline_evolution.maze_task.task import MazeTaskSettings

    # Every output is checked before any work, so that a typo costs nothing.
    outputs = _Outputs.of(run)
    repertoire = Repertoire.load(run.repertoire) if run.kind.uses_repertoire else None
    robot = repertoire.robot if repertoire else run.robot
    settings_file = load_run_settings(run.config, robot)
    generations = run.generations if run.generations is not None else settings_file.generations
    if not run.kind.uses_repertoire and run.equal_budget:
        generations += lookup(robot).equal_budget_generations
    neat_file = Path(run.neat_config) if run.neat_config else settings_file.neat_path()
    task_source = str(run.task or settings_file.task_path())
    task_settings = MazeTaskSettings.load(run.task or settings_file.task_path())
    if run.episode_time is not None:  # recorded with the task, which evaluate reads
        values = {**task_settings.as_dict(), "episode_time": run.episode_time}
        task_settings = MazeTaskSettings.from_dict(values, f"--episode-time {run.episode_time:g}")
    task_settings = _check_mazes(task_settings, run.seed, robot, task_source, report)
    # The NEAT settings, the task's sensor layout and a network to start from, before any
    # work.
    layout = SensorLayout.load(config_dir() / task_settings.sensors)
    n_outputs = run.kind.n_outputs(lookup(robot).n_parameters)
    neat_config = load_neat_config(neat_file, layout.n_inputs, n_outputs, run.population)
    mapping = (run.mapping or settings_file.mapping) if run.kind.uses_repertoire else None
    initial_network = None
    if run.init_from:
        initial_network = load_initial_network(
            run.init_from, robot, run.kind, mapping, layout, neat_config, str(neat_file)
        )
    # The post-selection's size: the run settings', or the options that replace them.
    selection = settings_file.selection()
    for key in ("hall_of_fame", "post_samples"):
        if getattr(run, key) is not None:
            selection[key] = getattr(run, key)
    settings = EvolutionSettings(
        kind=run.kind,
        robot=robot,
        generations=generations,
        seed=run.seed,
        neat_file=str(neat_file),
        neat_sha256=file_sha256(neat_file),
        task=task_settings.as_dict(),
        mapping=mapping,
        repertoire_fingerprint=repertoire.fingerprint() if repertoire else None,
        **selection,
        initial_network=network_fingerprint(initial_network) if initial_network else None,
        initial_network_file=run.init_from,
        population=run.population,
    )
    check_distinct(
        {
            **outputs.files,
            "--repertoire": run.repertoire if repertoire else None,
            "--config": run.config,
            "--neat-config": run.neat_config,
            "--task": run.task,
            "--init-from": run.init_from,
        }
    )
    _check_memory(run, settings_file, task_settings, neat_config, settings, task_source)
    every = run.checkpoint_every or settings_file.checkpoint_every
    return _Plan(settings, repertoire, task_settings, initial_network, every, outputs)


def _check_mazes(task_settings, seed: int, robot: str, source: str, report: Reporter):
    """The task settings with its mazes fitted to the robot; refuse held-out mazes and seeds.

    A maze the robot does not fit is scaled up to fit it (one ``report.warning`` line, and
    one when its own maze is scaled to size the generated mazes it trains on)
    and the scale recorded with the task, so that the tasks built from the recorded
    settings later say nothing again (docs/design.md section 21); a maze no scale fits is
    refused before any work. Held out: docs/design.md section 22.
    """
    from evorbc_ros.config import ConfigError
    from offline_evolution.maze_task.base import fit_task_mazes
    from offline_evolution.maze_task.training import check_training

    try:
        task_settings, task_mazes = fit_task_mazes(
            task_settings, lookup(robot).footprint_radius, robot, report.warning
        )
    except ConfigError as e:
        raise UserError(f"{source}: {e}") from None
    check_training(task_mazes, task_settings.training, seed, source)
    if task_settings.training is not None and task_settings.training.generated:
        from offline_evolution.mazes.generator import spec_for_robot

        try:
            sizing = spec_for_robot(robot).warning  # its maze scaled to size the generated
        except ConfigError as e:
            raise UserError(f"{source}: training: {e}") from None
        if sizing:
            report.warning(sizing)
    return task_settings


def _check_memory(run, settings_file, task_settings, neat_config, settings, source) -> None:
    """Refuse a run whose largest allocation would not fit in memory (before work)."""
    from offline_evolution.memory import check_evolution_memory

    snapshots = (
        settings.generations // settings_file.snapshot_every if settings_file.snapshot_every else 0
    )
    check_evolution_memory(
        task_settings,
        neat_config.pop_size,
        settings.robot,
        source,
        3 * settings.hall_of_fame + snapshots,
        settings.post_samples,
        settings_file.post_finalists,
        settings_file.post_final_samples,
        neat_source=settings.neat_file,
        run_source=str(run.config or lookup(settings.robot).settings_file("arbitrator")),
    )


def _write(run: ArbitratorRun, plan: _Plan, result) -> None:
    """Write the arbitrator file and its fitness curve."""
    from offline_evolution.arbitrator.evolve import arbitrator_file
    from offline_evolution.maze_task.task import make_task
    from offline_evolution.plots.fitness import plot_fitness_history

    settings = plan.settings
    task = make_task(plan.task_settings, settings.robot, workers=1)
    try:
        arb = arbitrator_file(
            result, task, plan.repertoire, run.repertoire if plan.repertoire else None
        )
        arb.save(plan.outputs.out)
    finally:
        task.close()
    plot_fitness_history(
        result.history,
        plan.outputs.plot,
        title=f"{run.kind.label}, {settings.robot}, seed {run.seed}",
    )
