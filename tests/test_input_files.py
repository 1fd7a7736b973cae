"""Only regular files are read: a FIFO, a device or a folder given as a file, or a file far
larger than its format could be, is refused in one line before it is read.

A FIFO blocks a reader on ``open`` until a writer comes (forever, usually) and /dev/zero
never ends, so the commands run in a subprocess with a time and memory limit: on failure
the test fails rather than hanging or eating the machine's memory.
"""

import os
import resource
import subprocess
import sys
import threading

import pytest

from evorbc_ros.arbitrator import ArbitratorError, ArbitratorFile
from evorbc_ros.config import ConfigError, load_yaml_mapping
from evorbc_ros.input_files import SETTINGS_LIMIT
from evorbc_ros.repertoire import Repertoire, RepertoireError
from offline_evolution.arbitrator.neat_config import load_neat_config
from offline_evolution.checkpoint import CheckpointError, checkpoint_kind, load_checkpoint

GIB = 1 << 30
#: How often a reader opened each test FIFO: never, when only regular files are read.
READER_OPENS = {}


def _limits():
    resource.setrlimit(resource.RLIMIT_AS, (2 * GIB, 2 * GIB))


def evolve_cli(*argv, timeout=60):
    """``evorbc-evolve ARGV`` in a subprocess limited to ``timeout`` s and 2 GiB."""
    return subprocess.run(
        [sys.executable, "-m", "offline_evolution.cli", *map(str, argv)],
        capture_output=True,
        text=True,
        timeout=timeout,
        preexec_fn=_limits,
        check=False,
    )


@pytest.fixture
def fifo(tmp_path):
    """A FIFO. A reader that opens it anyway (the bug) gets end-of-file from a helper
    writer rather than blocking the test forever."""
    path = tmp_path / "r.json"
    os.mkfifo(path)
    READER_OPENS[path] = 0
    stop = threading.Event()

    def feeder():
        while not stop.is_set():
            os.close(os.open(path, os.O_WRONLY))  # blocks until some reader opens it
            if not stop.is_set():
                READER_OPENS[path] += 1

    thread = threading.Thread(target=feeder, daemon=True)
    thread.start()
    yield path
    stop.set()
    # Let the feeder's blocking open return, again until it has seen `stop`: a reader the
    # test opened may have woken it just before, so that it blocks in a new open.
    for _ in range(100):
        os.close(os.open(path, os.O_RDONLY | os.O_NONBLOCK))
        thread.join(0.05)
        if not thread.is_alive():
            break


def test_export_csv_refuses_a_fifo_at_once(tmp_path, fifo):
    done = evolve_cli("export-csv", fifo, "--out", tmp_path / "r.csv")
    assert done.returncode == 1
    assert done.stderr.strip() == (
        f"evorbc-evolve: error: {fifo}: is a FIFO, not a regular file; expected a repertoire file"
    )


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom"])
def test_a_device_is_refused_without_being_read(tmp_path, device):
    done = evolve_cli("replay", "--arbitrator", device)
    assert done.returncode == 1
    assert done.stderr.strip() == (
        f"evorbc-evolve: error: {device}: is a character device, not a regular file; "
        "expected an arbitrator file"
    )


@pytest.mark.parametrize(
    ("load", "error", "what"),
    [
        (Repertoire.load, RepertoireError, "repertoire"),
        (ArbitratorFile.load, ArbitratorError, "arbitrator"),
        (load_yaml_mapping, ConfigError, "settings"),
        (lambda p: load_neat_config(p, 6, 2), ConfigError, "NEAT settings"),
        (load_checkpoint, CheckpointError, "checkpoint"),
    ],
)
def test_every_loader_refuses_fifos_folders_and_devices(tmp_path, fifo, load, error, what):
    for path, kind in [
        (fifo, "is a FIFO, not a regular file"),
        (tmp_path, "is a folder"),
        ("/dev/null", "is a character device, not a regular file"),  # /dev/zero: a subprocess
    ]:
        with pytest.raises(error) as info:
            load(path)
        message = str(info.value)
        assert message.startswith(f"{path}: {kind}") and what in message
    assert READER_OPENS[fifo] == 0


def test_a_file_far_larger_than_its_format_is_refused_before_reading(tmp_path):
    big = tmp_path / "settings.yaml"
    with open(big, "wb") as f:
        f.truncate(SETTINGS_LIMIT + 1)  # sparse: no disk used
    with pytest.raises(ConfigError, match=r"is 16 MiB, too large for a settings file"):
        load_yaml_mapping(big)


def test_restart_and_checkpoint_checks_never_open_a_fifo(tmp_path, fifo):
    assert checkpoint_kind(fifo) is None  # would block in zipfile.is_zipfile
    done = evolve_cli(
        "repertoire", "--iterations", "1", "--checkpoint", fifo, "--restart",
        "--out", tmp_path / "out.json",
    )  # fmt: skip
    # A FIFO is no file to write a checkpoint to: refused before --restart looks at it.
    assert done.returncode == 1 and "is a named pipe (FIFO), not a regular file" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and fifo.exists()
    assert READER_OPENS[fifo] == 0
