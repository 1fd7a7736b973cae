"""Dropouts through the ROS 2 graph (issue 18, item 2): a relay between the bridge's
``scan`` and the laser node knocks beams out; the paper-protocol 4ws-5 controller
(``paper_arbitrator``: its rangefinders, its path in ``obstacle``) still drives."""

import pytest
from dropout_graph import DEAD_SECTOR, DropoutRun
from graph_helpers import assert_same_choices

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.defaults import default_repertoire, paper_arbitrator
from evorbc_ros.repertoire import Repertoire
from offline_evolution.maze_task.replay import replay
from offline_evolution.maze_task.task import MazeTask, MazeTaskSettings


def offline_obstacle():
    arb = ArbitratorFile.load(paper_arbitrator())
    task = MazeTask(MazeTaskSettings(("obstacle",), 120.0), arb.robot)
    return replay(arb, task, task.nominal_starts(), Repertoire.load(default_repertoire(arb.robot)))


def test_five_percent_dropouts_and_a_dead_sector_through_the_graph(tmp_path):
    run = DropoutRun(
        tmp_path, 170, "obstacle", dropout=0.05, dead_sector=DEAD_SECTOR,
        arbitrator=paper_arbitrator(),
    )  # fmt: skip
    got = run.finish(timeout=120)
    counts = run.counts()
    assert counts["scans"] > 100
    assert 0.05 < counts["dropped_beams"] / counts["beams"] < 0.09  # 5 % plus 10 of 360
    assert counts["readings"] >= 0.99 * counts["scans"]  # at least 99 % of scans give readings
    assert got["reached"]


@pytest.mark.slow
def test_a_dead_sector_away_from_the_axes_changes_no_choice(tmp_path):
    outcomes, result = offline_obstacle()
    run = DropoutRun(
        tmp_path, 171, "obstacle", dropout=0.0, dead_sector=DEAD_SECTOR,
        arbitrator=paper_arbitrator(),
    )  # fmt: skip
    got = run.finish(timeout=120)
    assert_same_choices(run.recorded_choices(), result, 0)  # as the clean offline replay
    assert got["reached"] and got["time"] == pytest.approx(outcomes[0].time, abs=1e-9)
    assert run.counts()["readings"] == run.counts()["scans"]
