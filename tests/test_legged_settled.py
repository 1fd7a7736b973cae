"""A legged repertoire's settled outcomes: what the controller's whole executions observe.

:mod:`sim_bridge.legged.settled` runs each primitive after seeded predecessors, the gait
clock running on, on the intact robot on flat ground, and averages what the onboard rule
would observe (docs/design/adaptation.md, "What an observation is compared with");
``evorbc-evolve settled`` writes it for the arbitrator node and ``evaluate --adapt-expected
settled`` computes it the same way.
"""

from __future__ import annotations

import numpy as np
import pytest
from hexapod_helpers import tripod_repertoire

from evorbc_ros.adaptation import outcome_table
from evorbc_ros.adaptation.model import LEGGED_SETTINGS
from evorbc_ros.adaptation.settled import load_settled, save_settled, settled_path
from evorbc_ros.arbitration import Controller
from evorbc_ros.defaults import default_arbitrator, default_repertoire
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.diff_drive import DiffDriveGeometry
from offline_evolution.cli import main
from offline_evolution.maze_task.adapting import expected_outcomes
from sim_bridge.hexapod.physics import hexapod_robot_settings
from sim_bridge.legged.settled import context_outcomes
from sim_bridge.robots import make_robot


@pytest.fixture(scope="module")
def tripods():
    """Six tripod gaits (straight, curving either way, and their mirror images)."""
    return tripod_repertoire()


def test_tripod_gaits_walk_as_recorded_deterministically_whatever_else_is_computed(tripods):
    settings = hexapod_robot_settings()
    rows = context_outcomes(settings, tripods.genes, tripods.eval_time)  # 4 contexts
    assert rows.shape == (6, 4, 3) and np.isfinite(rows).all()
    # One primitive alone: the same bits (each context seeded by its primitive, from rest).
    alone = context_outcomes(settings, tripods.genes, tripods.eval_time, indices=[4])
    np.testing.assert_array_equal(alone[0], rows[4])
    mean = rows.mean(axis=1)
    # Executed after other gaits, every tripod still walks forward as recorded, though
    # slower over half a gait period (its recorded 2 s: 0.42-0.52 m); the recorded turns
    # (0.02-0.14 rad) are within one 0.5 s execution's sway, so no sign is asserted.
    assert (tripods.behaviour[:, 0] > 0.4).all()
    assert (mean[:, 0] > 0.05).all() and (mean[:, 0] < tripods.behaviour[:, 0]).all()
    # Other seeds draw other predecessors and phases: another reading.
    other = context_outcomes(settings, tripods.genes, tripods.eval_time, contexts=1, seed=1)
    assert not np.array_equal(other[:, 0], rows[:, 0])


def test_the_command_writes_what_evaluate_compares_with_for_the_node(tripods, tmp_path, capsys):
    path = tmp_path / "tripods.repertoire.json"
    tripods.save(path)
    assert main(["settled", str(path)]) == 0
    out = settled_path(path)
    assert capsys.readouterr().out.strip() == f"6 settled outcomes of hexapod -> {out}"
    rows = load_settled(out, Repertoire.load(path))  # what the arbitrator node reads
    # evaluate --adapt-expected settled: the maze task's robot settings, the same bits.
    offline = expected_outcomes(tripods, hexapod_robot_settings(), "settled")
    np.testing.assert_array_equal(rows.view(np.int64), offline.view(np.int64))
    # The mean of the default contexts.
    samples = context_outcomes(hexapod_robot_settings(), tripods.genes, tripods.eval_time)
    np.testing.assert_array_equal(rows, samples.mean(axis=1))


def test_bad_input_is_refused_in_one_line(tripods):
    settings = hexapod_robot_settings()
    genes, t = tripods.genes, tripods.eval_time
    cases = [
        ((settings, genes[:, :5], t), {}, "genes must be (n >= 2, 37) for the hexapod, got (6, 5)"),
        ((settings, genes[:1], t), {}, "genes must be (n >= 2, 37) for the hexapod, got (1, 37)"),
        ((settings, genes, 0.0), {}, "horizon must be > 0, got 0.0"),
        ((settings, genes, t), {"window": 0}, "window must be > 0, got 0"),
        ((settings, genes, t), {"indices": [6]}, "indices must be in [0, 6)"),
    ]
    for args, kwargs, problem in cases:
        with pytest.raises(ValueError) as e:
            context_outcomes(*args, **kwargs)
        assert str(e.value) == f"legged settled outcomes: {problem}"


def test_the_command_refuses_a_differential_drive_repertoire_in_one_line(tmp_path, capsys):
    robot = make_robot("turtlebot3-burger")
    assert isinstance(robot.geometry, DiffDriveGeometry)
    rep = Repertoire(
        robot="turtlebot3-burger",
        parameters=robot.parameter_specs,
        genes=np.array([[0.5, 0.0], [0.5, 0.5]]),
        behaviour=np.array([[0.3, 0.0], [0.2, 0.1]]),
        heading=np.array([0.0, 0.5]),
        quality=np.ones(2),
        metric="circular",
        eval_time=2.0,
        bin_size=0.05,
        seed=0,
    )
    path = tmp_path / "b.repertoire.json"
    rep.save(path)
    assert main(["settled", str(path), "--out", str(tmp_path / "b.json")]) == 1
    err = capsys.readouterr().err.strip()
    assert err == (
        f"evorbc-evolve: error: {path}: adaptation expected settled: only for 4WS and legged "
        "robots, not turtlebot3-burger"
    )
    assert not (tmp_path / "b.json").exists()


def test_the_hexapod_node_adapts_against_a_settled_file_beside_its_repertoire(tmp_path):
    # The arbitrator node's path (adaptation_expected: settled) has nothing wheeled in it:
    # the shipped hexapod controller reads a file in the format the command writes and
    # adapts against it with the legged settings. (The rows here are the recorded outcomes
    # shifted, not computed: what is checked is the node's path, the computation above.)
    rep = Repertoire.load(default_repertoire("hexapod"))
    rows = outcome_table(rep.behaviour, rep.heading) + np.array([0.01, -0.02, 0.03])
    path = tmp_path / "hexapod.settled.json"
    save_settled(path, rows, rep)
    controller = Controller(str(default_arbitrator("hexapod")))
    read = controller.settled_outcomes(str(path))
    np.testing.assert_array_equal(read.view(np.int64), rows.view(np.int64))
    controller.enable_adaptation(expected=read)
    assert controller.adaptation.settings == LEGGED_SETTINGS
    np.testing.assert_array_equal(controller.adaptation.model.expected, rows)
