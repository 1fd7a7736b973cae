"""Reading the files users give: regular files only, of a sane size for their format.

A FIFO given as a file blocks the reader on ``open`` until some writer appears (forever,
usually), and ``/dev/zero`` or ``/dev/urandom`` never ends: both are refused before they
are read, as is a file far larger than any of its format could be (a mistaken path to a
disk image, say), which would otherwise be read whole into memory before failing.
"""

from __future__ import annotations

import gc
import os
import stat
from collections.abc import Iterator
from contextlib import contextmanager

MIB = 1 << 20
#: Size limits (bytes) by format: far above any real file, far below a machine's memory.
SETTINGS_LIMIT = 16 * MIB  # YAML settings, sensor layouts, mazes, NEAT .ini
ARBITRATOR_LIMIT = 256 * MIB  # a network and its evolution record
DATA_LIMIT = 2048 * MIB  # repertoires (200,000 hexapod primitives are about 200 MB) and checkpoints

_KINDS = (
    (stat.S_ISFIFO, "a FIFO"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def file_problem(path: str | os.PathLike, what: str, limit: int) -> str | None:
    """Why ``path`` cannot be read as a ``what`` file, without opening it; None if it can.

    The problems: missing, a folder, not a regular file (FIFO, device, socket), larger
    than ``limit`` bytes, or not stat-able (permissions).
    """
    try:
        st = os.stat(path)
    except FileNotFoundError:
        return f"no such {what} file"
    except OSError as e:
        return f"cannot read ({e.strerror})"
    return _mode_problem(st, what, limit)


def _mode_problem(st: os.stat_result, what: str, limit: int) -> str | None:
    if stat.S_ISDIR(st.st_mode):
        return f"is a folder, expected {_a(what)} file"
    if not stat.S_ISREG(st.st_mode):
        kind = next((name for test, name in _KINDS if test(st.st_mode)), "not a file")
        return f"is {kind}, not a regular file; expected {_a(what)} file"
    if st.st_size > limit:
        return (
            f"is {_size(st.st_size)}, too large for {_a(what)} file (at most {_size(limit)}); "
            "is it the right file?"
        )
    return None


def _a(what: str) -> str:
    """``what`` with its article: "a repertoire", "an arbitrator"."""
    return f"{'an' if what[:1].lower() in 'aeiou' else 'a'} {what}"


def _size(n: int) -> str:
    return f"{n / MIB:.0f} MiB" if n >= MIB else f"{n} bytes"


def read_regular(path: str | os.PathLike, what: str, error: type[Exception], limit: int) -> bytes:
    """The bytes of the regular file ``path``.

    Args:
        what: what the file should be (``"repertoire"``), for the messages.
        error: the exception class to raise.
        limit: the largest size (bytes) accepted for such a file.

    Raises:
        ``error``: one line that starts with the path (see :func:`file_problem`).
    """
    source = str(path)
    problem = file_problem(path, what, limit)
    if problem:
        raise error(f"{source}: {problem}")
    try:
        # O_NONBLOCK: should the path have become a FIFO since the check, do not wait for
        # a writer; fstat then refuses it.
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except FileNotFoundError:
        raise error(f"{source}: no such {what} file") from None
    except OSError as e:
        raise error(f"{source}: cannot read ({e.strerror})") from None
    with open(fd, "rb") as f:
        try:
            st = os.fstat(fd)
            problem = _mode_problem(st, what, limit)
            if problem:
                raise error(f"{source}: {problem}")
            data = _read_at_most(f, st.st_size, limit)
        except OSError as e:
            raise error(f"{source}: cannot read ({e.strerror})") from None
        except MemoryError:
            raise error(
                f"{source}: cannot read: {_size(st.st_size)} do not fit in memory"
            ) from None
    if len(data) > limit:  # it grew while being read
        raise error(f"{source}: too large for {_a(what)} file (at most {_size(limit)})")
    return data


#: Bytes read at a time once a file is longer than ``fstat`` said (it is growing).
_CHUNK = 16 * MIB


def _read_at_most(f, size: int, limit: int) -> bytes:
    """The file's bytes, at most ``limit + 1`` of them.

    One read of its size and a byte: ``f.read(limit + 1)`` would ask for a buffer of the
    whole limit (2 GiB for repertoires) whatever the file's size. A file that grew since
    ``fstat`` (or a ``/proc`` file, whose size reads as 0) is read on in chunks.
    """
    want = min(size, limit) + 1
    data = f.read(want)
    if len(data) < want or want > limit:
        return data
    parts, total = [data], len(data)
    while total <= limit:
        chunk = f.read(min(_CHUNK, limit + 1 - total))
        if not chunk:
            break
        parts.append(chunk)
        total += len(chunk)
    return b"".join(parts)


def read_regular_text(
    path: str | os.PathLike, what: str, error: type[Exception], limit: int
) -> str:
    """:func:`read_regular` decoded as UTF-8.

    Raises:
        ``error``: as :func:`read_regular`, or ``not a <what> file (not UTF-8 text)``.
    """
    data = read_regular(path, what, error, limit)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise error(
            f"{path}: not a {what} file (not UTF-8 text: byte {e.start:,} is 0x{data[e.start]:02x})"
        ) from None
    except MemoryError:
        raise error(f"{path}: cannot read: {_size(len(data))} do not fit in memory") from None


@contextmanager
def gc_paused() -> Iterator[None]:
    """Pause the cyclic garbage collector while a parser builds a file's values.

    It would walk every list and dict built so far, again and again as they accumulate:
    two thirds of the time of a 200,000-wall maze in YAML, a third of a 200,000-primitive
    repertoire in JSON (docs/performance.md). Parsers make no reference cycles.
    """
    collecting = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if collecting:
            gc.enable()


def is_regular(path: str | os.PathLike) -> bool:
    """Whether ``path`` is a regular file (following links), without opening it."""
    try:
        return stat.S_ISREG(os.stat(path).st_mode)
    except OSError:
        return False
