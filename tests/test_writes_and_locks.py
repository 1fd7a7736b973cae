"""Nothing lost, nothing shared by accident.

* A write killed with SIGKILL leaves its temporary file; the next write of that file
  removes it, and never another live writer's.
* Two runs with the same --out: the second is refused while the first runs; a SIGKILLed
  run does not block the next one.
* A full disk (or a file-size limit) names the file being written.
"""

import os
import resource
import shutil
import signal
import subprocess
import sys
import time

import pytest

from evorbc_ros.atomic_io import atomic_write_text, remove_stale_temporaries
from evorbc_ros.defaults import default_repertoire

WRITER = """
import sys, time
from evorbc_ros.atomic_io import atomic_path
with atomic_path(sys.argv[1]) as tmp:
    tmp.write_text("x" * 100000)
    print("writing", flush=True)
    time.sleep(120)
"""


def start_writer(dest):
    """A process in the middle of an atomic write of ``dest`` (its temporary exists)."""
    proc = subprocess.Popen(
        [sys.executable, "-c", WRITER, str(dest)], stdout=subprocess.PIPE, text=True
    )
    assert proc.stdout.readline().strip() == "writing"
    return proc


def temporaries(folder):
    return sorted(p.name for p in folder.iterdir() if ".tmp" in p.name)


def test_the_next_write_removes_the_temporaries_of_killed_writers(tmp_path):
    dest = tmp_path / "out.json"
    for _ in range(3):
        proc = start_writer(dest)
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    # SIGKILL cannot clean up, but each write removed the one before: one is left.
    assert len(temporaries(tmp_path)) == 1
    atomic_write_text(dest, "new")
    assert temporaries(tmp_path) == [] and dest.read_text() == "new"


def test_a_live_writers_temporary_and_other_hosts_are_left_alone(tmp_path):
    dest = tmp_path / "out.json"
    other_host = tmp_path / ".out.json.tmp-elsewhere-12345-abcd.json"
    other_host.write_text("a writer on another machine sharing this folder")
    unrelated = tmp_path / ".out.json.backup"
    unrelated.write_text("not ours")
    live = start_writer(dest)
    try:
        mine = temporaries(tmp_path)
        atomic_write_text(dest, "new")
        assert temporaries(tmp_path) == mine  # the live one and the other host's
        assert remove_stale_temporaries(dest) == []
    finally:
        live.send_signal(signal.SIGKILL)
        live.wait()
    assert [p.name for p in remove_stale_temporaries(dest)] == [
        n for n in mine if n != other_host.name
    ]
    assert other_host.exists() and unrelated.exists()


# -- one run per output ----------------------------------------------------------------------


def evolve_cmd(*argv):
    return [sys.executable, "-m", "offline_evolution.cli", *map(str, argv)]


def test_a_second_run_with_the_same_out_is_refused_while_the_first_runs(tmp_path):
    out = tmp_path / "r.json"
    log = open(tmp_path / "first.log", "w")  # noqa: SIM115
    first = subprocess.Popen(
        evolve_cmd("repertoire", "--iterations", 10**5, "--out", out), stderr=log
    )
    try:
        deadline = time.monotonic() + 120
        while "iteration" not in (tmp_path / "first.log").read_text():
            assert first.poll() is None and time.monotonic() < deadline
            time.sleep(0.2)
        second = subprocess.run(
            evolve_cmd("repertoire", "--iterations", 2, "--quiet", "--out", out),
            capture_output=True,
            text=True,
            timeout=120,
            check=False,
        )
        assert second.returncode == 1
        assert second.stderr.strip() == (
            f"evorbc-evolve: error: --out {out}: another run (pid {first.pid}) is writing it; "
            "wait for it to finish or choose another --out"
        )
        assert not out.exists()
    finally:
        first.send_signal(signal.SIGKILL)  # as a crash or the OOM killer would
        first.wait()
        log.close()
    third = subprocess.run(
        evolve_cmd("repertoire", "--iterations", 2, "--quiet", "--out", out, "--restart"),
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert third.returncode == 0, third.stderr
    assert out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["first.log", "r.json"]


# -- a full disk names the file ------------------------------------------------------------------


def test_a_full_disk_names_the_file(tmp_path):
    """A 16 KiB tmpfs in a private mount namespace (needs root and unshare)."""
    if shutil.which("unshare") is None or os.geteuid() != 0:
        pytest.skip("needs root and unshare for a private tmpfs")
    disk = tmp_path / "disk"
    disk.mkdir()
    script = (
        f"mount -t tmpfs -o size=16k tmpfs {disk} && exec {sys.executable} -m "
        f"offline_evolution.cli export-csv {default_repertoire()} --out {disk}/r.csv"
    )
    done = subprocess.run(
        ["unshare", "--mount", "sh", "-c", script],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    if "mount:" in done.stderr or "unshare:" in done.stderr:
        pytest.skip(f"no private tmpfs here: {done.stderr.strip()}")
    assert done.returncode == 1
    assert done.stderr.strip() == f"evorbc-evolve: error: {disk}/r.csv: No space left on device"


def test_a_file_size_limit_names_the_file(tmp_path):
    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write fails with EFBIG instead
        resource.setrlimit(resource.RLIMIT_FSIZE, (16384, 16384))

    out = tmp_path / "r.csv"
    done = subprocess.run(
        evolve_cmd("export-csv", default_repertoire(), "--out", out),
        capture_output=True,
        text=True,
        timeout=120,
        preexec_fn=limit,
        check=False,
    )
    assert done.returncode == 1
    assert done.stderr.strip() == f"evorbc-evolve: error: {out}: File too large"
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # no half file, no temporary
