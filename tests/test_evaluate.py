"""Held-out evaluation (``evorbc-evolve evaluate``) and perturbed worlds (issue 21)."""

from __future__ import annotations

import functools
import json

import numpy as np
import pytest
import yaml

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.defaults import default_repertoire, paper_arbitrator
from evorbc_ros.repertoire import Repertoire
from offline_evolution.cli import main
from offline_evolution.maze_task.base import MazeTaskSettings
from offline_evolution.maze_task.evaluation import evaluate_suite, reach_interval, stalled
from offline_evolution.maze_task.perturbation import (
    NONE,
    QUANTITIES,
    PerturbationSet,
    load_perturbations,
)
from offline_evolution.maze_task.task import make_task
from sim_bridge.maze import load_named_maze

PAPER = ("obstacle", "zigzag", "baffles", "corridors", "gaps")
#: Every quantity at its identity value, given explicitly: a set that perturbs nothing.
ZERO = PerturbationSet(name="zero", **{k: (v[0], v[0]) for k, v in QUANTITIES.items()})


@functools.cache
def shipped_4ws():
    """The paper-protocol 4ws-5 controller (its 4-sector layout) in the paper mazes."""
    arb = ArbitratorFile.load(paper_arbitrator("4ws-5"))
    task = make_task(MazeTaskSettings(PAPER, 120.0, 1, "sensors/4ws.yaml"), "4ws-5")
    controller = task.controller("evorbc", Repertoire.load(default_repertoire()), arb.mapping)
    return task, arb.network, controller


def run_4ws(perturbation=NONE, starts=4, seed=0):
    task, network, controller = shipped_4ws()
    return evaluate_suite(task, network, controller, starts, seed, perturbation)


def outcome(suite):
    return (
        [e.as_dict() for e in suite.episodes],
        [p.tolist() for p in suite.paths],
    )


def test_shipped_4ws_controller_reaches_the_target_from_most_random_starts(tmp_path, capsys):
    out, picture = tmp_path / "report.json", tmp_path / "suite.png"
    argv = ["evaluate", "--paper", "--starts", "20", "--seed", "1", "--out", str(out)]
    assert main([*argv, "--plot", str(picture)]) == 0
    table = capsys.readouterr().out
    report = json.loads(out.read_text())
    assert report["arbitrator"] == str(paper_arbitrator("4ws-5"))
    assert report["mazes"] == list(PAPER) and report["perturbation"]["name"] == "none"
    assert [r["episodes"] for r in report["per_maze"]] == [20] * 5
    overall = report["overall"]
    print(f"paper-protocol 4ws-5, paper mazes, 5 x 20 random starts (seed 1): {overall}")
    # The issue measured 95 %; seeds 0-3 give 91-94 % here.
    assert overall["reach_rate"] >= 0.9
    assert overall["reached"] == sum(e["reached"] for e in report["episodes"])
    assert overall["stalls"] >= 1  # it does stall in some (gaps: at a wall's end)
    assert "all" in table and "reach %" in table and "gaps" in table
    assert "95 % interval" in table
    low, high = overall["reach_interval"]
    assert low < overall["reach_rate"] < high  # reached neither none nor all 100
    assert (low, high) == reach_interval(overall["reached"], overall["episodes"])
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # Each episode says where it ended: inside the target circle if and only if it reached.
    for e in report["episodes"]:
        maze = load_named_maze(e["maze"])
        miss = np.hypot(e["end"][0] - maze.target[0], e["end"][1] - maze.target[1])
        assert miss == pytest.approx(e["final_distance"], abs=1e-5)
        assert (miss <= maze.target_radius + 1e-5) == e["reached"]


def test_a_perturbation_changes_outcomes_and_the_identity_set_changes_nothing():
    none = outcome(run_4ws())
    assert outcome(run_4ws(ZERO)) == none  # runs the perturbed kernel path, bit for bit
    realistic = load_perturbations("realistic")
    assert outcome(run_4ws(realistic)) != none
    assert outcome(run_4ws(realistic)) == outcome(run_4ws(realistic))  # same seed
    assert outcome(run_4ws(realistic, seed=1)) != outcome(run_4ws(realistic))


@pytest.mark.parametrize(
    "quantity, value",
    [
        ("wheel_speed_gain", (0.5, 0.5)),
        ("latency_cycles", (1, 1)),
        ("range_noise", (0.05, 0.05)),
        ("dropout", (0.3, 0.3)),
        ("start_position", (0.04, 0.04)),
        ("start_heading_deg", (20, 20)),
    ],
)
def test_each_4ws_perturbation_acts(quantity, value):
    base = run_4ws(starts=2)
    one = run_4ws(PerturbationSet(name=quantity, **{quantity: value}), starts=2)
    assert outcome(one) != outcome(base)
    assert one.applied == (quantity,) and one.not_applicable == ()
    if quantity == "wheel_speed_gain":  # at half speed the first 10 s cover about half the way
        moved = [np.hypot(*np.diff(p[[0, 100], :2], axis=0)[0]) for p in base.paths]
        halved = [np.hypot(*np.diff(p[[0, 100], :2], axis=0)[0]) for p in one.paths]
        assert np.mean(halved) < 0.7 * np.mean(moved)


def test_the_4ws_kinematic_model_names_what_it_cannot_perturb():
    suite = run_4ws(load_perturbations("realistic"), starts=1)
    assert set(suite.not_applicable) == {
        "friction",
        "body_mass",
        "payload",
        "servo_strength",
        "servo_speed",
    }
    assert "wheel_speed_gain" in suite.applied and "latency_cycles" in suite.applied


@pytest.mark.slow
def test_hexapod_perturbations_act_and_are_undone():
    arb = ArbitratorFile.load(paper_arbitrator("hexapod"))
    settings = MazeTaskSettings(("hexapod",), 3.0, 1, "sensors/hexapod.yaml")
    task = make_task(settings, "hexapod", workers=1)
    rep = Repertoire.load(default_repertoire("hexapod"))
    controller = task.controller("evorbc", rep, arb.mapping)
    try:
        run = functools.partial(evaluate_suite, task, arb.network, controller, 1, 0)
        none = outcome(run())
        assert outcome(run(ZERO)) == none
        weak = PerturbationSet(name="weak", servo_strength=(0.3, 0.3), friction=(0.3, 0.3))
        assert outcome(run(weak)) != none
        assert outcome(run()) == none  # friction and torques were put back
        heavy = PerturbationSet(name="heavy", body_mass=(1.5, 1.5), latency_cycles=(1, 1))
        assert outcome(run(heavy)) != none
        assert outcome(run()) == none
        assert run(weak).not_applicable == ()
    finally:
        task.close()


def test_stall_needs_a_whole_window_without_progress():
    going = np.linspace(10.0, 0.0, 500)
    assert not stalled(going, 300, 0.1)
    waiting = np.concatenate([np.full(301, 10.0), going])
    assert stalled(waiting, 300, 0.1)
    back_and_forth = np.concatenate([going[:200], going[:200][::-1], going])
    assert stalled(back_and_forth, 300, 0.1)
    assert not stalled(np.full(200, 5.0), 300, 0.1)  # shorter than the window


def test_evaluate_on_generated_mazes_and_maze_folders(tmp_path, capsys):
    folder = tmp_path / "held"
    assert (
        main(["mazes", "--count", "2", "--seed", "5", "--out", str(folder), "--plot", "none"]) == 0
    )
    capsys.readouterr()
    args = ["evaluate", "--starts", "2", "--json", "--mazes", str(folder), "gaps"]
    assert main([*args, "--generated", "1", "--generated-seed", "6"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["mazes"] == ["gen5-000", "gen5-001", "gaps", "gen6-000"]
    assert report["generated"] == {"count": 1, "seed": 6}
    assert report["overall"]["episodes"] == 8


def test_bad_perturbation_sets_are_named(tmp_path, capsys):
    assert main(["evaluate", "--perturb", "rough", "--starts", "1"]) == 1
    err = capsys.readouterr().err
    assert "unknown perturbation set 'rough'" in err and "realistic" in err
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump({"friction": [1.2, 0.8]}))
    assert main(["evaluate", "--perturb", str(path), "--starts", "1"]) == 1
    err = capsys.readouterr().err
    assert f"{path}: friction must be [low, high]" in err and len(err.strip().splitlines()) == 1
    path.write_text(yaml.safe_dump({"frictions": [1, 1]}))
    assert main(["evaluate", "--perturb", str(path), "--starts", "1"]) == 1
    assert "unknown key 'frictions'" in capsys.readouterr().err


def test_an_empty_maze_folder_and_one_file_for_two_outputs_are_refused(tmp_path, capsys):
    assert main(["evaluate", "--mazes", str(tmp_path)]) == 1
    assert "holds no .yaml maze files" in capsys.readouterr().err
    both = str(tmp_path / "r.png")
    assert main(["evaluate", "--plot", both, "--out", both]) == 1
    assert f"--out {both} is the same file as --plot" in capsys.readouterr().err


def test_reach_interval_is_wilsons():
    # 15 of 20 (the hexapod's own-maze figure): Wilson's 95 % interval is 0.531-0.888.
    low, high = reach_interval(15, 20)
    assert low == pytest.approx(0.5313, abs=1e-4) and high == pytest.approx(0.8881, abs=1e-4)
    # It stays inside [0, 1] and is not empty at the ends, where the normal one collapses.
    low, high = reach_interval(0, 20)
    assert low == 0.0 and 0.15 < high < 0.17
    low, high = reach_interval(20, 20)
    assert 0.83 < low < 0.85 and high == 1.0
    # More episodes, a narrower interval around the same rate.
    wide, narrow = reach_interval(15, 20), reach_interval(750, 1000)
    assert narrow[0] > wide[0] and narrow[1] < wide[1]
    assert reach_interval(0, 0) == (0.0, 1.0)


def shipped_a1_suite(training: dict | None = None):
    """The shipped A1 controller from 10 seeded starts in its own maze: ``(task, result)``;
    with ``training``, scored as a training run of seed 1 scores them."""
    from evorbc_ros.defaults import default_arbitrator

    arb = ArbitratorFile.load(default_arbitrator("a1"))
    values = {**arb.evolution["task"], **({"training": training} if training else {})}
    task = make_task(MazeTaskSettings.from_dict(values, "the A1's task"), "a1", workers=1)
    try:
        if training:
            task.start_training("a1", seed=1)
        rep = Repertoire.load(default_repertoire("a1"))
        controller = task.controller("evorbc", rep, arb.mapping)
        return task, evaluate_suite(task, arb.network, controller, 10, 0)
    finally:
        task.close()


def test_a_legged_fall_is_timed_when_it_happens_as_replay_times_it():
    # The shipped A1 controller from 10 seeded starts in its own maze: 3 of them fall
    # (at 1.8, 7.1 and 29.1 s). Each fallen episode's time is the cycles it ran, as
    # replay and the bridge report a fall ("fell after 7.1 s"), not the episode's 30 s,
    # and its recorded path ends there.
    task, result = shipped_a1_suite()
    fell = [k for k, e in enumerate(result.episodes) if e.fell]
    assert fell, "no episode fell: pick starts in which the shipped A1 falls"
    for k in fell:
        episode, path = result.episodes[k], result.paths[k]
        assert not episode.reached and episode.time < task.settings.episode_time
        assert round(episode.time / task.dt) == len(path) - 1
    ran_out = [e for e in result.episodes if not e.reached and not e.fell]
    assert all(e.time == pytest.approx(task.settings.episode_time) for e in ran_out)


def test_a_fall_penalty_lowers_exactly_the_fallen_episodes_fitness():
    # training.fall_penalty: eq. 5 scores a fall by the progress made before it, as a
    # time-out; the penalty is subtracted from the episodes that fell, and only those.
    training = {"generated": 1, "maze_seed": 1, "post_mazes": 0}
    _, plain = shipped_a1_suite(training)
    _, penalised = shipped_a1_suite({**training, "fall_penalty": 1.0})
    fell = np.array([e.fell for e in plain.episodes])
    assert fell.any() and not fell.all()
    assert [e.fell for e in penalised.episodes] == fell.tolist()  # the same episodes
    got = np.array([e.fitness for e in penalised.episodes])
    want = np.array([e.fitness for e in plain.episodes]) - fell
    np.testing.assert_array_equal(got, want)
