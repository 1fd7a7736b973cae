"""Helpers shared by the subcommands: errors, argument types, signals, output checks."""

from __future__ import annotations

import argparse
import contextlib
import fcntl
import math
import os
import signal
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path

from offline_evolution import bounds
from sim_bridge.cli_support import integer_in

EXIT_ERROR = 1
EXIT_INTERRUPTED = 130


class CliError(Exception):
    """A user-facing error: printed as one line, exit status ``code``."""

    def __init__(self, message: str, code: int = EXIT_ERROR) -> None:
        super().__init__(message)
        self.code = code


#: ``integer >= low`` argument types (kept under this name for the subcommands).
at_least = integer_in


def count(text: str) -> int:
    """Argparse type: an integer >= 0."""
    return integer_in(0)(text)


def positive_float(text: str) -> float:
    """Argparse type: a finite number > 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not (value > 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text!r}")
    return value


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
def running(step: str, unit: str) -> Iterator[StopOnSignal]:
    """A long run's frame: Ctrl-C finishes the current ``step``; errors become one line.

    Yields the :class:`StopOnSignal` to poll. A checkpoint that cannot be used, and the
    interruption (status 130), end as :class:`CliError` saying what to do next; ``unit``
    names what the run counts ("iteration", "generation").
    """
    from offline_evolution.checkpoint import CheckpointError, Interrupted

    stop = StopOnSignal(step)
    previous = stop.install()
    try:
        yield stop
    except CheckpointError as e:
        if e.discardable:
            raise CliError(f"{e}; use --restart to discard it") from None
        raise CliError(f"{e}; choose another --checkpoint") from None
    except Interrupted as e:
        where = f"during {e.during}" if e.during else f"after {unit} {e.iteration}"
        raise CliError(
            f"interrupted {where}; finished work is saved in "
            f"{e.checkpoint}; run the same command again to resume",
            EXIT_INTERRUPTED,
        ) from None
    finally:
        stop.restore(previous)


class EpisodeProgress:
    """Progress of a long batch of episodes, as lines on stderr.

    Called as ``(done, total)`` (``MazeTaskBase.progress``). Says nothing for the first
    ``every`` seconds of a batch, so a batch that runs in seconds (every 4WS one) prints
    nothing; then a line at most every ``every`` seconds and one when the batch is done:
    ``post-evaluation: 340/1785 episodes (19 %), 2.1 min, eta 8.9 min``.

    Args:
        label: what the batch is.
        every: s between lines.
        clock: s, monotonic (a parameter for tests).
        stream: where lines go (default ``sys.stderr`` at the time of the call).
    """

    def __init__(
        self,
        label: str,
        every: float = 10.0,
        clock: Callable[[], float] | None = None,
        stream=None,
    ) -> None:
        self.label = label
        self.every = every
        self.clock = clock or time.monotonic
        self.stream = stream
        self.start = 0.0
        self.last = 0.0

    def __call__(self, done: int, total: int) -> None:
        """``done`` of ``total`` episodes have finished; ``done == 0`` starts a batch."""
        now = self.clock()
        if done == 0:
            self.start = self.last = now
            return
        elapsed = now - self.start
        finished = done >= total
        if elapsed < self.every or (now - self.last < self.every and not finished):
            return
        self.last = now
        tail = "done" if finished else f"eta {elapsed / done * (total - done) / 60:.1f} min"
        print(
            f"{self.label}: {done}/{total} episodes ({100 * done // total} %), "
            f"{elapsed / 60:.1f} min, {tail}",
            file=self.stream or sys.stderr,
        )


def add_resume_options(
    parser: argparse.ArgumentParser, suffix: str, unit: str, every: int | None = None
) -> None:
    """``--checkpoint``, ``--checkpoint-every`` and ``--restart`` of a resumable run.

    Args:
        suffix: the default checkpoint's, after OUT (``.checkpoint.json``).
        unit: what a run counts between checkpoints (``generations``).
        every: the default of ``--checkpoint-every`` (None: the run settings').
    """
    parser.add_argument(
        "--checkpoint",
        metavar="FILE",
        help=f"resume checkpoint (default: OUT{suffix}); a run resumes from it automatically",
    )
    parser.add_argument(
        "--checkpoint-every",
        type=at_least(1),
        default=every,
        metavar="N",
        help=f"{unit} between checkpoints" + (f" (default: {every})" if every else ""),
    )
    parser.add_argument(
        "--restart",
        action="store_true",
        help="discard an existing checkpoint and start from scratch",
    )


def add_workers_option(parser: argparse.ArgumentParser) -> None:
    """``--workers N``: processes for PyBullet simulations (results do not depend on it)."""
    parser.add_argument(
        "--workers",
        type=integer_in(1, bounds.WORKERS),
        metavar="N",
        help="worker processes for robots simulated in PyBullet (default: one per core; "
        "with --cluster, one per cluster CPU); results are the same for any number",
    )
    parser.add_argument(
        "--cluster",
        metavar="ADDRESS",
        help="spread PyBullet simulations over the Ray cluster at ADDRESS (host:port, "
        "auto or ray://...; default: $EVORBC_CLUSTER, else this machine's cores)",
    )


def default_checkpoint(out: Path, given: str | None, suffix: str) -> Path:
    """The checkpoint path: ``given``, or ``OUT<suffix>`` next to the output."""
    return Path(given) if given is not None else out.with_name(out.name + suffix)


def checkpoint_option(given: str | None) -> str:
    """How messages name the checkpoint: ``--checkpoint``, or the default one."""
    return "--checkpoint" if given is not None else "the default --checkpoint"


def check_outputs(files: dict[str, str | os.PathLike | None]) -> None:
    """Refuse, before any work, an output of ``files`` (option -> path) that cannot be one.

    A ``.png``-like option (``--plot``, ``--heatmap``) must also name a picture format.
    See :func:`sim_bridge.cli_support.check_output_file`.
    """
    from sim_bridge.cli_support import check_output_file

    for option, path in files.items():
        if path is not None:
            check_output_file(str(path), option, picture=option.endswith(("--plot", "--heatmap")))


def _identity(path: str | os.PathLike):
    """What makes two names one file: device and inode if it exists, else the full path."""
    try:
        st = os.stat(path)
    except OSError:
        return Path(os.path.realpath(path))  # no RuntimeError on a symlink loop
    return (st.st_dev, st.st_ino)


def check_distinct(files: dict[str, str | os.PathLike | None]) -> None:
    """Refuse two of ``files`` (option -> path; None skipped) that name the same file.

    Inputs count too: an output written over an input (or over another output, or the
    checkpoint) would destroy it.
    """
    seen: dict = {}
    for option, path in files.items():
        if path is None:
            continue
        other = seen.setdefault(_identity(path), option)
        if other != option:
            raise CliError(f"{option} {path} is the same file as {other}; use another file")


def write_then_discard(checkpoint: Path, write: Callable[[], None], discard: bool = True) -> None:
    """Write a finished run's files, then delete its checkpoint (unless not ``discard``).

    The run saved its finished state to ``checkpoint``; if writing fails it is kept and
    the one-line error says so, and the same command then only writes the files. A kept
    checkpoint (``--keep-checkpoint``) lets a longer run continue the finished one.
    """
    try:
        write()
    except (OSError, ValueError, CliError) as e:
        where = f"{e.filename}: {e.strerror or e}" if getattr(e, "filename", None) else str(e)
        raise CliError(
            f"{where}; the finished run is kept in {checkpoint}: run the same command "
            "again to write its files"
        ) from None
    if discard:
        checkpoint.unlink(missing_ok=True)


def restart_from_scratch(checkpoint: Path, kind: str, what: str) -> None:
    """``--restart``: delete ``checkpoint`` if it is a checkpoint of ``kind``, else refuse.

    A file given as ``--checkpoint`` by mistake (a repertoire, say) is never deleted.
    """
    from offline_evolution.checkpoint import CheckpointError, discard_checkpoint

    try:
        discard_checkpoint(checkpoint, kind, what)
    except CheckpointError as e:
        raise CliError(
            f"{e}, so --restart does not delete it; remove it yourself or choose "
            "another --checkpoint"
        ) from None


def lock_file(path: str | os.PathLike) -> Path:
    """The lock file of an output: ``.<name>.lock`` next to it."""
    path = Path(path)
    return path.with_name(f".{path.name}.lock")


@contextlib.contextmanager
def exclusive_outputs(files: dict[str, str | os.PathLike | None]) -> Iterator[None]:
    """Hold an OS lock on each of ``files`` (option -> path; None skipped) for a run.

    Two runs writing one file would share its checkpoint, or overwrite each other's
    output, and the last to write would win; the second is refused while the first runs.
    Every file a run writes is locked (its output, checkpoint, CSV and pictures), under
    its resolved name (``os.path.realpath``), so that the same file reached through a
    symbolic link, a relative path or another option (one run's ``--csv`` given as
    another's ``--out``) is one lock. The lock (``flock`` on :func:`lock_file`) belongs
    to the process, so the system releases it when the process ends in any way, SIGKILL
    included: a killed run never blocks the next one. The lock file is removed when the
    run ends normally.

    Raises:
        CliError: naming the option, the file and the running process.
    """
    with contextlib.ExitStack() as stack:
        for option, path in files.items():
            if path is not None:
                stack.enter_context(_locked(Path(path), option))
        yield


@contextlib.contextmanager
def _locked(path: Path, option: str) -> Iterator[None]:
    real = Path(os.path.realpath(path))
    lock = lock_file(real)
    # The file's own name, when the option reached it through a link or another folder.
    name = path if real == Path(os.path.abspath(path)) else f"{path} (the file {real})"
    try:
        lock.parent.mkdir(parents=True, exist_ok=True)
        fd = _acquire(lock, name, option)
    except OSError as e:
        raise CliError(f"{option} {name}: cannot lock {lock} ({e.strerror})") from None
    try:
        yield
    finally:
        # Removed while still held: a run that opened it meanwhile sees it gone and
        # retries with a new file rather than taking a lock nobody else will check.
        with contextlib.suppress(OSError):
            lock.unlink()
        os.close(fd)


def _acquire(lock: Path, path: Path | str, option: str, tries: int = 20) -> int:
    """An open, locked descriptor of ``lock`` that is still the file at that path."""
    for _ in range(tries):
        fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.read(fd, 32).decode(errors="replace").strip()
            held = _same_file(lock, fd)
            os.close(fd)
            if held:
                who = f" (pid {holder})" if holder.isdigit() else ""
                raise CliError(
                    f"{option} {path}: another run{who} is writing it; wait for it to "
                    f"finish or choose another {option}"
                ) from None
            continue  # its holder was just removing it: try again with the new file
        if _same_file(lock, fd):
            os.ftruncate(fd, 0)
            os.write(fd, f"{os.getpid()}\n".encode())
            return fd
        os.close(fd)  # removed by a run that ended between our open and our lock
    raise CliError(f"{option} {path}: cannot lock {lock}: it keeps changing")


def _same_file(lock: Path, fd: int) -> bool:
    """Whether the path ``lock`` still names the file open as ``fd``."""
    try:
        st = os.stat(lock)
    except FileNotFoundError:
        return False
    fst = os.fstat(fd)
    return (st.st_dev, st.st_ino) == (fst.st_dev, fst.st_ino)
