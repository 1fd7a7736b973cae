"""The shipped generalising controllers record the shipped recipes (evorbc_ros/data/README.md).

`evorbc-evolve arbitrator --config config/arbitrator/4ws-generated.yaml --seed 4` wrote
`evorbc_ros/data/4ws-5.arbitrator.json`. If one of the files such a command reads (the run
settings, the task, the NEAT settings, the sensor layout) is edited without shipping a
controller made with it, the command would no longer make the shipped file: these checks
fail instead of the record going silently stale. A robot whose generalising controller
ships adds its run settings and seed to :data:`RECIPES`.
"""

import pytest

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.config import config_dir
from evorbc_ros.defaults import DATA_DIR, default_arbitrator, default_repertoire
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.sensors import SensorLayout
from offline_evolution.arbitrator.evolve import file_sha256
from offline_evolution.arbitrator.settings import load_run_settings
from offline_evolution.maze_task.task import MazeTaskSettings

# robot: (its run settings in config/arbitrator, the --seed of the recorded command, the
# file in evorbc_ros/data its --init-from names, or None)
RECIPES = {
    "4ws-5": ("4ws-generated.yaml", 4, None),
    "hexapod": ("hexapod-anywhere-warm.yaml", 1, "hexapod-paper.arbitrator.json"),
}


@pytest.fixture(scope="module", params=sorted(RECIPES))
def shipped(request):
    """``(robot, arbitrator file, run settings, task settings)`` of a shipped recipe."""
    robot = request.param
    run = load_run_settings(config_dir() / "arbitrator" / RECIPES[robot][0])
    task = MazeTaskSettings.load(run.task_path())
    return robot, ArbitratorFile.load(default_arbitrator(robot)), run, task


def test_the_shipped_controller_records_the_shipped_task_and_neat_settings(shipped):
    robot, arb, run, task = shipped
    evolution = arb.evolution
    assert evolution["seed"] == RECIPES[robot][1]
    assert evolution["generations"] == run.generations
    assert evolution["task"] == task.as_dict()
    assert evolution["neat_sha256"] == file_sha256(run.neat_path())
    assert arb.mapping == run.mapping


def test_the_4ws_controller_trained_in_perturbed_worlds():
    arb = ArbitratorFile.load(default_arbitrator("4ws-5"))
    assert arb.evolution["task"]["training"]["perturb"] == "realistic"


def test_the_shipped_controller_was_chosen_by_the_shipped_post_selection(shipped):
    _, arb, run, _ = shipped
    post = arb.evolution["post_evaluation"]
    assert post["rule"] == run.post_rule
    assert post["hall_of_fame"] == run.hall_of_fame
    assert post["samples_per_maze"] == run.post_samples
    assert post.get("snapshot_every", 0) == run.snapshot_every  # written when set
    assert post["nominal_watch"] == run.nominal_watch
    assert post.get("finalists", 0) == run.post_finalists
    assert post.get("final_samples_per_maze", 0) == run.post_final_samples


def test_the_shipped_controller_records_the_network_it_started_from(shipped):
    robot, arb, _, _ = shipped
    source = RECIPES[robot][2]
    if source is None:
        assert "initial_network" not in arb.evolution
        return
    from offline_evolution.arbitrator.warm_start import network_fingerprint

    record = arb.evolution["initial_network"]
    assert record["file"] == source
    started = ArbitratorFile.load(DATA_DIR / source)
    assert record["fingerprint"] == network_fingerprint(started.network)
    assert started.evolution["task"]["mazes"] == [robot]  # the paper protocol's own maze


def test_the_shipped_controller_reads_the_shipped_layout_over_the_shipped_repertoire(shipped):
    robot, arb, _, task = shipped
    layout = SensorLayout.load(config_dir() / task.sensors)
    assert arb.sensors.fingerprint() == layout.fingerprint()
    assert arb.network.input_keys and len(arb.network.input_keys) == layout.n_inputs
    repertoire = Repertoire.load(default_repertoire(robot))
    assert arb.repertoire["fingerprint"] == repertoire.fingerprint()
