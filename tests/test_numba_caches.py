"""Numba caches left by a version whose modules have moved are dropped, not fatal
(evorbc_ros/numba_caches.py): an in-place upgrade that moved a module recompiles."""

import subprocess
import sys
import textwrap

from evorbc_ros.numba_caches import MARKER, drop_stale_caches, layout

#: A package whose cached kernel takes a NamedTuple defined in another module, like the
#: motion limits of the 4WS model.
KERNEL = """
import numba as nb
from {pkg}.{limits} import Limits

@nb.njit(cache=True)
def scaled(lim, x):
    return lim.gain * x
"""
LIMITS = """
from typing import NamedTuple

class Limits(NamedTuple):
    gain: float
"""
RUN = """
import sys
sys.path.insert(0, {root!r})
if {drop}:
    from evorbc_ros.numba_caches import drop_stale_caches
    drop_stale_caches({package!r})
from {pkg}.kernel import scaled
from {pkg}.{limits} import Limits
print(scaled(Limits(2.0), 3.0))
"""


def _write(root, limits: str) -> None:
    pkg = root / "pkg"
    pkg.mkdir(exist_ok=True)
    (pkg / "__init__.py").write_text("")
    for name in ("old_limits.py", "new_limits.py"):
        (pkg / name).unlink(missing_ok=True)
    (pkg / f"{limits}.py").write_text(textwrap.dedent(LIMITS))
    (pkg / "kernel.py").write_text(textwrap.dedent(KERNEL.format(pkg="pkg", limits=limits)))


def _run(root, limits: str, drop: bool) -> subprocess.CompletedProcess:
    code = RUN.format(root=str(root), drop=drop, package=str(root / "pkg"), pkg="pkg",
                      limits=limits)  # fmt: skip
    return subprocess.run([sys.executable, "-P", "-c", code], capture_output=True, text=True)


def test_a_moved_module_breaks_numba_without_the_drop_and_recompiles_with_it(tmp_path):
    _write(tmp_path, "old_limits")
    first = _run(tmp_path, "old_limits", drop=True)
    assert first.returncode == 0 and first.stdout.strip() == "6.0", first.stderr
    assert list((tmp_path / "pkg" / "__pycache__").glob("kernel.scaled-*.nbi"))
    # The upgrade: Limits moves to another module; kernel.py keeps its name and its cache.
    _write(tmp_path, "new_limits")
    broken = _run(tmp_path, "new_limits", drop=False)
    assert broken.returncode != 0 and "No module named 'pkg.old_limits'" in broken.stderr
    fixed = _run(tmp_path, "new_limits", drop=True)
    assert fixed.returncode == 0 and fixed.stdout.strip() == "6.0", fixed.stderr


def test_caches_stay_while_the_layout_is_unchanged(tmp_path):
    pkg = tmp_path / "pkg"
    (pkg / "sub" / "__pycache__").mkdir(parents=True)
    (pkg / "__pycache__").mkdir()
    (pkg / "__init__.py").write_text("")
    cache = pkg / "sub" / "__pycache__" / "m.f-3.py311.nbi"
    cache.write_bytes(b"index")
    assert drop_stale_caches(pkg) == 1 and not cache.exists()  # no marker yet: dropped
    assert (pkg / "__pycache__" / MARKER).read_text().strip() == layout(pkg)
    cache.write_bytes(b"index")
    assert drop_stale_caches(pkg) == 0 and cache.exists()
    (pkg / "sub" / "moved.py").write_text("")
    assert drop_stale_caches(pkg) == 1 and not cache.exists()


def test_the_layout_is_recorded_before_any_cache_exists(tmp_path):
    """Caches compiled after the first import are kept: the layout was recorded then."""
    (tmp_path / "__init__.py").write_text("")
    assert drop_stale_caches(tmp_path) == 0
    cache = tmp_path / "__pycache__" / "m.f-3.py311.nbi"
    cache.write_bytes(b"index")
    assert drop_stale_caches(tmp_path) == 0 and cache.exists()


def test_a_move_in_a_lower_layer_drops_the_caches_that_may_name_its_types(tmp_path):
    pkg, lower = tmp_path / "pkg", tmp_path / "lower"
    for folder in (pkg / "__pycache__", lower):
        folder.mkdir(parents=True)
    cache = pkg / "__pycache__" / "kernel.run-9.py311.nbi"
    cache.write_bytes(b"index")
    drop_stale_caches(pkg, lower)
    cache.write_bytes(b"index")
    assert drop_stale_caches(pkg, lower) == 0 and cache.exists()
    (lower / "motion.py").write_text("")
    assert drop_stale_caches(pkg, lower) == 1 and not cache.exists()
