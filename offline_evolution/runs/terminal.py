"""The repertoire and arbitrator runs as a terminal shows them.

One place for what ``evorbc-evolve repertoire``/``arbitrator``/``standard``, a study's
worker process and a recipe's steps print: the console reporters, Ctrl-C finishing the
current step (:mod:`.frame`), and the summary line on stdout. Each returns the exit
status, 0; errors are raised as ``UserError`` and the like for the caller's frame.
"""

from __future__ import annotations

from offline_evolution.runs.arbitrator import ArbitratorRun, arbitrator_run
from offline_evolution.runs.console import (
    GenerationPrinter,
    IterationPrinter,
    PostEvaluationPrinter,
    WarningPrinter,
)
from offline_evolution.runs.frame import StopOnSignal, explained
from offline_evolution.runs.repertoire import RepertoireRun, repertoire_run


def repertoire(run: RepertoireRun, workers: int | None = None, quiet: bool = False) -> int:
    """Run ``run`` with progress lines (none if ``quiet``); print its summary line."""
    reporters = [] if quiet else [IterationPrinter()]
    with explained("iteration"):
        done = repertoire_run(run, reporters, StopOnSignal("batch"), workers)
    rep, s = done.repertoire, done.repertoire.summary()
    print(
        f"{rep.robot} repertoire: {s['count']} primitives, mean quality "
        f"{s['mean_quality']:.3f}, QD-score {s['qd_score']:.1f}, "
        f"{rep.algorithm['evaluations']:,} evaluations in {done.seconds:.1f} s "
        f"(seed {done.seed}) -> {done.out}"
    )
    return 0


def arbitrator(run: ArbitratorRun, workers: int | None = None, quiet: bool = False) -> int:
    """Run ``run`` with a line per generation (none if ``quiet``); print its summary line.

    The resume is said even if ``quiet`` (a study's run.log keeps it).
    """
    reporters = [GenerationPrinter(quiet), WarningPrinter()]
    reporters += [] if quiet else [PostEvaluationPrinter()]
    # After the last generation the run stops between batches of its post-evaluation.
    stop = StopOnSignal("generation (or post-evaluation batch)")
    with explained("generation"):
        done = arbitrator_run(run, reporters, stop, workers)
    result, post = done.result, done.result.post_evaluation
    episodes = f"{post.episodes} post-evaluation episodes"
    if post.finalists:  # its figures are over both rounds (docs/design.md section 8)
        episodes = (
            f"{post.final_episodes} post-evaluation episodes (one of {post.finalists} "
            f"finalists of {post.candidates} candidates)"
        )
    print(
        f"{done.robot} {run.kind.noun}: best fitness {result.best_fitness:.3f} (generation "
        f"{result.best_generation + 1}); the controller written scores {post.fitness:.3f} and "
        f"reaches the target in {post.reached:.0%} of {episodes}; "
        f"{done.generations} generations in {result.seconds / 60:.1f} min "
        f"(seed {run.seed}) -> {done.out}, curve {done.plot}"
    )
    return 0
