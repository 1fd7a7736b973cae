"""Every node as a process: stopped by SIGINT, and again by a second SIGINT during its
shutdown (what ``ros2 launch`` run from a script sends), it exits cleanly: status 0, no
traceback, no crash. Start-up errors reach the ROS log file, not only stderr."""

import os
import signal
import subprocess
import time

import numpy as np
import pytest

from evorbc_ros.defaults import default_arbitrator
from sim_bridge.bringup import NODES, node_command

MODULES = {**NODES, "sim_bridge": "sim_bridge.bridge_node"}
TRIES = 24
AT_ONCE = 12  # processes started together


def node_env(log_dir) -> dict:
    return dict(
        os.environ,
        ROS_AUTOMATIC_DISCOVERY_RANGE="OFF",  # alone: nothing to discover, nothing to disturb
        ROS_LOG_DIR=str(log_dir),
        PYTHONUNBUFFERED="1",
    )


def log_lines(log_dir) -> str:
    return "".join(p.read_text() for p in log_dir.glob("*.log"))


class Try:
    """One node process, signalled twice after seeded delays once rclpy is up."""

    def __init__(self, tmp_path, k, name, first, second):
        self.name, self.first, self.second = name, first, second
        self.log_dir = tmp_path / f"try{k}"
        self.log_dir.mkdir()
        self.err = open(self.log_dir / "stderr.txt", "w+")  # noqa: SIM115
        params = {"sensor_layout": str(default_arbitrator())} if name == "laser_sensor" else {}
        self.proc = subprocess.Popen(
            node_command(MODULES[name], params),
            env=node_env(self.log_dir),
            stdout=subprocess.DEVNULL,
            stderr=self.err,
        )
        self.stage = "starting"
        self.due = None

    def step(self, now):
        """Advance: wait for rclpy (its log file), then SIGINT, then SIGINT again."""
        if self.stage == "starting" and any(self.log_dir.glob("*.log")):
            self.stage, self.due = "up", now + self.first
        elif self.stage == "up" and now >= self.due:
            self.proc.send_signal(signal.SIGINT)
            self.stage, self.due = "signalled", now + self.second
        elif self.stage == "signalled" and now >= self.due:
            if self.proc.poll() is None:
                self.proc.send_signal(signal.SIGINT)
            self.stage = "done"
        return self.stage == "done"

    def result(self):
        code = self.proc.wait(30)
        self.err.seek(0)
        return code, self.err.read()


@pytest.mark.slow
def test_every_node_exits_cleanly_on_a_second_sigint_during_shutdown(tmp_path):
    rng = np.random.default_rng(18)
    names = list(MODULES)
    plan = [
        # After rclpy is up: 0-1.5 s (mid-construction to spinning), then the second
        # signal 0-60 ms later, while the node shuts down.
        (names[k % len(names)], rng.uniform(0.0, 1.5), rng.uniform(0.0, 0.06))
        for k in range(TRIES)
    ]
    failures = []
    for start in range(0, TRIES, AT_ONCE):
        batch = [Try(tmp_path, start + i, *p) for i, p in enumerate(plan[start : start + AT_ONCE])]
        deadline = time.monotonic() + 120
        while not all(t.step(time.monotonic()) for t in batch):
            assert time.monotonic() < deadline, "a node never came up"
            time.sleep(0.005)
        for t in batch:
            code, err = t.result()
            if code != 0 or "Traceback" in err:
                failures.append(f"{t.name} ({t.first:.2f} s, +{t.second * 1e3:.0f} ms): "
                                f"status {code}\n{err[-2000:]}")  # fmt: skip
    assert not failures, "\n".join(failures)


def test_a_start_up_error_reaches_the_ros_log_file(tmp_path):
    missing = tmp_path / "missing.json"
    done = subprocess.run(
        node_command(NODES["arbitrator"], {"arbitrator": str(missing), "robot": "4ws-5"}),
        env=node_env(tmp_path),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2 and "Traceback" not in done.stderr
    line = f"[arbitrator]: cannot start: {missing}: no such arbitrator file"
    assert line in done.stderr.strip().splitlines()[-1]
    assert line in log_lines(tmp_path)
