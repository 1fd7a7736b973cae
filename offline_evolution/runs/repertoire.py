"""A repertoire run: MAP-Elites from the robot's settings to a checked, written file.

:func:`repertoire_run` is what ``evorbc-evolve repertoire`` does, without its console:
the checks before any work (outputs, settings, memory, budget), the search resumed from
its checkpoint, and the files written atomically before the checkpoint is deleted
(docs/design.md sections 6, 12, 13 and 15).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.registry import lookup
from offline_evolution.reporters import Reporter, Reporters
from offline_evolution.runs.command_line import option
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
CHECKPOINT_SUFFIX = ".checkpoint.npz"
#: Iterations between checkpoints unless the run says.
CHECKPOINT_EVERY = 100
#: The settings a run may override over its settings file (``MapElitesSettings`` keys).
SETTING_KEYS = (
    "robot",
    "metric",
    "bin_size",
    "eval_time",
    "initial_batch",
    "batch_size",
    "iterations",
    "seed",
    "archive",
    "variation",
)


@dataclass(frozen=True, kw_only=True)
class RepertoireRun:
    """What a repertoire run makes and from what (``evorbc-evolve repertoire``'s options).

    Unset (None) settings come from the settings file: ``config``, else the robot's
    (``config/repertoire/*.yaml``, paper Table I). Field order is the option order of the
    command line it is equivalent to (:func:`~.command_line.command_line`).
    """

    robot: str | None = None
    seed: int | None = None
    out: str  # the repertoire file (JSON)
    metric: str | None = None
    bin_size: float | None = None  # m, side of a square archive cell
    eval_time: float | None = None  # s, a primitive's evaluation time T
    initial_batch: int | None = None  # S_G
    batch_size: int | None = None  # S_B
    iterations: int | None = None  # I
    archive: str | None = None
    variation: str | None = None
    config: str | None = None  # settings file (YAML)
    plot: str | None = None  # picture of the repertoire (PNG)
    csv: str | None = None  # the primitives as CSV
    checkpoint: str | None = None  # default: OUT.checkpoint.npz
    checkpoint_every: int | None = None  # iterations (default CHECKPOINT_EVERY)
    restart: bool = False  # discard an existing checkpoint

    #: The subcommand it is.
    command = "repertoire"


@dataclass(frozen=True)
class RepertoireOutcome:
    """A finished repertoire run: the repertoire written to ``out``, seconds searched."""

    repertoire: Repertoire
    seconds: float  # wall time of the search in this process
    out: Path
    seed: int


def repertoire_run(
    run: RepertoireRun,
    reporters: Sequence[Reporter] = (),
    should_stop: Callable[[], bool] | None = None,
    workers: int | None = None,
) -> RepertoireOutcome:
    """Generate a repertoire, write it (and the plot and CSV asked for); print nothing.

    Args:
        run: the settings.
        reporters: told of every batch (``iteration_end``).
        should_stop: polled after every batch; True saves the checkpoint and raises
            ``Interrupted``. A ``frame.StopOnSignal`` catches Ctrl-C/SIGTERM meanwhile.
        workers: processes for PyBullet simulations (default: every core); the result
            does not depend on it.

    Raises:
        UserError: a bad output, setting or combination (one line); no primitive kept.
        ConfigError: a bad settings file.
        CheckpointError, Interrupted: as ``generate_repertoire``.
    """
    from offline_evolution.memory import check_repertoire_memory
    from offline_evolution.repertoire.settings import check_budget, load_settings, settings_path
    from sim_bridge.cli_support import check_output_file

    # Every output is checked before any work, so that a typo costs nothing.
    check_output_file(run.out, "--out")
    out = Path(run.out)
    checkpoint = default_checkpoint(out, run.checkpoint, CHECKPOINT_SUFFIX)
    written = {
        "--out": out,
        "--plot": run.plot,
        "--csv": run.csv,
        checkpoint_option(run.checkpoint): checkpoint,
    }
    check_distinct({**written, "--config": run.config})
    check_outputs(written)
    given = {key: option(key) for key in SETTING_KEYS if getattr(run, key) is not None}
    config = settings_path(run.config, run.robot)
    settings = load_settings(config, options=given, **{k: getattr(run, k) for k in SETTING_KEYS})
    check_repertoire_memory(
        settings,
        lookup(settings.robot).n_parameters,
        lambda key: given.get(key) or f"{config}: {key}",
    )
    check_budget(settings, config, given)
    with exclusive_outputs(written):
        search = _Search(run, settings, config, given, checkpoint)
        repertoire, seconds = search.go(Reporters(reporters), should_stop, workers)
        write_then_discard(checkpoint, lambda: _write(repertoire, out, run.plot, run.csv))
    return RepertoireOutcome(repertoire, seconds, out, settings.seed)


@dataclass(frozen=True)
class _Search:
    run: RepertoireRun
    settings: object  # MapElitesSettings
    config: Path
    given: dict
    checkpoint: Path

    def go(self, report: Reporters, should_stop, workers) -> tuple[Repertoire, float]:
        """Run MAP-Elites (resuming from the checkpoint); the repertoire and seconds taken."""
        from offline_evolution.repertoire.map_elites import CHECKPOINT_KIND, generate_repertoire
        from offline_evolution.repertoire.settings import SettingError, blame

        checkpoint = self.checkpoint
        if self.run.restart:
            restart_from_scratch(checkpoint, CHECKPOINT_KIND, "MAP-Elites checkpoint")
        start = time.perf_counter()
        with listening(should_stop):
            try:
                repertoire = generate_repertoire(
                    self.settings,
                    checkpoint=checkpoint,
                    checkpoint_every=self.run.checkpoint_every or CHECKPOINT_EVERY,
                    progress=report.iteration_end,
                    should_stop=should_stop,
                    workers=workers,
                    keep_checkpoint=True,
                )
            except SettingError as e:
                raise blame(e, self.config, self.given) from None
        elapsed = time.perf_counter() - start
        if len(repertoire) == 0:
            # A repertoire without primitives could drive nothing (and would not load).
            checkpoint.unlink(missing_ok=True)
            raise UserError(
                f"no primitive was kept after {repertoire.algorithm['evaluations']:,} "
                "evaluations (each one left the archive's range or was discarded); nothing "
                f"written to {self.run.out}; try a larger budget or another --metric"
            )
        return repertoire, elapsed


def _write(repertoire: Repertoire, out: Path, plot: str | None, csv: str | None) -> None:
    """Write the repertoire file and the plot and CSV asked for."""
    repertoire.save(out)
    if plot:
        from offline_evolution.plots.repertoire import plot_repertoire

        plot_repertoire(repertoire, plot)
    if csv:
        repertoire.to_csv(csv)
