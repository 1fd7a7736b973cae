"""The ROS 2 graph across processes (localhost discovery): lockstep parity with the offline
replay, real-time mode, and a node restarted in the middle of a run."""

import re
import signal
import subprocess
import sys
import time
import uuid
from pathlib import Path

import numpy as np
import pytest
from graph_helpers import GraphRun, assert_same_choices, graph_env

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.defaults import default_arbitrator, default_repertoire, paper_arbitrator
from evorbc_ros.repertoire import Repertoire
from offline_evolution.maze_task.replay import replay
from offline_evolution.maze_task.task import MazeTask, MazeTaskSettings
from sim_bridge.bringup import NODES, node_command

MAZES = ["obstacle", "zigzag", "baffles", "corridors", "gaps"]
#: The mazes whose whole episode goes through the graph: the two shortest episodes, to keep
#: the suite short. The graph's parity does not depend on the walls; `obstacle` and
#: `baffles` go through the graph with parity checks in test_laser_graph.py and
#: test_nonfinite_outputs.py, `zigzag` in the real-time test below.
GRAPH_MAZES = ["corridors", "gaps"]


def replayed(path):
    """The arbitrator ``path`` replayed offline from each maze's nominal start, with its own
    sensor layout (the shipped default's may not be the paper's)."""
    arb = ArbitratorFile.load(path)
    repertoire = Repertoire.load(default_repertoire(arb.robot))
    sensors = MazeTaskSettings.from_dict(arb.evolution["task"], str(path)).sensors
    task = MazeTask(MazeTaskSettings(tuple(MAZES), 120.0, 1, sensors), arb.robot)
    return replay(arb, task, task.nominal_starts(), repertoire)


@pytest.fixture(scope="module")
def offline():
    """The shipped (default) arbitrator, what the graph runs when given none."""
    return replayed(default_arbitrator())


def test_the_paper_controller_reaches_every_target_from_the_nominal_start():
    outcomes, _ = replayed(paper_arbitrator())
    assert all(o.reached for o in outcomes)


@pytest.mark.parametrize("k", [MAZES.index(m) for m in GRAPH_MAZES], ids=GRAPH_MAZES)
def test_lockstep_graph_makes_the_offline_choices_and_reaches_the_target(tmp_path, offline, k):
    outcomes, result = offline
    run = GraphRun(tmp_path, 150 + k, MAZES[k])
    got = run.finish(timeout=120)
    cycles = assert_same_choices(run.recorded_choices(), result, k)
    trajectory = np.array(got["trajectory"])
    np.testing.assert_allclose(trajectory, result.pose[k, : cycles + 1], atol=1e-9)
    assert got["time"] == pytest.approx(outcomes[k].time, abs=1e-9)
    assert got["fitness"] == pytest.approx(outcomes[k].fitness, abs=1e-12)
    # Reaching is the controller's business (the paper one's is pinned above); the graph's
    # is to reach exactly when the offline episode does.
    assert got["reached"] == outcomes[k].reached


#: ROS domains of the parity runs under load (no other test uses 140-142).
LOADED_DOMAINS = (140, 141, 142)


@pytest.mark.slow
def test_lockstep_parity_holds_next_to_busy_processes(tmp_path, offline):
    # Three 30 s runs of gaps (300 cycles each) with two busy processes on the machine's
    # cores: lockstep waits for every answer, so load may slow it, never change it.
    _, result = offline
    k, cycles = MAZES.index("gaps"), 300
    busy = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(2)]
    try:
        for i, domain in enumerate(LOADED_DOMAINS):
            folder = tmp_path / str(i)
            folder.mkdir()
            run = GraphRun(folder, domain, "gaps", episode_time=cycles / 10)
            got = run.finish(timeout=180)
            choices = run.recorded_choices()
            assert len(choices) in (cycles, cycles + 1), f"run {i}: {len(choices)} choices"
            np.testing.assert_array_equal(choices[:cycles], result.choice[k, :cycles])
            np.testing.assert_array_equal(got["trajectory"], result.pose[k, : cycles + 1])
    finally:
        for p in busy:
            p.kill()
            p.wait()


def test_realtime_mode_runs_at_ten_hertz(tmp_path):
    run = GraphRun(tmp_path, 160, "zigzag", mode="realtime", episode_time=3.0)
    start = time.monotonic()
    try:
        got = run.wait(timeout=60)
    finally:
        run.stop()
    wall = time.monotonic() - start
    assert got["mode"] == "realtime" and got["time"] == pytest.approx(3.0)
    assert len(got["trajectory"]) == 31
    assert wall >= 3.0  # simulated time did not outrun the wall clock
    moved = np.hypot(*np.diff(np.array(got["trajectory"])[:, :2], axis=0).T).sum()
    assert moved > 0.2  # the controller drove the robot


def test_a_restarted_arbitrator_rejoins_and_the_run_continues(tmp_path):
    # The paper-protocol controller: from the nominal start it reaches the target in gaps.
    paper = str(paper_arbitrator())
    run = GraphRun(tmp_path, 161, "gaps", arbitrator=paper)
    try:
        deadline = time.monotonic() + 60
        log = tmp_path / "gaps-lockstep.log"
        while "t =  10.0 s" not in log.read_text() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert "t =  10.0 s" in log.read_text()
        arb = run.procs["arbitrator"]
        arb.send_signal(signal.SIGINT)
        arb.wait(10)
        run.start("arbitrator", NODES["arbitrator"], {"use_sim_time": True, "arbitrator": paper})
        got = run.wait(timeout=120)
    finally:
        run.stop()
    assert got["time"] > 10.0
    assert got["reached"]
    assert "sending the state again" in log.read_text()


def test_nodes_refuse_bad_parameters_with_one_line(tmp_path):
    cmd = node_command(NODES["arbitrator"], {"arbitrator": str(tmp_path / "missing.json")})
    done = subprocess.run(cmd, env=graph_env(162), capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    last = done.stderr.strip().splitlines()[-1]
    assert re.fullmatch(
        r"\[FATAL\] \[[0-9.]+\] \[arbitrator\]: cannot start: "
        + re.escape(f"{tmp_path / 'missing.json'}: no such arbitrator file"),
        last,
    ), last
    cmd = node_command("sim_bridge.bridge_node", {"maze": "labyrinth"})
    done = subprocess.run(cmd, env=graph_env(163), capture_output=True, text=True, timeout=60)
    assert done.returncode == 2 and "unknown maze 'labyrinth'" in done.stderr


def test_evorbc_sim_stops_the_whole_graph_on_ctrl_c(tmp_path):
    # A mark of this run's processes alone (another suite on the machine may use domain 164).
    mark = f"EVORBC_TEST_RUN={uuid.uuid4().hex}"
    env = {**graph_env(164), "EVORBC_TEST_RUN": mark.split("=", 1)[1]}
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "sim_bridge.bringup",
            "--maze",
            "obstacle",
            "--mode",
            "realtime",
            "--plot",
            str(tmp_path / "run.png"),
        ],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=tmp_path,
    )
    deadline = time.monotonic() + 60
    seen = ""
    while "t =  10.0 s" not in seen and time.monotonic() < deadline:
        line = proc.stderr.readline()
        assert line, "the graph ended early"
        seen += line
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=30)
    assert proc.returncode == 130
    assert "evorbc-sim: interrupted; stopping the graph" in err
    # The partial run is reported as interrupted, and drawn; no rcl noise, no traceback.
    assert re.fullmatch(
        r"obstacle: interrupted after [0-9.]+ s \([0-9.]+ m left\) \(realtime\) -> \S+",
        out.strip(),
    ), out
    assert "rcl" not in err and "Traceback" not in err and "Failed" not in err
    assert (tmp_path / "run.png").exists()
    assert not processes_with_env(mark), "nodes outlived evorbc-sim"


def processes_with_env(entry: str) -> list[int]:
    """PIDs of processes whose environment contains ``entry`` (``NAME=value``)."""
    found = []
    for environ in Path("/proc").glob("[0-9]*/environ"):
        try:
            if entry.encode() in environ.read_bytes().split(b"\0"):
                found.append(int(environ.parent.name))
        except OSError:
            continue  # the process ended or is not ours to read
    return found
