"""A replay run: a controller in the mazes it was evolved for, per maze.

:func:`replay_run` is what ``evorbc-evolve replay`` does, without its console: the
controller's repertoire and task found and checked against it, the memory estimate, the
episodes from nominal or seeded random starts, and the pictures asked for. The controller
inputs and their checks are shared with :mod:`.evaluate`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from evorbc_ros.arbitrator import ArbitratorError, ArbitratorFile
from evorbc_ros.defaults import default_repertoire
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.registry import lookup
from offline_evolution.reporters import Reporter, Reporters
from offline_evolution.runs.errors import UserError
from offline_evolution.runs.outputs import check_distinct, check_outputs
from sim_bridge.robots.design import check_simulation, simulation_mismatch

#: How a user lets another repertoire fingerprint or sensor layout through.
WAIVER = "--allow-mismatch"


@dataclass(frozen=True, kw_only=True)
class ReplayRun:
    """What to replay and how (``evorbc-evolve replay``'s options)."""

    arbitrator: str  # arbitrator file
    repertoire: str | None = None  # default: the one it names, next to it, or the shipped
    maze: str = "all"  # one maze (name or file) or all of the arbitrator's
    task: str | None = None  # task settings (default: those the arbitrator records)
    start: str = "nominal"  # or "random", from seed
    seed: int = 0
    episodes: int = 1  # random starts per maze (start "random")
    plot: str | None = None  # trajectories (PNG)
    heatmap: str | None = None  # repertoire cells used (PNG; EvoRBC)
    allow_mismatch: bool = False  # another repertoire fingerprint or sensor layout


@dataclass(frozen=True)
class ReplayOutcome:
    """A finished replay: the controller, its repertoire and one outcome per episode."""

    arbitrator: ArbitratorFile
    path: Path  # of the arbitrator file
    repertoire: Repertoire | None
    repertoire_path: str | None
    outcomes: list  # ``EpisodeOutcome`` per episode, maze-major

    @property
    def mean_fitness(self) -> float:
        """Mean of the episodes' fitness (Eq. 5)."""
        return float(np.mean([o.fitness for o in self.outcomes]))

    @property
    def reached(self) -> int:
        """Episodes that reached the target."""
        return sum(o.reached for o in self.outcomes)


def replay_run(run: ReplayRun, reporters: Sequence[Reporter] = ()) -> ReplayOutcome:
    """Replay, then draw the trajectories and the selection heatmap asked for.

    Args:
        run: the settings.
        reporters: told of warnings (a waived mismatch, network outputs that were not
            finite) and of episodes as they finish (``episodes_done``; the legged robots).

    Raises:
        UserError: a bad option, combination or output (one line).
        ConfigError, RepertoireError, ArbitratorError: a bad input file.
    """
    from offline_evolution.maze_task.replay import replay
    from offline_evolution.maze_task.task import make_task

    report = Reporters(reporters)
    arb_path = Path(run.arbitrator)
    if run.episodes > 1 and run.start != "random":
        raise UserError("--episodes N needs N >= 1, and N > 1 needs --start random")
    written = {"--plot": run.plot, "--heatmap": run.heatmap}
    check_outputs(written)
    check_distinct(written)
    arb = ArbitratorFile.load(arb_path)
    if run.heatmap and not arb.kind.uses_repertoire:
        raise UserError("--heatmap needs an EvoRBC arbitrator (standard NEAT has no primitives)")
    repertoire, rep_path, settings = controller_inputs(arb, arb_path, run, report)
    recorded = arb.evolution.get("task")
    if run.maze != "all":
        settings = _one_maze(settings, run.maze)
    where = run.task or (f"{arb_path}: evolution.task" if recorded else "the default task")
    _check_memory(run, arb, settings, where)
    task = make_task(settings, arb.robot)
    for w in task.warnings:  # a maze scaled to fit the robot (a --task or --maze not recorded)
        report.warning(w)
    try:
        check_task(task, arb, arb_path, repertoire, rep_path, run.allow_mismatch, where)
        task.progress = report.episodes_done  # many PyBullet episodes take minutes
        outcomes, result = replay(arb, task, _starts(run, task), repertoire)
    finally:
        task.close()
    for o in outcomes:
        if o.stopped_cycles:
            report.warning(
                f"{o.maze}: the network's outputs were not finite in {o.stopped_cycles} of "
                f"{round(o.time / task.dt)} cycles; the robot stood still in those (no primitive)"
            )
    _draw(run, task, outcomes, result, arb, repertoire)
    return ReplayOutcome(arb, arb_path, repertoire, rep_path, outcomes)


def _one_maze(settings, maze: str):
    """``settings`` for the one maze ``maze``, keeping the scale recorded for it, if any."""
    from offline_evolution.maze_task.base import MazeTaskSettings

    scale = None
    if settings.maze_scale is not None and maze in settings.mazes:
        scale = (settings.maze_scale[settings.mazes.index(maze)],)
    return MazeTaskSettings((maze,), settings.episode_time, 1, settings.sensors, maze_scale=scale)


def _check_memory(run: ReplayRun, arb: ArbitratorFile, settings, where: str) -> None:
    """Refuse a replay whose recorded paths would not fit in memory (before work)."""
    from offline_evolution.maze_task.task import CONTROL_PERIOD
    from offline_evolution.memory import check_replay_memory
    from sim_bridge.robots.base import control_steps

    per_maze = run.episodes * settings.samples_per_maze if run.start == "random" else 1
    check_replay_memory(
        len(settings.mazes) * per_maze,
        control_steps(settings.episode_time, CONTROL_PERIOD),
        len(arb.network.output_keys),
        arb.robot,
        f"episode_time {settings.episode_time} s in {where}",
    )


def _starts(run: ReplayRun, task) -> np.ndarray:
    """The episodes' start poses (n, 4): maze index, x m, y m, heading rad."""
    if run.start != "random":
        return task.nominal_starts()
    rng = np.random.default_rng(run.seed)
    starts = np.concatenate([task.sample_starts(rng) for _ in range(run.episodes)])
    # maze-major, so each maze's episodes are together in the report
    return starts[np.argsort(starts[:, 0], kind="stable")]


def _draw(run: ReplayRun, task, outcomes, result, arb, repertoire) -> None:
    """The trajectories and the selection heatmap, if asked for."""
    title = Path(run.arbitrator).name
    if run.plot:
        from offline_evolution.plots.replay import plot_trajectories

        plot_trajectories(task, outcomes, result, run.plot, title=title)
    if run.heatmap:
        from offline_evolution.plots.selection import plot_selection

        plot_selection(repertoire, arb.mapping, result, run.heatmap, title=title)


def resolve_repertoire(
    arb: ArbitratorFile, arb_path: Path, given: str | None, allow_mismatch: bool
) -> tuple[Repertoire, str, list[str]]:
    """The repertoire to replay an EvoRBC arbitrator with, its path and any warnings."""
    if given:
        candidates = [Path(given)]
    else:
        named = (arb.repertoire or {}).get("file")
        candidates = [arb_path.with_name(named)] if named else []
        candidates.append(default_repertoire(arb.robot))
        candidates = [c for c in candidates if c.exists()]
        if not candidates:
            raise UserError(f"{arb_path}: cannot find its repertoire; pass --repertoire FILE")
    errors = []
    for path in candidates:
        repertoire = Repertoire.load(path)
        try:
            warnings = arb.check_repertoire(repertoire, str(path), allow_mismatch, WAIVER)
            return repertoire, str(path), warnings
        except ArbitratorError as e:
            errors.append(str(e))
    raise UserError(
        errors[0]
        if given
        else f"{arb_path}: none of {', '.join(map(str, candidates))} is the repertoire "
        "it was evolved with; pass --repertoire FILE"
    )


def controller_inputs(arb: ArbitratorFile, arb_path: Path, run, report: Reporter):
    """``(repertoire or None, its path or None, task settings)`` to run ``arb`` with.

    The repertoire as :func:`resolve_repertoire` finds it (``run.repertoire``,
    ``run.allow_mismatch``; warnings go to ``report``), the task from ``run.task``, else
    the one the arbitrator records, else the robot's default.
    """
    from offline_evolution.maze_task.base import MazeTaskSettings

    repertoire, rep_path, warnings = None, None, []
    if arb.kind.uses_repertoire:
        repertoire, rep_path, warnings = resolve_repertoire(
            arb, arb_path, run.repertoire, run.allow_mismatch
        )
    for w in warnings:
        report.warning(w)
    recorded = arb.evolution.get("task")
    if run.task:
        settings = MazeTaskSettings.load(run.task)
    elif recorded:
        settings = MazeTaskSettings.from_dict(recorded, f"{arb_path}: evolution.task")
    else:
        settings = MazeTaskSettings.load(lookup(arb.robot).settings_file("task"))
    return repertoire, rep_path, settings


def check_task(
    task, arb, arb_path: Path, repertoire, rep_path, allow_mismatch: bool, where: str = ""
) -> None:
    """Refuse a task whose simulated robot or sensor layout is not ``arb``'s.

    The robot as :func:`check_design` compares it; the layout unless ``allow_mismatch``.
    ``where`` names the task's file (a refusal then starts with it, and says which
    arbitrator the layout was compared with).
    """
    check_design(task.describe(), arb, arb_path, repertoire, rep_path)
    try:
        arb.check_sensors(task.layout, task.settings.sensors, allow_mismatch, WAIVER)
    except ArbitratorError as e:
        raise UserError(f"{where}: sensors: {e} ({arb_path})" if where else str(e)) from None


def check_design(
    simulation: dict | None,
    arb: ArbitratorFile,
    arb_path: Path,
    repertoire: Repertoire | None,
    rep_path: str | None,
) -> None:
    """Refuse files evolved for another simulated robot than the task's ``simulation``.

    Like ``evorbc-sim``'s check: a repertoire's primitives, or a controller, evolved with
    other servos, legs or physics would be replayed on a robot they were never tried on.
    """
    if repertoire is not None:
        check_simulation(repertoire, simulation, rep_path)
    mismatch = simulation_mismatch(arb.evolution.get("simulation"), simulation, "the arbitrator")
    if mismatch:
        raise UserError(f"{arb_path}: was evolved for a different robot ({mismatch})")
