"""The shipped hexapod controller (evorbc_ros/data/hexapod.*): it walks the maze to the
target from the nominal start offline, and the ROS 2 graph in lockstep makes the same
choices and reaches it too."""

import numpy as np
import pytest
from graph_helpers import GraphRun, assert_same_choices

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.defaults import default_arbitrator, default_repertoire
from evorbc_ros.repertoire import Repertoire
from offline_evolution.maze_task.replay import replay
from offline_evolution.maze_task.task import MazeTaskSettings, make_task


@pytest.fixture(scope="module")
def offline():
    """The shipped hexapod controller replayed offline from the maze's nominal start."""
    arb = ArbitratorFile.load(default_arbitrator("hexapod"))
    repertoire = Repertoire.load(default_repertoire("hexapod"))
    task = make_task(MazeTaskSettings(**arb.evolution["task"]), "hexapod", workers=1)
    try:
        outcomes, result = replay(arb, task, task.nominal_starts(), repertoire)
    finally:
        task.close()
    return arb, repertoire, outcomes[0], result


def test_shipped_files_belong_together_and_record_how_they_were_made(offline):
    arb, repertoire, _, _ = offline
    assert arb.robot == repertoire.robot == "hexapod" and arb.kind == "evorbc"
    assert arb.repertoire["fingerprint"] == repertoire.fingerprint()
    assert arb.evolution["seed"] == 4 and arb.evolution["task"]["samples_per_maze"] == 1
    assert arb.evolution["post_evaluation"]["reached_nominal"]
    assert len(repertoire) >= 336  # the paper's coverage at 8 cm


def test_shipped_controller_reaches_the_target_from_the_nominal_start(offline):
    _, _, outcome, _ = offline
    assert outcome.reached and not outcome.fell
    assert outcome.time < 30.0


def test_lockstep_graph_walks_the_shipped_controller_to_the_target(tmp_path, offline):
    _, _, outcome, result = offline
    run = GraphRun(
        tmp_path, 171, "hexapod", episode_time=30.0,
        arbitrator=default_arbitrator("hexapod"), robot="hexapod",
    )  # fmt: skip
    got = run.finish(timeout=300)
    cycles = assert_same_choices(run.recorded_choices(), result)
    trajectory = np.array(got["trajectory"])
    np.testing.assert_array_equal(trajectory, result.pose[0, : cycles + 1])  # bit for bit
    assert got["reached"] and got["time"] == pytest.approx(outcome.time)
