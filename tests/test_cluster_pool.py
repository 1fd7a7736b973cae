"""A legged robot's evaluations within one run spread over a real two-node Ray cluster
(``--cluster`` / ``EVORBC_CLUSTER``): the same results as on one process, also after
losing a node mid-batch."""

import json
import os
import subprocess
import sys
import time

import numpy as np
import pytest
from hexapod_helpers import tripod_repertoire
from ray_cluster import LocalCluster, free_port

from offline_evolution.maze_task.hexapod_task import HexapodMazeTask
from offline_evolution.maze_task.task import MazeTaskSettings
from sim_bridge.hexapod.robot import HexapodRobot

pytest.importorskip("ray")

GENES_SEED = 5
N_PRIMITIVES = 600  # enough that a quiet 2-core machine is still busy after 3 s
EVAL_TIME = 2.0  # s
# Runs in its own process, connected to the cluster through EVORBC_CLUSTER, as the CLI is.
PRIMITIVES = f"""
import sys, numpy as np
from sim_bridge.hexapod.robot import HexapodRobot
genes = np.random.default_rng({GENES_SEED}).uniform(-1, 1, ({N_PRIMITIVES}, 37))
robot = HexapodRobot(workers=int(sys.argv[2]) if len(sys.argv) > 2 else None)
print("started", flush=True)
out = robot.evaluate_primitives(genes, {EVAL_TIME})
np.save(sys.argv[1], np.stack([out.x, out.y, out.heading, out.path, out.max_tilt]))
robot.close()
"""
EPISODES = """
import sys, numpy as np
sys.path.insert(0, "tests")
from test_cluster_pool import episodes
np.save(sys.argv[1], episodes(workers=None))
"""


@pytest.fixture(scope="module")
def cluster():
    c = LocalCluster()
    yield c
    c.stop()


def on_cluster(cluster, script, out, *args):
    env = dict(cluster.env, EVORBC_CLUSTER=cluster.address)
    return subprocess.Popen(
        [sys.executable, "-c", script, str(out), *map(str, args)],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )


def local_primitives():
    genes = np.random.default_rng(GENES_SEED).uniform(-1, 1, (N_PRIMITIVES, 37))
    robot = HexapodRobot(workers=1)
    try:
        out = robot.evaluate_primitives(genes, EVAL_TIME)
    finally:
        robot.close()
    return np.stack([out.x, out.y, out.heading, out.path, out.max_tilt])


def episodes(workers):
    """Recorded poses and fitness of 3 networks x 2 starts, 2 s hexapod episodes."""
    from test_hexapod_task import networks

    settings = MazeTaskSettings(("hexapod",), 2.0, 1, "sensors/hexapod.yaml")
    task = HexapodMazeTask(settings, workers=workers)
    try:
        controller = task.controller("evorbc", tripod_repertoire(), "polar")
        starts = np.array([[0, -3.5, 0.0, 0.0], [0, -3.4, 0.3, 1.0]])
        reports = []  # on the cluster too, one report per episode (docs/design.md section 15)
        task.progress = lambda done, total: reports.append((done, total))
        r = task.evaluate(networks(2), controller, starts, record=True)
    finally:
        task.close()
    assert reports == [(done, 6) for done in range(7)]
    return np.concatenate([r.pose.ravel(), r.fitness, r.choice.ravel()])


def repertoire_command(out, *extra):
    return [
        sys.executable, "-m", "offline_evolution.cli", "repertoire", "--robot", "hexapod",
        "--iterations", "2", "--initial-batch", "40", "--batch-size", "20", "--seed", "3",
        "--quiet", "--out", str(out), *extra,
    ]  # fmt: skip


@pytest.mark.slow
def test_a_repertoire_run_with_cluster_writes_the_same_file(cluster, tmp_path):
    env = dict(cluster.env)
    env.pop("EVORBC_CLUSTER", None)
    spread = repertoire_command(tmp_path / "c.json", "--cluster", cluster.address)
    local = repertoire_command(tmp_path / "l.json", "--workers", "1")
    for cmd in (spread, local):
        done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, done.stderr
    on_cluster_file, local_file = (json.loads((tmp_path / f"{k}.json").read_text()) for k in "cl")
    assert on_cluster_file["primitives"] == local_file["primitives"]
    assert len(local_file["primitives"]["genes"]) > 0


@pytest.mark.slow
def test_episodes_on_the_cluster_match_one_process(cluster, tmp_path):
    out = tmp_path / "episodes.npy"
    proc = on_cluster(cluster, EPISODES, out)
    text, _ = proc.communicate(timeout=600)
    assert proc.returncode == 0, text
    np.testing.assert_array_equal(np.load(out), episodes(workers=1))


# Last of the cluster's tests: it loses the worker node.
@pytest.mark.slow
def test_primitives_on_the_cluster_match_one_process_after_losing_a_node(cluster, tmp_path):
    out = tmp_path / "cluster.npy"
    proc = on_cluster(cluster, PRIMITIVES, out)
    assert proc.stdout.readline().strip() == "started"
    time.sleep(3.0)  # both nodes are evaluating chunks
    assert proc.poll() is None, "finished before the node was lost: nothing was tested"
    cluster.kill_worker_node()
    text, _ = proc.communicate(timeout=600)
    assert proc.returncode == 0, text
    np.testing.assert_array_equal(np.load(out), local_primitives())


def test_an_unreachable_cluster_is_one_line(tmp_path):
    env = dict(os.environ, RAY_USAGE_STATS_ENABLED="0")
    result = subprocess.run(
        [
            sys.executable, "-m", "offline_evolution.cli", "repertoire", "--robot", "hexapod",
            "--iterations", "1", "--initial-batch", "20", "--batch-size", "20",
            "--cluster", f"127.0.0.1:{free_port()}", "--out", str(tmp_path / "r.json"),
        ],
        env=env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert result.returncode == 1, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("evorbc-evolve: error: cluster 127.0.0.1:")
    assert not (tmp_path / "r.json").exists()


def test_a_study_spread_needs_a_cluster_and_runs_take_only_their_cpus(tmp_path):
    from study_helpers import run_study, write_tiny_study

    from offline_evolution.study.run import commands
    from offline_evolution.study.spec import load_study

    study = write_tiny_study(tmp_path)
    result = run_study("run", study, "--results", tmp_path / "r", "--spread", "2")
    assert result.returncode != 0
    assert result.stderr.strip().endswith("--spread needs a Ray cluster (--address or RAY_ADDRESS)")
    run = load_study(study).runs()[0]
    assert all(cmd[-2:] == ["--workers", "3"] for cmd in commands(run, 3))
