"""ROS domain IDs for multi-process tests, exclusive across every suite on the machine.

Several checkouts run the test suite at once on one machine, and the multi-process tests
discover each other over localhost. Two graphs in one ROS domain answer each other's
states: each lockstep run then diverges from its offline episode (docs/design.md section
9). A test claims its domain here: an exclusive ``flock`` on a file per domain in the
temporary folder, held until the test ends (``conftest.py`` releases it). If another
process holds the domain, a spare one is taken; if every spare is busy, the claim waits.
"""

import fcntl
import os
import tempfile
import time
from pathlib import Path

#: Domains taken when a test's own is busy (no test names one of these).
SPARES = tuple(range(210, 220))
#: s to wait for a busy domain when no spare is free.
WAIT = 900.0

_held: dict[int, int] = {}  # domain -> open lock file descriptor
_given: dict[int, int] = {}  # preferred domain -> the one claimed for it, until released


def _lock_path(domain: int) -> Path:
    folder = Path(tempfile.gettempdir()) / "evorbc-ros-domains"
    folder.mkdir(exist_ok=True)
    return folder / f"{domain}.lock"


def _try(domain: int) -> bool:
    """Take ``domain``'s lock if no other process holds it."""
    if domain in _held:
        return True
    fd = os.open(_lock_path(domain), os.O_RDWR | os.O_CREAT, 0o666)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        return False
    _held[domain] = fd
    return True


def claim_domain(preferred: int) -> int:
    """``preferred`` if no other process uses it, else a free spare; held until released.

    Raises:
        TimeoutError: every candidate stayed busy for :data:`WAIT` s.
    """
    if preferred in _given:  # asked again by the same test: the same domain
        return _given[preferred]
    deadline = time.monotonic() + WAIT
    while True:
        for domain in (preferred, *SPARES):
            if domain in _held and domain != preferred:
                continue  # a spare this process already gave to another preferred domain
            if _try(domain):
                _given[preferred] = domain
                return domain
        if time.monotonic() > deadline:
            raise TimeoutError(f"ROS domains {preferred} and {SPARES} stayed busy")
        time.sleep(0.5)


def release_all() -> None:
    """Give back every domain this process claimed (after a test's processes stopped)."""
    for fd in _held.values():
        os.close(fd)  # closing the descriptor drops the flock
    _held.clear()
    _given.clear()
