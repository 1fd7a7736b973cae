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

DATA = config_dir().parent / "evorbc_ros" / "data"
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
    [(PAPER_4WS, "4ws-5", "4ws"), (DATA / "hexapod.arbitrator.json", "hexapod", "hexapod")],
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
    with pytest.raises(CheckpointError, match="initial_network"):
        evolve(cold, repertoire, checkpoint=ckpt)


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
    for given in (None, other):
        with pytest.raises(ConfigError, match="not the one the run settings name"):
            Evolution(settings, repertoire, initial_network=given)


def test_inputs_are_matched_by_name():
    hexapod = DATA / "hexapod.arbitrator.json"
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
    # bad files: one line, exit code 2, nothing written
    bad = tmp_path / "bad.json"
    bad.write_text("{}")
    for given, message in (
        (bad, "not an arbitrator file"),
        (DATA / "hexapod.arbitrator.json", "its robot is 'hexapod'"),
        (tmp_path / "missing.json", "missing.json"),
    ):
        code = main([str(a) for a in [*argv, "--init-from", given, "--out", tmp_path / "b.json"]])
        err = capsys.readouterr().err
        assert code == 1 and message in err and "Traceback" not in err
        assert len(err.strip().splitlines()) == 1
        assert not (tmp_path / "b.json").exists()
