"""evorbc-sim fails when a node of its graph dies (docs/design.md section 9).

A graph without its arbitrator would wait forever, or drive on nothing: evorbc-sim stops
the rest, says which node died and how, and exits 1.
"""

import os
import signal
import subprocess
import sys
import time

import pytest
from graph_helpers import children, cmdline
from ros_domains import claim_domain


@pytest.mark.slow
def test_evorbc_sim_exits_1_naming_a_node_that_died(tmp_path):
    env = dict(os.environ, PYTHONUNBUFFERED="1", ROS_LOG_DIR=str(tmp_path / "log"))
    sim = subprocess.Popen(
        [sys.executable, "-P", "-m", "sim_bridge.bringup", "--domain-id", str(claim_domain(209)),
         "--mode", "realtime", "--plot", str(tmp_path / "p.png")],
        env=env, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        deadline = time.monotonic() + 120
        arbitrator = None
        while arbitrator is None and time.monotonic() < deadline and sim.poll() is None:
            found = [p for p in children(sim.pid) if "evorbc_ros.nodes.arbitrator" in cmdline(p)]
            arbitrator = found[0] if found else None
            time.sleep(0.1)
        assert arbitrator is not None, "the arbitrator never started"
        time.sleep(2.0)  # let the run get going: a death mid-episode, not at start-up
        nodes = children(sim.pid)
        os.kill(arbitrator, signal.SIGKILL)
        _, err = sim.communicate(timeout=120)
    finally:
        if sim.poll() is None:
            sim.kill()
    assert sim.returncode == 1, err
    assert (
        "evorbc-sim: error: arbitrator failed (status -9); the graph cannot run without it" in err
    )
    assert "Traceback" not in err
    assert len(nodes) == 5
    still = [cmdline(p) for p in nodes if cmdline(p)]  # nothing outlives it
    assert still == []
