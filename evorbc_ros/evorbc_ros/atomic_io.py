"""Atomic file writes: a reader sees the old file or the new one, never half of one.

Each write goes to a temporary file in the destination folder (same filesystem), is
flushed to disk, and then renamed over the destination.

* A writer killed outright (SIGKILL, power loss) cannot remove its temporary file. So each
  temporary is named after its writer, ``.<name>.tmp-<host>-<pid>-<random><suffix>``, and
  every write first removes the destination's temporaries whose writer was on this host
  and is gone. Another live writer's file, or one from another host (a shared folder), is
  never touched.
* A failed write (disk full, quota, file too large) raises :class:`OSError` naming the
  destination, not the hidden temporary: ``r.json: No space left on device``.
* The destination is a regular file or nothing. A symbolic link is written through: its
  target is replaced and the link kept (``ln -s`` to a shared results folder works as
  users expect). Anything else that exists there (a device, a named pipe, a socket, a
  folder) is refused: renaming over ``/dev/null`` as root would replace the system's
  device with a regular file (docs/design.md section 12, "Writing").
"""

from __future__ import annotations

import contextlib
import errno
import os
import socket
import stat
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO


def _host() -> str:
    """The host name, as it may appear in a file name (no ``/``)."""
    return socket.gethostname().replace("/", "_") or "localhost"


def _prefix(dest: Path) -> str:
    """The start of every temporary file name of ``dest``."""
    return f".{dest.name}.tmp-"


#: What a path that is not a regular file is, by its ``stat`` type, as a message says it.
_KINDS = (
    (stat.S_ISDIR, "a folder"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISFIFO, "a named pipe (FIFO)"),
    (stat.S_ISSOCK, "a socket"),
)


def special_file_kind(path: str | os.PathLike) -> str | None:
    """What ``path`` (links followed) is if it exists and is not a regular file, else None.

    ``"a character device"`` for ``/dev/null``, ``"a folder"``, ``"a named pipe (FIFO)"``...
    """
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return None  # missing (or a dangling link, written through): a new file
    if stat.S_ISREG(mode):
        return None
    return next((kind for test, kind in _KINDS if test(mode)), "not a regular file")


def write_target(path: str | os.PathLike) -> Path:
    """The file a write of ``path`` replaces: ``path`` with every symbolic link resolved.

    Raises:
        OSError: ``path`` is something other than a regular file (see module doc).
    """
    kind = special_file_kind(path)
    if kind:
        code = errno.EISDIR if kind == "a folder" else errno.EEXIST
        raise OSError(code, f"is {kind}, not a regular file; refusing to replace it", str(path))
    return Path(os.path.realpath(path))


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; on success it is renamed onto ``path``.

    For writers that insist on a file name (matplotlib, numpy). The temporary keeps the
    destination's suffix so that format detection by extension still works. A link is
    written through to its target (see module doc).

    Raises:
        OSError: from the system, with ``filename`` the destination (see module doc); or
            ``path`` exists and is not a regular file.
    """
    given = Path(path)
    dest = write_target(given)
    try:
        dest.parent.mkdir(parents=True, exist_ok=True)
        remove_stale_temporaries(dest)
        fd, tmp = tempfile.mkstemp(
            prefix=f"{_prefix(dest)}{_host()}-{os.getpid()}-",
            suffix=dest.suffix,
            dir=dest.parent,
        )
        os.close(fd)
    except OSError as e:
        raise _naming(e, given) from None
    tmp_path = Path(tmp)
    try:
        # mkstemp creates 0600 files; give the result the permissions a plain open() would.
        os.chmod(tmp_path, _default_mode(dest))
        yield tmp_path
        with open(tmp_path, "rb+") as f:
            os.fsync(f.fileno())
        write_target(given)  # again: it may have been replaced while the writer ran
        os.replace(tmp_path, dest)
    except OSError as e:
        raise _naming(e, given) from None
    finally:
        tmp_path.unlink(missing_ok=True)


def _naming(error: OSError, dest: Path) -> OSError:
    """``error`` about ``dest``: the system's errors name the file the user asked for.

    An error without an errno (raised by a writer's own code) is passed on as it is.
    """
    if error.errno is None:
        return error
    return OSError(error.errno, error.strerror or os.strerror(error.errno), str(dest))


def remove_stale_temporaries(path: str | os.PathLike) -> list[Path]:
    """Remove the temporary files of ``path`` left by writers that no longer run.

    Only temporaries named by :func:`atomic_path` on this host whose process is gone are
    removed; a live writer's (or a reused pid's) file is left, as is anything that does
    not parse. Returns the files removed.
    """
    dest = Path(path)
    prefix, host = _prefix(dest), _host()
    removed = []
    try:
        names = os.listdir(dest.parent)
    except OSError:
        return removed
    for name in names:
        if not (name.startswith(prefix) and name.endswith(dest.suffix)):
            continue
        stem = name[len(prefix) :]
        stem = stem[: len(stem) - len(dest.suffix)]
        parts = stem.rsplit("-", 2)  # host (may hold "-"), pid, mkstemp's random part
        if len(parts) != 3 or parts[0] != host or not parts[1].isdigit():
            continue
        if _alive(int(parts[1])):
            continue
        with contextlib.suppress(FileNotFoundError):  # another writer cleaned it first
            (dest.parent / name).unlink()
            removed.append(dest.parent / name)
    return removed


def _alive(pid: int) -> bool:
    """Whether process ``pid`` exists on this host (ours counts: a write in progress)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return True  # another user's process; or no pid at all: not ours to judge
    return True


def _default_mode(dest: Path) -> int:
    """The existing file's mode, else 0666 minus the process umask."""
    try:
        return dest.stat().st_mode & 0o7777
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


def atomic_write(path: str | os.PathLike, write: Callable[[IO], None], binary: bool = False):
    """Call ``write(file)`` on a temporary file and rename it onto ``path``."""
    with (
        atomic_path(path) as tmp,
        open(
            tmp,
            "wb" if binary else "w",
            encoding=None if binary else "utf-8",
            newline=None if binary else "",
        ) as f,
    ):
        write(f)
        f.flush()


def atomic_write_text(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    atomic_write(path, lambda f: f.write(text))
