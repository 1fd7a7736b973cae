"""The measurement of adaptation (docs/design/adaptation.md, "Measured on the held-out mazes").

The replay of an adapted episode's outcome model from its traces, the suites that
``evaluate --adapt`` runs, and the settled outcomes of a damaged or slowed robot.
"""

from __future__ import annotations

import numpy as np

from evorbc_ros.adaptation import outcome_table
from evorbc_ros.defaults import default_repertoire
from evorbc_ros.repertoire import Repertoire
from offline_evolution.maze_task.adaptation_replay import replay_model
from offline_evolution.maze_task.adapting import expected_outcomes
from offline_evolution.reporters import Reporters
from offline_evolution.runs.evaluate import EvaluateRun, evaluate_run, run_suites
from sim_bridge.damage import FOUR_WS_CODES
from sim_bridge.four_ws.robot import FourWSRobot
from sim_bridge.four_ws.steady import settled_outcomes


def test_the_replayed_model_chooses_what_the_adapted_episode_chose():
    run = EvaluateRun(mazes=["gaps"], starts=3, perturb="4ws-stuck-steering", adapt=True)
    runs = run_suites(run, Reporters([]))
    task, rep = runs.task, runs.repertoire
    controller = task.controller(runs.arbitrator.kind, rep, runs.arbitrator.mapping)
    expected = expected_outcomes(rep, task.robot, "recorded")
    recorded = outcome_table(rep.behaviour, rep.heading)
    changed_any = False
    for k in range(3):
        path, choice = runs.adapted.paths[k], runs.adapted.choices[k]
        r = replay_model(rep, controller, runs.settings, expected, task.dt, path, choice,
                         runs.adapted.outputs[k])  # fmt: skip
        assert r.disagreements == 0
        assert len(r.observations) == len(choice) == len(path) - 1
        assert r.observations[0] == 0 and np.all(np.diff(r.observations) >= 0)
        assert np.all(r.observed <= r.observations)
        assert r.observations[-1] > 0 and len(r.in_model) == r.observed[-1]
        # Observed primitives are corrected; the choices differ from the grid's only
        # once something was observed.
        assert np.any(r.corrected[r.in_model] != recorded[r.in_model])
        assert not r.changed[r.observations == 0].any()
        changed_any |= bool(r.changed.any())
        # Without adaptation the same start ran the grid's choices.
        assert runs.suite.episodes[k].start == runs.adapted.episodes[k].start
    assert changed_any


def test_run_suites_gives_the_episodes_evaluate_reports():
    run = EvaluateRun(mazes=["gaps"], starts=2, perturb="4ws-slow-wheel", adapt=True)
    report = evaluate_run(run).report
    runs = run_suites(run, Reporters([]))
    assert [e.as_dict() for e in runs.suite.episodes] == report["episodes"]
    assert [e.as_dict() for e in runs.adapted.episodes] == report["adaptation"]["episodes"]
    # Traces of every episode, as long as it ran.
    for path, choice, out in zip(runs.suite.paths, runs.suite.choices, runs.suite.outputs,
                                 strict=True):  # fmt: skip
        assert len(choice) == len(out) == len(path) - 1 and out.shape[1] == 2


def test_settled_outcomes_of_a_slower_or_damaged_robot():
    rep = Repertoire.load(default_repertoire("4ws-5"))
    robot = FourWSRobot("4ws-5")
    commands = robot.commands(rep.genes)
    intact = settled_outcomes(commands, robot.limits, rep.eval_time)
    before = commands.copy()
    slow = settled_outcomes(commands, robot.limits, rep.eval_time, gain=0.5)
    np.testing.assert_array_equal(commands, before)  # the caller's commands untouched
    # Half the wheel speed: the same arcs at half the turn rate, half as long.
    np.testing.assert_allclose(slow[:, 2], 0.5 * intact[:, 2], atol=1e-9)
    # An intact damage row is the intact model, bit for bit.
    none = settled_outcomes(commands, robot.limits, rep.eval_time, damage=np.zeros(3))
    np.testing.assert_array_equal(none, intact)
    # Straight ahead at half the speed: half as far. A slow rear-left wheel turns the
    # robot left, one at the front right turns it right (docs/perturbations.md).
    ahead = np.array([[0.15, 0.0, 0.0, 0.0, 0.0]])
    straight = settled_outcomes(ahead, robot.limits, rep.eval_time)
    assert straight[0, 0] > 0.2 and straight[0, 1] == straight[0, 2] == 0.0
    half = settled_outcomes(ahead, robot.limits, rep.eval_time, gain=0.5)
    np.testing.assert_allclose(half, 0.5 * straight, atol=1e-12)
    slow = FOUR_WS_CODES["slow_wheel"]
    left = settled_outcomes(ahead, robot.limits, rep.eval_time, damage=np.array([slow, 2, 0.2]))
    right = settled_outcomes(ahead, robot.limits, rep.eval_time, damage=np.array([slow, 1, 0.2]))
    assert left[0, 2] > 0.05 and right[0, 2] < -0.05 and left[0, 0] < straight[0, 0]


def test_the_pictures_are_drawn_small(tmp_path):
    from offline_evolution.plots.adaptation import draw_pictures, save_error_over_time

    run = EvaluateRun(mazes=["gaps"], starts=2, perturb="4ws-stuck-steering", adapt=True)
    runs = run_suites(run, Reporters([]))
    task, rep = runs.task, runs.repertoire
    controller = task.controller(runs.arbitrator.kind, rep, runs.arbitrator.mapping)
    replays = [
        replay_model(rep, controller, runs.settings, None, task.dt, p, c, o)
        for p, c, o in zip(runs.adapted.paths, runs.adapted.choices, runs.adapted.outputs,
                           strict=True)
    ]  # fmt: skip
    paths = draw_pictures(runs, replays, tmp_path)
    errors = {"off": [0.2, 0.25], "on": [0.2, 0.1], "best": [0.06, 0.06]}
    sets = [{"set": "none", "execution_error": errors}, {"set": "x", "execution_error": errors}]
    paths.append(save_error_over_time(((0, 5), (5, 10)), sets, tmp_path))
    for path in paths:
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size < 200_000
