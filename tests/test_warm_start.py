"""Starting a NEAT run from an evolved controller (``--init-from``, docs/design.md section 8).

The first population is the network unchanged plus mutated copies; inputs are matched by
name; the run is seeded, resumes exactly and records where it started.
"""

import dataclasses
import json

import pytest
from conftest import SMALL_TASK, evolution_settings

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.config import ConfigError, config_dir
from evorbc_ros.defaults import DATA_DIR
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.sensors import SensorLayout
from offline_evolution.arbitrator.evolve import Evolution, evolve, network_spec
from offline_evolution.arbitrator.neat_config import load_neat_config
from offline_evolution.arbitrator.neat_state import genome_to_dict
from offline_evolution.arbitrator.warm_start import (
    genome_from_network,
    load_initial_network,
    network_fingerprint,
)
from offline_evolution.checkpoint import CheckpointError, Interrupted
from offline_evolution.cli import main

DATA = DATA_DIR
PAPER_4WS = DATA / "4ws-5-paper.arbitrator.json"  # sensors/4ws.yaml, SMALL_TASK's layout


def layout(name: str) -> SensorLayout:
    return SensorLayout.load(config_dir() / "sensors" / f"{name}.yaml")


def with_motion(base: str) -> SensorLayout:
    """``base`` plus the motion input (appended last)."""
    data = layout(base).to_dict()
    return SensorLayout.from_dict({**data, "motion": {"window": 1.0, "distance": 0.1}}, "test")


@pytest.fixture(scope="module")
def repertoire():
    return Repertoire.load(DATA / "4ws-5.repertoire.json")


def warm(neat_file, repertoire, task=SMALL_TASK, **changes):
    """A small 4ws-5 run started from the paper-protocol controller."""
    network = load_initial_network(PAPER_4WS, "4ws-5", "evorbc", "polar", layout("4ws"))
    settings = evolution_settings(
        neat_file,
        repertoire,
        task,
        initial_network=network_fingerprint(network),
        initial_network_file=str(PAPER_4WS),
        **changes,
    )
    return settings, network


@pytest.mark.parametrize(
    "file, robot, sensors",
    [(PAPER_4WS, "4ws-5", "4ws"), (DATA / "hexapod-paper.arbitrator.json", "hexapod", "hexapod")],
)
def test_a_genome_from_a_network_is_that_network(file, robot, sensors):
    import neat

    arb = ArbitratorFile.load(file)
    ini = "4ws.ini" if robot == "4ws-5" else "hexapod.ini"
    config = load_neat_config(config_dir() / "neat" / ini, layout(sensors).n_inputs, 2)
    neat.Population(config, seed=0)  # sets up the innovation tracker
    network = load_initial_network(file, robot, "evorbc", "polar", layout(sensors))
    assert network == arb.network  # the same layout: nothing renumbered
    genome = genome_from_network(network, 7, config)
    assert network_spec(genome, config) == arb.network
    # copies line up in crossover: the same innovation numbers
    again = genome_from_network(network, 8, config)
    assert [c.innovation for c in genome.connections.values()] == [
        c.innovation for c in again.connections.values()
    ]


def test_the_first_population_is_the_network_and_mutated_copies(small_neat_file, repertoire):
    settings, network = warm(small_neat_file, repertoire)
    runs = [Evolution(settings, repertoire, initial_network=network) for _ in range(2)]
    try:
        pop = runs[0].population
        genomes = [pop.population[k] for k in sorted(pop.population)]
        assert len(genomes) == 24
        specs = [network_spec(g, pop.config) for g in genomes]
        assert specs[0] == network
        assert all(s != network for s in specs[1:])
        # mutated copies, not random networks: most genes are the network's
        for s in specs[1:]:
            kept = {(c.source, c.target) for c in network.connections}
            assert len(kept & {(c.source, c.target) for c in s.connections}) >= len(kept) - 1
        assert len(pop.species.species) >= 1
        assert sum(len(s.members) for s in pop.species.species.values()) == 24
        # seeded: the same settings give the same population
        other = runs[1].population
        assert [genome_to_dict(g) for g in genomes] == [
            genome_to_dict(other.population[k]) for k in sorted(other.population)
        ]
    finally:
        for run in runs:
            run.close()


def test_a_warm_start_keeps_what_the_controller_does(small_neat_file, repertoire):
    # The paper-protocol controller reaches the target from most random starts of its
    # training mazes in its 120 s; a random first population almost never does.
    task = {**SMALL_TASK, "episode_time": 120.0}
    settings, network = warm(small_neat_file, repertoire, task, generations=1)
    started = evolve(settings, repertoire, initial_network=network)
    cold = evolve(evolution_settings(small_neat_file, repertoire, task, generations=1), repertoire)
    first, scratch = started.history[0], cold.history[0]
    assert first.best_reached == 2  # both mazes, by the unchanged copy at least
    assert first.mean > scratch.mean + 0.2
    assert first.best >= scratch.best


def test_a_warm_started_run_resumes_to_the_straight_result(tmp_path, small_neat_file, repertoire):
    settings, network = warm(small_neat_file, repertoire, generations=3)
    straight = evolve(settings, repertoire, initial_network=network)
    ckpt = tmp_path / "c.json"
    stops = iter([True])
    with pytest.raises(Interrupted):
        evolve(
            settings, repertoire, checkpoint=ckpt, checkpoint_every=1,
            should_stop=lambda: next(stops, False), initial_network=network,
        )  # fmt: skip
    resumed = evolve(settings, repertoire, checkpoint=ckpt, initial_network=network)
    assert [h.best for h in resumed.history] == [h.best for h in straight.history]
    assert resumed.selected_network == straight.selected_network
    # A checkpoint of a warm-started run is another run's for a cold start, and back.
    evolve(settings, repertoire, checkpoint=ckpt, keep_checkpoint=True, initial_network=network)
    cold = dataclasses.replace(settings, initial_network=None, initial_network_file=None)
    with pytest.raises(CheckpointError, match="the run started from the network of"):
        evolve(cold, repertoire, checkpoint=ckpt)
    evolve(cold, repertoire, checkpoint=tmp_path / "cold.json", keep_checkpoint=True)
    with pytest.raises(CheckpointError, match="started from random networks"):
        evolve(settings, repertoire, checkpoint=tmp_path / "cold.json", initial_network=network)


def test_a_checkpoint_from_before_warm_starts_resumes(tmp_path, small_neat_file, repertoire):
    settings = evolution_settings(small_neat_file, repertoire, SMALL_TASK, generations=2)
    ckpt = tmp_path / "c.json"
    evolve(settings, repertoire, checkpoint=ckpt, keep_checkpoint=True)
    data = json.loads(ckpt.read_text())
    for key in ("initial_network", "initial_network_file"):
        del data["settings"][key]
    ckpt.write_text(json.dumps(data))
    assert evolve(settings, repertoire, checkpoint=ckpt).history[-1].generation == 1


def test_the_network_must_be_the_one_the_settings_name(small_neat_file, repertoire):
    settings, _ = warm(small_neat_file, repertoire)
    other = load_initial_network(
        DATA / "4ws-5.arbitrator.json", "4ws-5", "evorbc", "polar", layout("4ws-p8m")
    )
    with pytest.raises(ConfigError, match="not the one the run settings name"):
        Evolution(settings, repertoire, initial_network=other)
    # Without it, such a run can only continue from a checkpoint.
    run = Evolution(settings, repertoire)
    try:
        with pytest.raises(ValueError, match="needs it or a checkpoint"):
            run.step()
    finally:
        run.close()


def test_inputs_are_matched_by_name():
    hexapod = DATA / "hexapod-paper.arbitrator.json"
    plain = load_initial_network(hexapod, "hexapod", "evorbc", "polar", layout("hexapod"))
    moved = load_initial_network(hexapod, "hexapod", "evorbc", "polar", with_motion("hexapod"))
    # motion comes last: the file's inputs keep their keys and motion starts unconnected
    assert moved.input_keys == (*plain.input_keys, -7)
    assert moved.connections == plain.connections
    # a layout with the beams in another order: the connections follow the names
    data = layout("4ws").to_dict()
    data["rangefinders"]["angles_deg"] = list(reversed(data["rangefinders"]["angles_deg"]))
    turned = SensorLayout.from_dict(data, "test")
    paper = load_initial_network(PAPER_4WS, "4ws-5", "evorbc", "polar", layout("4ws"))
    renamed = load_initial_network(PAPER_4WS, "4ws-5", "evorbc", "polar", turned)
    names, new_names = layout("4ws").input_names(), turned.input_names()
    for a, b in zip(paper.connections, renamed.connections, strict=True):
        if a.source < 0:
            assert new_names[-b.source - 1] == names[-a.source - 1]
        else:
            assert a == b


@pytest.mark.parametrize(
    "file, robot, mapping, sensors, message",
    [
        (PAPER_4WS, "hexapod", "polar", "4ws", "its robot is '4ws-5', this run's is 'hexapod'"),
        (PAPER_4WS, "4ws-5", "cartesian", "4ws", "its mapping is 'polar'"),
        # the file reads the motion input; the paper layout has none
        (DATA / "4ws-5.arbitrator.json", "4ws-5", "polar", "4ws", "reads range_090, range_270"),
        # same names, other goal-sector width: they would mean something else
        (PAPER_4WS, "4ws-5", "polar", "4ws-8sectors", "goal_sectors.width_deg is 90.0"),
    ],
)
def test_a_network_that_does_not_fit_is_refused(file, robot, mapping, sensors, message):
    with pytest.raises(ConfigError) as info:
        load_initial_network(file, robot, "evorbc", mapping, layout(sensors))
    assert str(info.value).startswith(f"{file}: ") and message in str(info.value)
    assert "\n" not in str(info.value)


def test_the_cli_starts_from_a_file_and_records_it(
    tmp_path, capsys, repertoire, small_neat_file, small_task_file
):
    argv = ["arbitrator", "--repertoire", DATA / "4ws-5.repertoire.json", "--quiet"]
    argv += ["--neat-config", small_neat_file, "--task", small_task_file, "--generations", 1]
    out = tmp_path / "a.json"
    assert main([str(a) for a in [*argv, "--init-from", PAPER_4WS, "--out", out]]) == 0
    record = ArbitratorFile.load(out).evolution["initial_network"]
    network = ArbitratorFile.load(PAPER_4WS).network
    assert record == {"file": PAPER_4WS.name, "fingerprint": network_fingerprint(network)}
    capsys.readouterr()
    # bad files: one line, exit status 1, nothing written
    bad = tmp_path / "bad.json"
    bad.write_text("{}")
    for given, message in (
        (bad, "not an arbitrator file"),
        (DATA / "hexapod-paper.arbitrator.json", "its robot is 'hexapod'"),
        (tmp_path / "missing.json", "missing.json"),
    ):
        code = main([str(a) for a in [*argv, "--init-from", given, "--out", tmp_path / "b.json"]])
        err = capsys.readouterr().err
        assert code == 1 and message in err and "Traceback" not in err
        assert len(err.strip().splitlines()) == 1
        assert not (tmp_path / "b.json").exists()


def test_the_first_speciation_uses_the_settings_threshold(small_neat_file, repertoire):
    # The discarded random population was speciated once (the threshold steered one step);
    # the seeded one is speciated from the settings' value again, as a cold run's was.
    settings, network = warm(small_neat_file, repertoire)
    warm_run = Evolution(settings, repertoire, initial_network=network)
    cold_run = Evolution(evolution_settings(small_neat_file, repertoire, SMALL_TASK), repertoire)
    try:
        configured = load_neat_config(small_neat_file, 10, 2).species_set_config
        step = configured.threshold_step
        for run in (warm_run, cold_run):
            moved = run.config.species_set_config.compatibility_threshold
            assert abs(moved - configured.compatibility_threshold) == pytest.approx(step)
    finally:
        warm_run.close()
        cold_run.close()


def edited_paper_file(tmp_path, change) -> str:
    data = json.loads(PAPER_4WS.read_text())
    change(data)
    path = tmp_path / f"{change.__name__}.arbitrator.json"
    path.write_text(json.dumps(data))
    return path


def test_a_file_whose_inputs_are_keyed_in_another_order_computes_the_same(tmp_path):
    import numpy as np

    def reverse(data):
        data["network"]["inputs"].reverse()

    path = edited_paper_file(tmp_path, reverse)
    network = load_initial_network(path, "4ws-5", "evorbc", "polar", layout("4ws"))
    theirs = ArbitratorFile.load(path).network.compile()
    ours = network.compile()
    rng = np.random.default_rng(0)
    for _ in range(20):
        x = rng.random(10)
        np.testing.assert_array_equal(ours.activate(x), theirs.activate(x))
    assert not np.array_equal(
        ours.activate(x), ArbitratorFile.load(PAPER_4WS).network.compile().activate(x)
    )


def test_a_run_resumed_without_the_network_says_what_to_give(tmp_path, small_neat_file, repertoire):
    settings, network = warm(small_neat_file, repertoire, generations=2)
    ckpt = tmp_path / "c.json"
    evolve(settings, repertoire, checkpoint=ckpt, keep_checkpoint=True, initial_network=network)
    cold = dataclasses.replace(settings, initial_network=None, initial_network_file=None)
    with pytest.raises(CheckpointError, match=f"give --init-from {PAPER_4WS} to resume it"):
        evolve(cold, repertoire, checkpoint=ckpt)
    # A tool that reopens the kept checkpoint from its settings alone (candidates.py) can.
    run = Evolution(settings, repertoire)
    try:
        run.restore(ckpt)
        assert run.generation == 2 and run.best is not None
    finally:
        run.close()


def test_an_unfitting_network_is_refused_before_any_work(tmp_path, capsys, small_task_file):
    def tanh(data):
        data["network"]["nodes"][-1]["activation"] = "tanh"

    def negative(data):  # a hidden node keyed like the motion input an added layout has
        node = next(n for n in data["network"]["nodes"] if n["key"] > 1)
        old, node["key"] = node["key"], -11
        for c in data["network"]["connections"]:
            c["source"] = -11 if c["source"] == old else c["source"]
            c["target"] = -11 if c["target"] == old else c["target"]

    recurrent = config_dir() / "neat" / "4ws-recurrent.ini"
    cases = [
        (PAPER_4WS, recurrent, "feed_forward = False"),
        (edited_paper_file(tmp_path, tanh), None, "activation 'tanh', which"),
        (edited_paper_file(tmp_path, negative), None, "node keys must be 0 or more"),
    ]
    for given, neat_file, message in cases:
        argv = ["arbitrator", "--repertoire", DATA / "4ws-5.repertoire.json", "--quiet"]
        argv += ["--task", small_task_file, "--init-from", given, "--out", tmp_path / "b.json"]
        if neat_file:
            argv += ["--neat-config", neat_file]
        code = main([str(a) for a in argv])
        err = capsys.readouterr().err
        assert code == 1 and f"{given}: " in err and message in err, err
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
        assert not (tmp_path / "b.json").exists() and not (tmp_path / "b.json.lock").exists()


def test_inputs_must_point_the_same_way_and_have_distinct_names(tmp_path):
    hexapod = DATA / "hexapod-paper.arbitrator.json"
    data = layout("hexapod").to_dict()
    data["rangefinders"]["angles_deg"] = [-75, -37.5, 0, 38.0, 75]  # still range_038
    with pytest.raises(
        ConfigError, match=r"its range_038 points at 37\.5 deg, the run's at 38 deg"
    ):
        load_initial_network(
            hexapod, "hexapod", "evorbc", "polar", SensorLayout.from_dict(data, "t")
        )
    data["rangefinders"]["angles_deg"] = [-75, 0.2, 0, 37.5, 75]
    with pytest.raises(ConfigError, match="two inputs named range_000"):
        load_initial_network(
            hexapod, "hexapod", "evorbc", "polar", SensorLayout.from_dict(data, "t")
        )
