"""The shipped generalising hexapod controller (evorbc_ros/data/hexapod.arbitrator.json,
trained from the paper-protocol one with starts anywhere in its maze; docs/generalisation.md)
walks its maze from the nominal start offline in its 90 s episodes, and the ROS 2 graph in
lockstep makes the same choices, bit for bit."""

import pytest
from graph_helpers import assert_lockstep_reproduces

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.defaults import default_arbitrator, default_repertoire, paper_arbitrator
from evorbc_ros.repertoire import Repertoire
from offline_evolution.maze_task.replay import replay
from offline_evolution.maze_task.task import MazeTaskSettings, make_task

DOMAIN = 175  # the ROS domain of this file's graph (tests/test_shipped_legged.py: 171, 174)


@pytest.fixture(scope="module")
def offline():
    """The shipped hexapod controller replayed offline from the nominal start."""
    arb = ArbitratorFile.load(default_arbitrator("hexapod"))
    repertoire = Repertoire.load(default_repertoire("hexapod"))
    task = make_task(MazeTaskSettings(**arb.evolution["task"]), "hexapod", workers=1)
    try:
        outcomes, result = replay(arb, task, task.nominal_starts()[:1], repertoire)
    finally:
        task.close()
    return arb, outcomes[0], result


def test_it_is_not_the_paper_protocol_controller(offline):
    arb, _, _ = offline
    paper = ArbitratorFile.load(paper_arbitrator("hexapod"))
    assert arb.network != paper.network and arb.sensors.fingerprint() == paper.sensors.fingerprint()
    assert arb.evolution["task"]["episode_time"] == 90.0
    assert arb.evolution["task"]["mazes"] == ["hexapod", "hexapod-anywhere"]


def test_it_reaches_the_target_from_the_nominal_start(offline):
    _, outcome, _ = offline
    assert outcome.reached and not outcome.fell
    assert outcome.time < 90.0


def test_the_lockstep_graph_walks_it_to_the_target(tmp_path, offline):
    _, outcome, result = offline
    controller = (default_arbitrator("hexapod"), default_repertoire("hexapod"), outcome, result)
    # the same choices and poses bit for bit, and so the same reach and fitness
    assert_lockstep_reproduces(tmp_path, DOMAIN, "hexapod", "hexapod", controller, 90.0, 400)
