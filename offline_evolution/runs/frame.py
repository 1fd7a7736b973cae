"""How a process runs a run: Ctrl-C finishes the current step, errors end as one line.

The runs (:mod:`offline_evolution.runs`) never print; the front ends (``evorbc-evolve``, a
study's worker process, a recipe) run them in this frame and pass a :class:`StopOnSignal`
as their ``should_stop``, which a run lets catch signals only while it searches
(:func:`listening`; docs/design.md section 15).
"""

from __future__ import annotations

import contextlib
import signal
import sys
from collections.abc import Callable, Iterator

from offline_evolution.runs.errors import EXIT_ERROR, EXIT_INTERRUPTED, UserError


class StopOnSignal:
    """First Ctrl-C/SIGTERM: finish the current step, checkpoint, exit. Second: abort."""

    def __init__(self, what: str = "batch") -> None:
        self.requested = False
        self.what = what

    def __call__(self) -> bool:
        """True once a stop was requested."""
        return self.requested

    def install(self) -> dict:
        """Install the handlers; return the previous ones for :meth:`restore`."""

        def handler(signum, frame):
            if self.requested:
                raise KeyboardInterrupt
            self.requested = True
            print(
                f"\nstopping after this {self.what} (Ctrl-C again to abort without saving)",
                file=sys.stderr,
            )

        return {sig: signal.signal(sig, handler) for sig in (signal.SIGINT, signal.SIGTERM)}

    @staticmethod
    def restore(previous: dict) -> None:
        """Put back the handlers :meth:`install` replaced."""
        for sig, old in previous.items():
            signal.signal(sig, old)


@contextlib.contextmanager
def listening(should_stop: Callable[[], bool] | None) -> Iterator[None]:
    """Let ``should_stop``, if a :class:`StopOnSignal`, catch Ctrl-C/SIGTERM meanwhile.

    A run enters it around its search only (the part that polls ``should_stop``), so that
    a Ctrl-C while it checks its inputs or writes its files aborts at once, as ever.
    """
    if not isinstance(should_stop, StopOnSignal):
        yield
        return
    previous = should_stop.install()
    try:
        yield
    finally:
        should_stop.restore(previous)


@contextlib.contextmanager
def explained(unit: str) -> Iterator[None]:
    """A checkpoint that cannot be used, or an interruption, as a :class:`UserError`.

    The one line says what to do next (status 130 for the interruption); ``unit`` names
    what the run counts ("iteration", "generation").
    """
    from offline_evolution.checkpoint import CheckpointError, Interrupted

    try:
        yield
    except CheckpointError as e:
        if e.discardable:
            raise UserError(f"{e}; use --restart to discard it") from None
        raise UserError(f"{e}; choose another --checkpoint") from None
    except Interrupted as e:
        where = f"during {e.during}" if e.during else f"after {unit} {e.iteration}"
        raise UserError(
            f"interrupted {where}; finished work is saved in "
            f"{e.checkpoint}; run the same command again to resume",
            EXIT_INTERRUPTED,
        ) from None


def one_line_errors(prog: str, call: Callable[[], int]) -> int:
    """``call()``'s exit status, every error printed as ``PROG: error: ...`` on stderr.

    A :class:`UserError` exits with its code, a bad file with 1, an abort (a second
    Ctrl-C) with 130, anything unexpected as one ``internal error`` line and 1
    (``EVORBC_DEBUG=1`` shows its traceback).
    """
    from evorbc_ros.arbitrator import ArbitratorError
    from evorbc_ros.config import ConfigError
    from evorbc_ros.repertoire import RepertoireError
    from offline_evolution.checkpoint import CheckpointError
    from sim_bridge.cli_support import report_unexpected
    from sim_bridge.cluster_pool import ClusterError

    try:
        return call()
    except UserError as e:
        print(f"{prog}: error: {e}", file=sys.stderr)
        return e.code
    except (ConfigError, RepertoireError, CheckpointError, ArbitratorError, ClusterError) as e:
        print(f"{prog}: error: {e}", file=sys.stderr)
        return EXIT_ERROR
    except KeyboardInterrupt:
        print(f"{prog}: aborted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except Exception as e:
        return report_unexpected(prog, e)
