"""evorbc-study on a real two-node Ray cluster on localhost, losing a node mid-run."""

import contextlib
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest
from study_helpers import (
    first_checkpoint,
    results_contents,
    run_study,
    study_command,
    wait_for,
    write_tiny_study,
)

pytest.importorskip("ray")

RAY = str(Path(sys.executable).with_name("ray"))


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class LocalCluster:
    """A head node and a worker node, one CPU each, each in its own process group."""

    def __init__(self):
        # Ray's socket paths must stay under 107 characters: a short folder in /tmp.
        self.temp = Path(tempfile.mkdtemp(prefix="rayev", dir="/tmp"))
        self.port = _free_port()
        self.address = f"127.0.0.1:{self.port}"
        self.env = dict(os.environ, RAY_USAGE_STATS_ENABLED="0")
        common = ["--num-cpus=1", "--object-store-memory=100000000", "--disable-usage-stats"]
        self.head = self._start(
            [
                "--head",
                f"--port={self.port}",
                "--include-dashboard=false",
                f"--temp-dir={self.temp}",
                *common,
            ]
        )
        self.worker = self._start([f"--address={self.address}", *common])

    def _start(self, args) -> int:
        """``ray start``; returns the process group of the node's daemons."""
        proc = subprocess.Popen(
            [RAY, "start", *args],
            env=self.env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            start_new_session=True,  # the node's daemons keep this process group
        )
        out, _ = proc.communicate(timeout=120)
        assert proc.returncode == 0, out
        return proc.pid

    def kill_worker_node(self) -> None:
        """SIGKILL the worker node: its raylet, its Ray workers and their commands."""
        os.killpg(self.worker, signal.SIGKILL)

    def stop(self) -> None:
        for pgid in (self.worker, self.head):
            with contextlib.suppress(ProcessLookupError):
                os.killpg(pgid, signal.SIGKILL)
        shutil.rmtree(self.temp, ignore_errors=True)


@pytest.fixture
def cluster():
    c = LocalCluster()
    yield c
    c.stop()


@pytest.mark.slow
def test_a_study_survives_losing_a_node_with_results_identical_to_a_serial_run(cluster, tmp_path):
    study = write_tiny_study(tmp_path)
    serial = tmp_path / "serial"
    done = run_study("run", study, "--results", serial, "--jobs", "1")
    assert done.returncode == 0, done.stderr

    results = tmp_path / "ray"
    proc = subprocess.Popen(
        study_command("run", study, "--results", results, "--address", cluster.address),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=cluster.env,
    )
    # Both runs go at once, one per node; once one has saved a NEAT checkpoint, the
    # worker node is lost with whatever it was running.
    wait_for(lambda: first_checkpoint(results), 300, "a NEAT checkpoint")
    cluster.kill_worker_node()
    out, _ = proc.communicate(timeout=600)
    assert proc.returncode == 0, out
    assert "study tiny: 2 done, 0 running, 0 left" in out
    logs = [p.read_text() for p in results.rglob("run.log")]
    assert any(log.count("$ evorbc-evolve arbitrator") == 2 for log in logs)  # retried
    assert results_contents(results) == results_contents(serial)


def test_an_unreachable_cluster_is_one_line(tmp_path):
    study = write_tiny_study(tmp_path)
    result = run_study(
        "run", study, "--results", tmp_path / "r", "--address", f"127.0.0.1:{_free_port()}",
        timeout=120,
    )  # fmt: skip
    assert result.returncode == 1
    lines = result.stderr.strip().splitlines()
    assert lines[-1].startswith("evorbc-study: error: --address 127.0.0.1:")
    assert "cannot connect to the Ray cluster" in lines[-1]
