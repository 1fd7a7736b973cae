"""Drop a package's numba disk caches when its modules have moved.

numba (0.68) reads a cache index by unpickling it before it checks that the index is
fresh, and the index names the types of the compiled signatures by module. After an
upgrade that moves a module (issue 40 moved the 4WS and diff-drive models into their
family folders), an index left in ``__pycache__`` names a module that no longer exists,
and the first call of the cached function raises ``ModuleNotFoundError`` instead of
recompiling. pip removes the ``.pyc`` files of an uninstalled version but not numba's
``.nbi``/``.nbc`` files, so an in-place upgrade hits this (docs/design.md section 16,
docs/design/performance.md).

Each package records the layout of its modules and of the lower layers' (the sorted paths
of their ``.py`` files: a compiled signature may name a type of a lower layer, as the
episode kernel names the 4WS motion limits) beside its caches; when the layout differs,
every numba cache file of the package is deleted once and numba recompiles. Edits to a
module's source need nothing: numba's own time stamp check handles those.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
from pathlib import Path

from evorbc_ros.atomic_io import atomic_write_text

#: The file, in the package's top ``__pycache__``, holding the layout its caches were made with.
MARKER = "evorbc-numba-layout"
#: numba's cache files: the index and the compiled data.
CACHE_SUFFIXES = (".nbi", ".nbc")


def layout(*packages: Path) -> str:
    """A fingerprint of the packages' module layout: the sorted ``.py`` paths under each."""
    names = [
        f"{package.name}/{p.relative_to(package).as_posix()}"
        for package in packages
        for p in sorted(package.rglob("*.py"))
    ]
    return hashlib.sha256("\n".join(names).encode()).hexdigest()


def drop_stale_caches(package: str | os.PathLike, *lower: str | os.PathLike) -> int:
    """Delete ``package``'s numba cache files if the module layout changed since they were made.

    Args:
        package: the package folder (holding ``__init__.py``).
        lower: the folders of the packages it builds on, whose types its compiled
            signatures may name.

    Returns:
        The number of cache files deleted (0 when the layout is unchanged, the caches are
        elsewhere or the folder is read-only).
    """
    package = Path(package)
    pycache = package / "__pycache__"
    # numba writes its caches beside the sources when it can (else in its own cache
    # folder, which this does not manage): so does the marker.
    if not os.access(pycache if pycache.is_dir() else package, os.W_OK):
        return 0
    now = layout(package, *map(Path, lower))
    marker = pycache / MARKER
    try:
        if marker.read_text(encoding="utf-8").strip() == now:
            return 0
    except (OSError, UnicodeDecodeError):
        pass
    dropped = 0
    for folder in package.rglob("__pycache__"):
        for path in folder.iterdir():
            if path.suffix in CACHE_SUFFIXES:
                try:
                    path.unlink()
                    dropped += 1
                except OSError:  # another process dropped it first
                    pass
    with contextlib.suppress(OSError):  # a read-only marker: drop again next time
        pycache.mkdir(exist_ok=True)
        atomic_write_text(marker, now + "\n")
    return dropped


__all__ = ["drop_stale_caches", "layout"]
