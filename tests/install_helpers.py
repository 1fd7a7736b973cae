"""Running evorbc as users install it: the commands, the nodes and their checks.

Everything here runs in a folder outside the checkout with an environment that holds only
the install under test, so nothing of the editable install leaks in (docs/design.md
section 10). ``ros2 run PKG EXE`` is what :func:`executable` does: find ``PKG`` in the
ament index under ``AMENT_PREFIX_PATH`` and run ``<prefix>/lib/PKG/EXE``.
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import rclpy
from rclpy.context import Context
from rclpy.node import Node
from ros_domains import claim_domain

ROOT = Path(__file__).resolve().parents[1]

#: Every node executable: (package, executable, a parameter that makes it refuse to start,
#: the start of its one FATAL line).
NODES = [
    ("evorbc_ros", "laser_sensor", "sensor_layout:=/nonexistent/l.yaml", "parameter sensor_layout"),
    ("evorbc_ros", "radar_sensor", "sensor_layout:=/nonexistent/l.yaml", "parameter sensor_layout"),
    ("evorbc_ros", "arbitrator", "arbitrator:=/nonexistent/a.json", "/nonexistent/a.json"),
    ("evorbc_ros", "primitive_executor", "robot:=no-such-robot", "parameter robot"),
    ("sim_bridge", "sim_bridge", "maze:=no-such-maze", "parameter maze"),
]

#: The ros2 CLI beside the Python running the tests, or on the PATH.
ROS2 = shutil.which("ros2", path=f"{Path(sys.executable).parent}:{os.environ.get('PATH', '')}")
needs_ros2 = pytest.mark.skipif(ROS2 is None, reason="needs the ros2 CLI and launch (a full ROS 2)")


def clean_env(domain: int, **extra: str) -> dict:
    """The caller's environment without what points into the checkout or its venv."""
    env = {
        k: v
        for k, v in os.environ.items()
        if k not in ("PYTHONPATH", "PYTHONSAFEPATH", "VIRTUAL_ENV", "AMENT_PREFIX_PATH")
        and not k.startswith("COLCON")
    }
    env.update(
        ROS_DOMAIN_ID=str(claim_domain(domain)),  # ours alone (tests/ros_domains.py)
        ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
        PYTHONUNBUFFERED="1",
        **extra,
    )
    return env


def run(cmd, env, cwd, timeout=300, check=True) -> subprocess.CompletedProcess:
    """Run ``cmd`` (a list, or a string for bash) and return its output; fail with it."""
    shell = isinstance(cmd, str)
    done = subprocess.run(
        ["bash", "-c", cmd] if shell else [str(c) for c in cmd],
        env=env,
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    if check:
        assert done.returncode == 0, f"{cmd}: status {done.returncode}\n{done.stdout}{done.stderr}"
    return done


def assert_fatal_line(done: subprocess.CompletedProcess, node: str, start: str) -> None:
    """Status 2 and, as the last line, the node's one FATAL start-up line; no traceback."""
    assert done.returncode == 2, done.stdout + done.stderr
    assert "Traceback" not in done.stderr + done.stdout
    last = done.stderr.strip().splitlines()[-1]
    pattern = rf"\[FATAL\] \[[0-9.]+\] \[{node}\]: cannot start: {re.escape(start)}.*"
    assert re.fullmatch(pattern, last), last


def wait_for_node(name: str, domain: int, process: subprocess.Popen, timeout=60.0) -> None:
    """Wait until a node called ``name`` shows in the ROS graph of ``domain``."""
    context = Context()
    rclpy.init(context=context, domain_id=claim_domain(domain))
    try:
        probe = Node("install_probe", context=context)
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline and process.poll() is None:
            if name in probe.get_node_names():
                return
            time.sleep(0.1)
        out = process.stdout.read() if process.poll() is not None else ""
        raise AssertionError(f"node {name} never joined the graph: {out}")
    finally:
        context.try_shutdown()


def start_and_stop(cmd, name: str, domain: int, env, cwd) -> str:
    """Start a node, wait until it is in the graph, Ctrl-C it; its output (status 0)."""
    process = subprocess.Popen(
        [str(c) for c in cmd],
        env=env,
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    try:
        wait_for_node(name, domain, process)
    finally:
        if process.poll() is None:
            process.send_signal(signal.SIGINT)
        out = process.communicate(timeout=60)[0]
    assert process.returncode == 0, out
    assert "Traceback" not in out, out
    return out


def reached(out: str) -> re.Match:
    """The ``evorbc-sim`` result line of a run that reached the target."""
    found = re.search(r"reached the target in ([0-9.]+) s, fitness ([0-9.]+)", out)
    assert found, out
    return found
