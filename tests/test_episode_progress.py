"""Progress of long batches of episodes (`MazeTaskBase.progress`, `EpisodeProgress`).

The legged robots' PyBullet episodes take about a second each, so a held-out suite or a
post-evaluation of thousands of them runs for many minutes; they report progress on
stderr, and reporting changes nothing they return.
"""

import io

import numpy as np
import pytest

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.defaults import default_repertoire, paper_arbitrator
from evorbc_ros.repertoire import Repertoire
from offline_evolution.maze_task.task import MazeTaskSettings, make_task
from offline_evolution.runs.console import EpisodeProgress


class Clock:
    """A settable clock (s)."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_a_short_batch_says_nothing_and_a_long_one_reports_at_most_every_interval():
    clock, out = Clock(), io.StringIO()
    report = EpisodeProgress("evaluate", every=10.0, clock=clock, stream=out)
    report(0, 4)
    for done in range(1, 5):
        clock.now += 2.0  # 8 s in all: under the interval
        report(done, 4)
    assert out.getvalue() == ""

    report(0, 100)
    for done in range(1, 101):
        clock.now += 1.5  # 150 s in all
        report(done, 100)
    lines = out.getvalue().splitlines()
    # the first after 10 s, then every 10 s at most, and the end
    assert lines[0] == "evaluate: 7/100 episodes (7 %), 0.2 min, eta 2.3 min"  # 10.5 s / 7 x 93
    assert lines[-1] == "evaluate: 100/100 episodes (100 %), 2.5 min, done"
    assert 13 <= len(lines) <= 16
    counts = [int(line.split()[1].split("/")[0]) for line in lines]
    assert counts == sorted(counts) and len(set(counts)) == len(counts)


def test_lines_go_to_stderr_so_json_on_stdout_stays_clean(capsys):
    clock = Clock()
    report = EpisodeProgress("evaluate", every=10.0, clock=clock)
    report(0, 2000)
    clock.now += 20.0
    report(1990, 2000)
    captured = capsys.readouterr()
    assert captured.out == ""
    # 99.5 % shows as 99 %: 100 % only when every episode is done
    assert captured.err == "evaluate: 1990/2000 episodes (99 %), 0.3 min, eta 0.0 min\n"


def test_the_end_of_a_long_batch_is_always_said():
    clock, out = Clock(), io.StringIO()
    report = EpisodeProgress("post-evaluation", every=10.0, clock=clock, stream=out)
    report(0, 2)
    clock.now += 9.0
    report(1, 2)
    clock.now += 2.0  # 11 s: past the first interval, 11 s after the start
    report(2, 2)
    assert out.getvalue() == "post-evaluation: 2/2 episodes (100 %), 0.2 min, done\n"


@pytest.fixture(scope="module")
def hexapod():
    """The paper-protocol hexapod controller on 1.5 s episodes of its maze."""
    arb = ArbitratorFile.load(paper_arbitrator("hexapod"))
    rep = Repertoire.load(default_repertoire("hexapod"))
    return arb, rep, MazeTaskSettings(("hexapod",), 1.5, 1, "sensors/hexapod.yaml")


def test_in_process_batches_report_each_episode_as_it_finishes(hexapod, monkeypatch):
    from offline_evolution.maze_task import legged_task

    arb, rep, settings = hexapod
    ran = []
    run = legged_task._run
    monkeypatch.setattr(legged_task, "_run", lambda *a: ran.append(1) or run(*a))
    task = make_task(settings, "hexapod", workers=1)
    try:
        controller = task.controller("evorbc", rep, arb.mapping)
        starts = np.concatenate([task.sample_starts(np.random.default_rng(4)) for _ in range(3)])
        seen = []  # episodes run when each report came
        task.progress = lambda done, total: seen.append((done, len(ran)))
        task.evaluate([arb.network], controller, starts)
    finally:
        task.close()
    assert seen == [(0, 0), (1, 1), (2, 2), (3, 3)]


@pytest.mark.parametrize("workers", [1, 2])
def test_legged_batches_report_every_episode_and_return_the_same(hexapod, workers):
    arb, rep, settings = hexapod
    task = make_task(settings, "hexapod", workers=workers)
    try:
        controller = task.controller("evorbc", rep, arb.mapping)
        starts = np.concatenate([task.sample_starts(np.random.default_rng(3)) for _ in range(3)])
        silent = task.evaluate([arb.network], controller, starts)
        calls = []
        task.progress = lambda done, total: calls.append((done, total))
        reported = task.evaluate([arb.network], controller, starts)
    finally:
        task.close()
    assert calls == [(0, 3), (1, 3), (2, 3), (3, 3)]
    np.testing.assert_array_equal(reported.fitness, silent.fitness)
    np.testing.assert_array_equal(reported.cycles, silent.cycles)
    np.testing.assert_array_equal(reported.final_distance, silent.final_distance)
