"""MAP-Elites as a library: the ask/tell loop on plain arrays, driven by the caller."""

import numpy as np
import pytest
from conftest import small_settings

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.config import ConfigError
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.primitive import ParameterSpec
from offline_evolution.checkpoint import CheckpointError
from offline_evolution.cli import main
from offline_evolution.quality import quality_metric
from offline_evolution.repertoire.map_elites import MapElites
from offline_evolution.repertoire.settings import SettingError
from sim_bridge.robots import make_robot

#: A made-up two-parameter robot for the checks that need no physics.
TWO = (ParameterSpec("a", "m/s", -1.0, 1.0), ParameterSpec("b", "rad/s", -2.0, 2.0))


def by_hand(settings, checkpoint_after=None, path=None) -> MapElites:
    """Drive a run with the 4ws-5 robot's own evaluation through ask and tell only."""
    robot = make_robot(settings.robot)
    metric = quality_metric(settings.metric)
    run = MapElites(
        settings,
        parameters=robot.parameter_specs,
        max_reach=robot.max_reach(settings.eval_time),
    )
    if path is not None and path.exists():
        run.restore(path)
    while not run.finished:
        genes = run.ask()
        outcome = robot.evaluate_primitives(genes, settings.eval_time)
        run.tell(genes, metric(outcome), outcome.displacement, outcome.heading)
        if checkpoint_after is not None and run.batches_done == checkpoint_after:
            run.save(path)
            return run
    return run


def linear_evaluation(genes):
    """Behaviour a linear function of the genes, quality highest near the middle."""
    behaviour = 0.3 * genes[:, :2]
    return 1.0 - np.abs(genes[:, 0]), behaviour, np.arctan2(genes[:, 1], 1.0)


def own_run(**overrides) -> MapElites:
    settings = small_settings(robot="2ws-2", iterations=5, **overrides)
    return MapElites(settings, parameters=TWO, max_reach=0.3)


def test_the_loop_driven_by_hand_with_the_robots_evaluation_reproduces_generate_repertoire(
    small_repertoire,
):
    mine = by_hand(small_settings()).repertoire()
    for field in ("genes", "behaviour", "heading", "quality"):
        np.testing.assert_array_equal(getattr(mine, field), getattr(small_repertoire, field))
    assert mine.fingerprint() == small_repertoire.fingerprint()
    assert mine.archive == small_repertoire.archive
    recorded = {k: v for k, v in mine.algorithm.items() if k not in ("evaluation", "max_reach")}
    assert recorded == small_repertoire.algorithm
    assert mine.algorithm["evaluation"] == "ask/tell by the caller"


def test_a_repertoire_from_your_own_evaluation_goes_through_the_arbitrator_cli(
    tmp_path, capsys, small_neat_file, small_task_file
):
    rep = tmp_path / "mine.json"
    by_hand(small_settings(iterations=5)).repertoire().save(rep)
    out = tmp_path / "a.json"
    argv = ["arbitrator", "--repertoire", rep, "--generations", 1, "--seed", 1]
    argv += ["--neat-config", small_neat_file, "--task", small_task_file, "--out", out]
    code = main([str(a) for a in argv])
    assert code == 0, capsys.readouterr().err
    arb = ArbitratorFile.load(out)
    assert arb.repertoire["fingerprint"] == Repertoire.load(rep).fingerprint()


def test_a_checkpoint_of_your_own_run_resumes_to_the_uninterrupted_result(tmp_path):
    path = tmp_path / "own.checkpoint.npz"
    whole = own_run()
    while not whole.finished:
        genes = whole.ask()
        whole.tell(genes, *linear_evaluation(genes))
    first = own_run()
    for _ in range(6):  # inside the initial batch of 400 in pieces of 100, then mutants
        genes = first.ask()
        first.tell(genes, *linear_evaluation(genes))
    first.save(path)
    resumed = own_run()
    resumed.restore(path)
    assert resumed.evaluations == 600
    while not resumed.finished:
        genes = resumed.ask()
        resumed.tell(genes, *linear_evaluation(genes))
    a, b = whole.repertoire(), resumed.repertoire()
    assert a.fingerprint() == b.fingerprint() and len(a) > 20
    assert a.parameters == TWO and a.algorithm["max_reach"] == 0.3
    # Another stated design cannot resume it.
    other = MapElites(small_settings(robot="2ws-2", iterations=5), parameters=TWO, max_reach=0.5)
    with pytest.raises(CheckpointError, match=r"max_reach is 0\.3 in the checkpoint but 0\.5 now"):
        other.restore(path)


def test_tell_keeps_the_best_per_cell_and_discards_nan_and_outside():
    run = own_run()
    genes = np.array([[0.1, 0.0], [0.2, 0.0], [0.3, 0.0], [0.4, 0.0]])
    quality = np.array([0.5, 0.7, np.nan, 0.9])
    behaviour = np.array([[0.1, 0.1], [0.11, 0.11], [0.2, 0.2], [5.0, 0.0]])
    run.tell(genes, quality, behaviour, np.zeros(4))
    assert len(run.archive) == 1 and run.discarded == 2 and run.evaluations == 4
    assert run.archive.data("solution")[0, 0] == 0.2


@pytest.mark.parametrize(
    ("arrays", "message"),
    [
        ({"genes": np.zeros((3, 3))}, r"genes has shape \(3, 3\), expected \(3, 2\)"),
        ({"quality": np.zeros(2)}, r"quality has shape \(2,\), expected \(3,\)"),
        ({"behaviour": np.zeros((3, 3))}, r"behaviour has shape \(3, 3\), expected \(3, 2\)"),
        ({"heading": np.zeros((3, 1))}, r"heading has shape \(3, 1\), expected \(3,\)"),
        ({"genes": np.full((3, 2), 1.5)}, r"genes must be finite and lie in \[-1.0, 1.0\]"),
        ({"genes": np.full((3, 2), np.nan)}, "genes must be finite"),
    ],
)
def test_tell_refuses_arrays_that_do_not_fit(arrays, message):
    given = {
        "genes": np.zeros((3, 2)),
        "quality": np.ones(3),
        "behaviour": np.zeros((3, 2)),
        "heading": np.zeros(3),
    }
    run = own_run()
    with pytest.raises(ValueError, match=message):
        run.tell(**{**given, **arrays})
    assert run.evaluations == 0 and len(run.archive) == 0


def test_ask_twice_or_save_mid_batch_is_refused(tmp_path):
    run = own_run()
    genes = run.ask()
    with pytest.raises(RuntimeError, match="tell\\(\\) the 100 genes asked for before asking"):
        run.ask()
    with pytest.raises(RuntimeError, match="before saving"):
        run.save(tmp_path / "c.npz")
    run.tell(genes, *linear_evaluation(genes))
    assert run.ask().shape == (100, 2)


def test_without_a_robot_there_is_nothing_to_step():
    with pytest.raises(RuntimeError, match="no simulated robot: evaluate the genes yourself"):
        own_run().step()


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"parameters": TWO}, "parameters and max_reach are both needed"),
        ({"max_reach": 0.3}, "parameters and max_reach are both needed"),
        ({"parameters": (), "max_reach": 0.3}, "parameters must be one or more ParameterSpec"),
        ({"parameters": ("a",), "max_reach": 0.3}, "parameters must be one or more"),
        (
            {"parameters": (ParameterSpec("a", "m", 1.0, 1.0),), "max_reach": 0.3},
            r"parameters \[0\] \(a\) needs finite low < high",
        ),
        ({"parameters": TWO, "max_reach": 0.0}, "max_reach must be a finite number of metres > 0"),
        ({"parameters": TWO, "max_reach": "1"}, "max_reach must be a number of metres"),
    ],
)
def test_your_own_parameters_and_reach_are_checked(kwargs, message):
    with pytest.raises(SettingError, match=message):
        MapElites(small_settings(robot="2ws-2"), **kwargs)


def test_settings_given_in_code_are_checked_like_a_files():
    import dataclasses

    settings = dataclasses.replace(small_settings(robot="2ws-2"), bin_size=0.0)
    with pytest.raises(ConfigError, match=r"MapElitesSettings: bin_size must be >= 0\.0001"):
        MapElites(settings, parameters=TWO, max_reach=0.3)
