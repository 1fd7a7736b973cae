"""What a run tells as it goes: reporters, in neat-python's ``BaseReporter`` way.

A run (the runs of :mod:`offline_evolution.runs`, and
:func:`~offline_evolution.arbitrator.evolve.evolve` under them) calls each of its
reporters at the same points, in order; a reporter overrides what it wants and inherits a
no-op for the rest. The command line prints through the console ones
(:mod:`offline_evolution.runs.console`), a study or a test can count or log through
another, and none of them changes what the run computes.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence


class Reporter:
    """A reporter that ignores everything; subclass it and override what you need."""

    def search_start(self, settings) -> None:
        """A run's checks passed and its search starts with ``settings`` (resolved).

        ``EvolutionSettings`` of an arbitrator run (``generations`` is the total).
        """

    def resumed(self, generations: int) -> None:
        """The run resumes from its checkpoint with ``generations`` already done.

        Called before anything runs, also when only the post-evaluation is left.
        """

    def generation_end(self, stats, settings) -> None:
        """A generation finished: ``stats`` (``GenerationStats``) of the run ``settings``."""

    def post_evaluation(self, done: int, total: int, finalists: bool) -> None:
        """``done`` of the post-evaluation's ``total`` episodes finished.

        ``done == 0`` starts a batch; ``finalists``: the finalists' round. Only tasks that
        report call it (``MazeTaskBase.progress``: the legged robots', whose batches take
        minutes).
        """

    def wants_episodes(self, finalists: bool) -> bool:
        """Whether :meth:`post_evaluation` does anything in that round.

        Only then is the task asked to report its episodes as they finish.
        """
        return type(self).post_evaluation is not Reporter.post_evaluation

    def iteration_end(self, progress) -> None:
        """A MAP-Elites batch finished: ``progress`` (``map_elites.Progress``).

        Its ``resumed_from`` is the iteration a resumed run started from (None if fresh).
        """

    def episodes_done(self, done: int, total: int) -> None:
        """``done`` of a replay's or an evaluation's ``total`` episodes finished.

        ``done == 0`` starts the batch. Only tasks that report call it (the legged
        robots'; ``MazeTaskBase.progress``).
        """

    def warning(self, message: str) -> None:
        """Something the user should know that does not stop the run (one line)."""


class Reporters(Reporter):
    """Several reporters as one, called in the order given."""

    def __init__(self, reporters: Sequence[Reporter] = ()) -> None:
        self.reporters = tuple(reporters)

    def search_start(self, settings) -> None:
        """Tell every reporter."""
        for r in self.reporters:
            r.search_start(settings)

    def resumed(self, generations: int) -> None:
        """Tell every reporter."""
        for r in self.reporters:
            r.resumed(generations)

    def generation_end(self, stats, settings) -> None:
        """Tell every reporter."""
        for r in self.reporters:
            r.generation_end(stats, settings)

    def post_evaluation(self, done: int, total: int, finalists: bool) -> None:
        """Tell every reporter."""
        for r in self.reporters:
            r.post_evaluation(done, total, finalists)

    def iteration_end(self, progress) -> None:
        """Tell every reporter."""
        for r in self.reporters:
            r.iteration_end(progress)

    def episodes_done(self, done: int, total: int) -> None:
        """Tell every reporter."""
        for r in self.reporters:
            r.episodes_done(done, total)

    def warning(self, message: str) -> None:
        """Tell every reporter."""
        for r in self.reporters:
            r.warning(message)

    def episodes(self, finalists: bool) -> Callable[[int, int], None] | None:
        """A task's ``(done, total)`` callback for one round; None if no reporter wants it."""
        wanted = [r for r in self.reporters if r.wants_episodes(finalists)]
        if not wanted:
            return None

        def report(done: int, total: int) -> None:
            for r in wanted:
                r.post_evaluation(done, total, finalists)

        return report


class CallbackReporter(Reporter):
    """The four callbacks ``evolve`` took before reporters, as a reporter.

    Args:
        progress: ``(stats, settings)`` after every generation.
        on_resume: ``(generations done)`` when the run resumes.
        post_progress: ``(done, total)`` during the post-evaluation.
        final_progress: the same in its finalists' round (default ``post_progress``).
    """

    def __init__(self, progress=None, on_resume=None, post_progress=None, final_progress=None):
        self.progress, self.on_resume = progress, on_resume
        self.post = post_progress
        self.final = final_progress if final_progress is not None else post_progress

    def resumed(self, generations: int) -> None:
        """Call ``on_resume``."""
        if self.on_resume is not None:
            self.on_resume(generations)

    def generation_end(self, stats, settings) -> None:
        """Call ``progress``."""
        if self.progress is not None:
            self.progress(stats, settings)

    def post_evaluation(self, done: int, total: int, finalists: bool) -> None:
        """Call ``post_progress`` or ``final_progress``."""
        callback = self.final if finalists else self.post
        if callback is not None:
            callback(done, total)

    def wants_episodes(self, finalists: bool) -> bool:
        """Whether that round's callback was given."""
        return (self.final if finalists else self.post) is not None
