"""A real Ray cluster on localhost for tests: a head and a worker node, in process groups."""

import contextlib
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
from pathlib import Path

RAY = str(Path(sys.executable).with_name("ray"))


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class LocalCluster:
    """A head node and a worker node, one CPU each, each in its own process group."""

    def __init__(self):
        # Ray's socket paths must stay under 107 characters: a short folder in /tmp.
        self.temp = Path(tempfile.mkdtemp(prefix="rayev", dir="/tmp"))
        self.port = free_port()
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
