"""The shipped paper-protocol legged controllers (evorbc_ros/data/hexapod.*, a1.*;
``paper_arbitrator``): each walks its maze to the target from the nominal start offline,
and the ROS 2 graph in lockstep makes the same choices and reaches it too."""

import numpy as np
import pytest
from graph_helpers import GraphRun, assert_same_choices

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.defaults import default_repertoire, paper_arbitrator
from evorbc_ros.repertoire import Repertoire
from offline_evolution.maze_task.replay import replay
from offline_evolution.maze_task.task import MazeTaskSettings, make_task

# What each shipped controller records (evorbc_ros/data/README.md): its NEAT seed and the
# fewest primitives its repertoire must have (the hexapod: the paper's coverage at 8 cm);
# and the ROS domain its graph test uses.
SHIPPED = {
    "hexapod": {"seed": 4, "primitives": 336, "domain": 171},
    "a1": {"seed": 1, "primitives": 800, "domain": 174},
}


@pytest.fixture(scope="module", params=sorted(SHIPPED))
def offline(request):
    """A shipped legged controller replayed offline from its maze's nominal start."""
    robot = request.param
    arb = ArbitratorFile.load(paper_arbitrator(robot))
    repertoire = Repertoire.load(default_repertoire(robot))
    task = make_task(MazeTaskSettings(**arb.evolution["task"]), robot, workers=1)
    try:
        outcomes, result = replay(arb, task, task.nominal_starts(), repertoire)
    finally:
        task.close()
    return robot, arb, repertoire, outcomes[0], result


def test_shipped_files_belong_together_and_record_how_they_were_made(offline):
    robot, arb, repertoire, _, _ = offline
    assert arb.robot == repertoire.robot == robot and arb.kind == "evorbc"
    assert arb.repertoire["fingerprint"] == repertoire.fingerprint()
    assert arb.evolution["seed"] == SHIPPED[robot]["seed"]
    assert arb.evolution["task"]["samples_per_maze"] == 1
    assert arb.evolution["post_evaluation"]["reached_nominal"]
    assert len(repertoire) >= SHIPPED[robot]["primitives"]


def test_shipped_controller_reaches_the_target_from_the_nominal_start(offline):
    _, _, _, outcome, _ = offline
    assert outcome.reached and not outcome.fell
    assert outcome.time < 30.0


def test_lockstep_graph_walks_the_shipped_controller_to_the_target(tmp_path, offline):
    robot, _, _, outcome, result = offline
    run = GraphRun(
        tmp_path, SHIPPED[robot]["domain"], robot, episode_time=30.0,
        arbitrator=paper_arbitrator(robot), robot=robot,
    )  # fmt: skip
    got = run.finish(timeout=300)
    cycles = assert_same_choices(run.recorded_choices(), result)
    trajectory = np.array(got["trajectory"])
    np.testing.assert_array_equal(trajectory, result.pose[0, : cycles + 1])  # bit for bit
    assert got["reached"] and got["time"] == pytest.approx(outcome.time)
