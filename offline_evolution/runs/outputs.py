"""A run's output files: checked before any work, locked while it runs, written last.

Every run (:mod:`offline_evolution.runs`) checks its outputs before it starts, so that a
typo costs nothing, holds an OS lock on each while it runs, and writes them only when it
has finished, deleting its checkpoint after (docs/design.md section 12).
"""

from __future__ import annotations

import contextlib
import fcntl
import os
from collections.abc import Callable, Iterator
from pathlib import Path

from offline_evolution.runs.errors import UserError


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
            raise UserError(f"{option} {path} is the same file as {other}; use another file")


def write_then_discard(checkpoint: Path, write: Callable[[], None], discard: bool = True) -> None:
    """Write a finished run's files, then delete its checkpoint (unless not ``discard``).

    The run saved its finished state to ``checkpoint``; if writing fails it is kept and
    the one-line error says so, and the same command then only writes the files. A kept
    checkpoint (``--keep-checkpoint``) lets a longer run continue the finished one.
    """
    try:
        write()
    except (OSError, ValueError, UserError) as e:
        where = f"{e.filename}: {e.strerror or e}" if getattr(e, "filename", None) else str(e)
        raise UserError(
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
        raise UserError(
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
        UserError: naming the option, the file and the running process.
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
        raise UserError(f"{option} {name}: cannot lock {lock} ({e.strerror})") from None
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
                raise UserError(
                    f"{option} {path}: another run{who} is writing it; wait for it to "
                    f"finish or choose another {option}"
                ) from None
            continue  # its holder was just removing it: try again with the new file
        if _same_file(lock, fd):
            os.ftruncate(fd, 0)
            os.write(fd, f"{os.getpid()}\n".encode())
            return fd
        os.close(fd)  # removed by a run that ended between our open and our lock
    raise UserError(f"{option} {path}: cannot lock {lock}: it keeps changing")


def _same_file(lock: Path, fd: int) -> bool:
    """Whether the path ``lock`` still names the file open as ``fd``."""
    try:
        st = os.stat(lock)
    except FileNotFoundError:
        return False
    fst = os.fstat(fd)
    return (st.st_dev, st.st_ino) == (fst.st_dev, fst.st_ino)
