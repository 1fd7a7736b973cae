"""The shipped 4ws-5 controller records the shipped recipe (evorbc_ros/data/README.md).

`evorbc-evolve arbitrator --config config/arbitrator/4ws-generated.yaml --seed 4` is the
command that wrote `evorbc_ros/data/4ws-5.arbitrator.json`. If one of the files it reads
(the run settings, the task, the NEAT settings, the sensor layout) is edited without
shipping a controller made with it, the command would no longer make the shipped file:
these checks fail instead of the record going silently stale.
"""

import pytest

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.config import config_dir
from evorbc_ros.defaults import default_arbitrator, default_repertoire
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.sensors import SensorLayout
from offline_evolution.arbitrator.evolve import file_sha256
from offline_evolution.arbitrator.settings import load_run_settings
from offline_evolution.maze_task.task import MazeTaskSettings

SEED = 4  # the --seed of the recorded command


@pytest.fixture(scope="module")
def shipped():
    """``(arbitrator file, run settings, task settings)`` of the shipped recipe."""
    run = load_run_settings(config_dir() / "arbitrator" / "4ws-generated.yaml")
    task = MazeTaskSettings.load(run.task_path())
    return ArbitratorFile.load(default_arbitrator("4ws-5")), run, task


def test_the_shipped_controller_records_the_shipped_task_and_neat_settings(shipped):
    arb, run, task = shipped
    evolution = arb.evolution
    assert evolution["seed"] == SEED
    assert evolution["generations"] == run.generations
    assert evolution["task"] == task.as_dict()
    assert evolution["task"]["training"]["perturb"] == "realistic"
    assert evolution["neat_sha256"] == file_sha256(run.neat_path())
    assert arb.mapping == run.mapping


def test_the_shipped_controller_was_chosen_by_the_shipped_post_selection(shipped):
    arb, run, _ = shipped
    post = arb.evolution["post_evaluation"]
    assert post["rule"] == run.post_rule
    assert post["hall_of_fame"] == run.hall_of_fame
    assert post["samples_per_maze"] == run.post_samples
    assert post["snapshot_every"] == run.snapshot_every


def test_the_shipped_controller_reads_the_shipped_layout_over_the_shipped_repertoire(shipped):
    arb, _, task = shipped
    layout = SensorLayout.load(config_dir() / task.sensors)
    assert arb.sensors.fingerprint() == layout.fingerprint()
    assert arb.network.input_keys and len(arb.network.input_keys) == layout.n_inputs
    repertoire = Repertoire.load(default_repertoire("4ws-5"))
    assert arb.repertoire["fingerprint"] == repertoire.fingerprint()
