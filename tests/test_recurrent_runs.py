"""Recurrent arbitrators end to end: evolved by the CLI, replayed, run by the lockstep ROS
graph (bit for bit with the offline replay) and by the legged task on 1 and 2 workers."""

import json

import numpy as np
import pytest
import yaml
from graph_helpers import assert_lockstep_reproduces
from neat_helpers import neat_config, network_spec, random_genomes
from test_recurrent import RECURRENT_4WS, cycles_among_needed

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.config import config_dir
from evorbc_ros.defaults import default_repertoire
from evorbc_ros.repertoire import Repertoire
from offline_evolution.cli import main
from offline_evolution.maze_task.replay import replay
from offline_evolution.maze_task.task import MazeTask, MazeTaskSettings


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_the_cli_evolves_a_recurrent_arbitrator_and_replay_gives_its_fitness(tmp_path, capsys):
    task = tmp_path / "task.yaml"
    task.write_text(yaml.safe_dump({"mazes": ["gaps", "corridors"], "episode_time": 30.0}))
    # Post-evaluation from the nominal starts only: replay's default starts.
    settings = yaml.safe_load((config_dir() / "arbitrator" / "4ws.yaml").read_text())
    run_settings = tmp_path / "run.yaml"
    run_settings.write_text(yaml.safe_dump({**settings, "post_samples": 0}))
    out = tmp_path / "a.json"
    code, _, err = run(
        capsys, "arbitrator", "--repertoire", default_repertoire("4ws-5"), "--generations", 2,
        "--seed", 3, "--config", run_settings, "--neat-config", RECURRENT_4WS, "--task", task,
        "--out", out, "--quiet",
    )  # fmt: skip
    assert code == 0, err
    data = json.loads(out.read_text())
    assert data["network"]["recurrent"] is True
    record = data["evolution"]["post_evaluation"]
    code, stdout, err = run(
        capsys, "replay", "--arbitrator", out, "--repertoire", default_repertoire("4ws-5"),
        "--json",
    )  # fmt: skip
    assert code == 0, err
    mazes = json.loads(stdout)["mazes"]
    assert [m["maze"] for m in mazes] == ["gaps", "corridors"]
    assert np.mean([m["fitness"] for m in mazes]) == pytest.approx(record["fitness"], abs=1e-12)


@pytest.fixture(scope="module")
def recurrent_arbitrator(tmp_path_factory):
    """A recurrent arbitrator of neat-python genomes with a cycle among the nodes that feed
    its outputs, which switches among at least 3 primitives from gaps' nominal start.

    Returns ``(arbitrator path, repertoire path, offline outcome, offline result)``.
    """
    folder = tmp_path_factory.mktemp("recurrent")
    rep_path = default_repertoire("4ws-5")
    rep = Repertoire.load(rep_path)
    task = MazeTask(MazeTaskSettings(("gaps",), 25.0), "4ws-5")
    config = neat_config(task.layout.n_inputs, 2, path=RECURRENT_4WS)
    for seed in range(40):
        network = network_spec(random_genomes(config, 1, seed=seed)[0], config)
        if not any(cycles_among_needed(network)):
            continue
        arb = ArbitratorFile(
            kind="evorbc",
            robot="4ws-5",
            network=network,
            sensors=task.layout,
            mapping="polar",
            repertoire={"fingerprint": rep.fingerprint(), "robot": "4ws-5", "count": len(rep)},
            evolution={},
        )
        outcomes, result = replay(arb, task, task.nominal_starts(), rep)
        if len(set(result.choice[0, : result.cycles[0]].tolist())) >= 3:
            break
    else:
        pytest.fail("no switching recurrent arbitrator among 40 seeds")
    path = folder / "recurrent.json"
    arb.save(path)
    return str(path), str(rep_path), outcomes[0], result


def test_the_lockstep_graph_reproduces_a_recurrent_arbitrator_bit_for_bit(
    tmp_path, recurrent_arbitrator
):
    assert_lockstep_reproduces(tmp_path, 178, "4ws-5", "gaps", recurrent_arbitrator, 25.0)
    log = (tmp_path / "gaps-lockstep.log").read_text()
    assert "recurrent network: its state starts at 0" in log


def test_a_legged_task_runs_a_recurrent_network_identically_on_one_or_two_workers(tmp_path):
    from hexapod_helpers import tripod_repertoire

    from offline_evolution.maze_task.hexapod_task import HexapodMazeTask

    ini = tmp_path / "hexapod-recurrent.ini"
    text = (config_dir() / "neat" / "hexapod.ini").read_text()
    ini.write_text(text.replace("feed_forward          = True", "feed_forward          = False"))
    config = neat_config(6, 2, path=ini)
    specs = [network_spec(g, config) for g in random_genomes(config, 12, seed=4)]
    nets = [s for s in specs if any(cycles_among_needed(s))][:2]
    assert len(nets) == 2
    # The same start twice: an episode must not inherit the state of the one before.
    starts = np.array([[0, -3.5, 0.0, 0.0], [0, -3.5, 0.0, 0.0]])
    repertoire = tripod_repertoire()
    results = []
    for workers in (1, 2):
        settings = MazeTaskSettings(("hexapod",), 2.0, 1, "sensors/hexapod.yaml")
        task = HexapodMazeTask(settings, workers=workers)
        try:
            controller = task.controller("evorbc", repertoire, "polar")
            results.append(task.evaluate(nets, controller, starts, record=True))
        finally:
            task.close()
    one, two = results
    for a, b in zip(one, two, strict=True):
        if a is not None:
            np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(one.outputs[0::2], one.outputs[1::2])
    assert one.outputs.shape == (4, 20, 2)
