"""The offline episodes with the onboard controller's adaptation (docs/design/adaptation.md).

The episode kernel runs the same adaptation code as the arbitrator node (the settled-cycle
rule, the GP correction, the matching), compiled: the lockstep graph, the arbitrator node
adapting, drives a damaged 4WS robot exactly as the adapted offline episode, bit for bit.
``evaluate --adapt`` reports each episode with and without adaptation.
"""

from __future__ import annotations

import json

import numpy as np
from hexapod_helpers import tripod_repertoire

from evorbc_ros.adaptation import AdaptationSettings
from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.defaults import default_arbitrator, default_repertoire
from evorbc_ros.repertoire import Repertoire
from offline_evolution.cli import main
from offline_evolution.maze_task.adapting import adapting, expected_outcomes
from offline_evolution.maze_task.base import MazeTaskSettings
from offline_evolution.maze_task.task import MazeTask
from sim_bridge.perturbation import load_perturbations


def _gaps_task(episode_time=25.0):
    path = default_arbitrator()
    arb = ArbitratorFile.load(path)
    sensors = MazeTaskSettings.from_dict(arb.evolution["task"], str(path)).sensors
    task = MazeTask(MazeTaskSettings(("gaps",), episode_time, 1, sensors), arb.robot)
    rep = Repertoire.load(default_repertoire())
    return path, arb, task, rep, task.controller("evorbc", rep, arb.mapping)


def test_the_kernel_adapts_deterministically_and_changes_choices_only_when_on():
    _, arb, task, rep, controller = _gaps_task()
    starts = task.nominal_starts()
    world = load_perturbations("4ws-stuck-steering").draw(np.random.default_rng([4, 1]), 1)
    off = task.evaluate([arb.network], controller, starts, record=True, world=world)
    for expected in ("recorded", "settled"):
        expected_rows = expected_outcomes(rep, task.robot, expected)
        task.adapt(adapting(rep, AdaptationSettings(), task.dt, expected_rows))
        on = task.evaluate([arb.network], controller, starts, record=True, world=world)
        again = task.evaluate([arb.network], controller, starts, record=True, world=world)
        np.testing.assert_array_equal(on.pose, again.pose)  # each episode from the prior
        np.testing.assert_array_equal(on.choice, again.choice)
        n = min(on.cycles[0], off.cycles[0])
        assert (on.choice[0, :n] != off.choice[0, :n]).any()
        # Until an observation is taken, the adapted controller chooses as the evolved one.
        assert on.choice[0, 0] == off.choice[0, 0]
        task.adapt(None)
    back = task.evaluate([arb.network], controller, starts, record=True, world=world)
    np.testing.assert_array_equal(back.pose, off.pose)


def _lockstep_adapted(tmp_path, domain, expected, episode_time, other=None):
    """The lockstep graph, its arbitrator adapting against ``expected``, with a stuck
    steering wheel, against the kernel's adapted episode: the same primitive at every
    cycle and the same poses, bit for bit. Returns the graph's choices and the number of
    cycles compared, and checks that they differ from the unadapted episode's and, with
    ``other``, from the episode adapting against ``other``."""
    from graph_helpers import GraphRun, assert_same_choices

    path, arb, task, rep, controller = _gaps_task(episode_time)
    starts = task.nominal_starts()
    world = load_perturbations("4ws-stuck-steering").draw(np.random.default_rng([4, 1]), 1)
    plain = task.evaluate([arb.network], controller, starts, record=True, world=world)
    episodes = {}
    for e in filter(None, (other, expected)):
        task.adapt(adapting(rep, AdaptationSettings(), task.dt, expected_outcomes(rep, task.robot, e)))  # noqa: E501  # fmt: skip
        episodes[e] = task.evaluate([arb.network], controller, starts, record=True, world=world)
    result = episodes[expected]
    # odom twice: the bridge starts once the adapting arbitrator has subscribed it too
    # (a first pose it missed would be sent again, and the other nodes answer twice).
    bridge = {"perturb": "4ws-stuck-steering", "seed": 4,
              "wait_for_subscribers": ["scan", "odom", "odom"]}  # fmt: skip
    params = {"adaptation": True, **({"adaptation_expected": expected} if other else {})}
    run = GraphRun(tmp_path, domain, "gaps", episode_time=episode_time, arbitrator=path,
                   bridge=bridge, arbitrator_params=params)  # fmt: skip
    got = run.finish(timeout=120)
    choices = run.recorded_choices()
    cycles = assert_same_choices(choices, result)
    trajectory = np.array(got["trajectory"])
    np.testing.assert_array_equal(trajectory, result.pose[0, : cycles + 1])  # bit for bit
    n = min(cycles, plain.cycles[0])
    assert (choices[:n] != plain.choice[0, :n]).any()  # adaptation changed the choices
    if other:
        n = min(cycles, episodes[other].cycles[0])
        assert (choices[:n] != episodes[other].choice[0, :n]).any()  # so did what it expects
    log = (tmp_path / "gaps-lockstep.log").read_text()
    assert f"adaptation on: correcting outcomes from odometry (expected: {expected})" in log
    assert "stuck_steering: " in log


def test_the_lockstep_graph_adapting_drives_a_damaged_robot_as_the_offline_episode(tmp_path):
    # The arbitrator node with its adaptation parameter on (recorded outcomes as expected,
    # the node's default) against the kernel's adapted episode.
    _lockstep_adapted(tmp_path, 187, "recorded", 25.0)


def test_the_lockstep_graph_adapting_against_the_shipped_settled_outcomes_is_offline_s(tmp_path):
    # adaptation_expected settled: the node reads the settled outcomes shipped beside the
    # repertoire (evorbc-evolve settled), the kernel computes them with the 4WS model
    # (evaluate --adapt-expected settled); the episodes are the same, bit for bit, and not
    # the recorded one's (they part at cycle 8). 10 s keeps the graph's cost small.
    _lockstep_adapted(tmp_path, 188, "settled", 10.0, other="recorded")


def test_evaluate_adapt_reports_each_episode_with_and_without(tmp_path, capsys):
    out = tmp_path / "report.json"
    args = ["evaluate", "--mazes", "gaps", "--starts", "2", "--perturb", "4ws-stuck-steering",
            "--adapt", "--out", str(out)]  # fmt: skip
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "with adaptation (expected: recorded):" in text
    assert "with adaptation, by damaged part (stuck_steering):" in text
    report = json.loads(out.read_text())
    adapted = report["adaptation"]
    assert adapted["settings"]["match"] == "outcome" and adapted["expected"] == "recorded"
    assert len(adapted["episodes"]) == len(report["episodes"]) == 2
    for off, on in zip(report["episodes"], adapted["episodes"], strict=True):
        assert on["start"] == off["start"] and on["damage"] == off["damage"]
    assert adapted["per_damage"] and adapted["overall"]["episodes"] == 2
    assert main(["evaluate", "--mazes", "gaps", "--starts", "1", "--json"]) == 0
    assert "adaptation" not in json.loads(capsys.readouterr().out)  # only with --adapt


def test_evaluate_adapts_a_legged_robot_against_its_settled_outcomes(tmp_path, capsys):
    # Legged robots adapt (tests/test_legged_adaptation.py) against the recorded outcomes
    # or their settled ones, computed in PyBullet first (tests/test_legged_settled.py): the
    # shipped hexapod controller with six tripod gaits (a mismatch, waived), 3 s episodes.
    rep = tmp_path / "tripods.repertoire.json"
    tripod_repertoire().save(rep)
    task = tmp_path / "task.yaml"
    task.write_text(
        "mazes: [hexapod]\nepisode_time: 3.0\nsamples_per_maze: 1\nsensors: sensors/hexapod.yaml\n"
    )
    out = tmp_path / "report.json"
    args = ["evaluate", "--robot", "hexapod", "--repertoire", str(rep), "--allow-mismatch",
            "--task", str(task), "--mazes", "hexapod", "--starts", "1", "--adapt",
            "--adapt-expected", "settled", "--out", str(out)]  # fmt: skip
    assert main(args) == 0
    assert "with adaptation (expected: settled):" in capsys.readouterr().out
    report = json.loads(out.read_text())
    assert report["adaptation"]["expected"] == "settled"
    assert report["adaptation"]["settings"]["steady"] == "held"  # the legged settings
    assert len(report["adaptation"]["episodes"]) == len(report["episodes"]) == 1
