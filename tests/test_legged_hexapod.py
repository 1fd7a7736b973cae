"""The hexapod is an instance of the generic legged robot, and its results are unchanged.

Three paths give every number: the code that simulated the hexapod before the generic
legged robot existed (``reference_hexapod.py``), the hexapod's own modules (now thin
wrappers over ``sim_bridge/legged``) and the generic legged robot built from
``config/robots/hexapod.yaml``. Primitive outcomes and maze episodes agree bit for bit.
"""

import dataclasses

import numpy as np
import pytest
import reference_hexapod as reference
from hexapod_helpers import tripod

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.config import config_dir
from evorbc_ros.defaults import default_arbitrator, default_repertoire
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.hexapod import GaitTable, hexapod_gait, mirror_genes
from offline_evolution.maze_task import hexapod_episode
from offline_evolution.maze_task.task import MazeTaskSettings, make_task
from sim_bridge.hexapod.evaluate import evaluate_genes
from sim_bridge.hexapod.physics import HexapodSim, hexapod_settings
from sim_bridge.hexapod.urdf import hexapod_urdf
from sim_bridge.legged import episode as legged_episode
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.legged.settings import load_robot_settings
from sim_bridge.robots.hexapod import DISCARD_TILT

YAML = config_dir() / "robots" / "hexapod.yaml"


@pytest.fixture(scope="module")
def from_yaml():
    return load_robot_settings(YAML)


def test_the_settings_file_describes_the_codes_hexapod(from_yaml):
    code = hexapod_settings()
    assert (config_dir() / "robots" / "hexapod.urdf").read_text() == hexapod_urdf()
    for field in dataclasses.fields(code):
        if field.name not in ("urdf", "urdf_text", "source"):
            assert getattr(from_yaml, field.name) == getattr(code, field.name), field.name
    assert from_yaml.gait == hexapod_gait()
    assert from_yaml.describe() == code.describe()


def test_gait_targets_and_mirror_images_equal_the_old_code():
    rng = np.random.default_rng(4)
    genes = rng.uniform(-1.0, 1.0, (6, 37))
    times = np.arange(40) * 0.02 + 0.37
    rows = np.arange(40) % 6
    new = GaitTable(genes).joint_targets(times, rows)
    old = reference.GaitTable(genes).joint_targets(times, rows)
    np.testing.assert_array_equal(new, old)
    # Left and right legs swap their 6 genes each (the old mirror_genes).
    legs = genes[:, 1:].reshape(6, 6, 6)[:, [3, 4, 5, 0, 1, 2], :].reshape(6, 36)
    np.testing.assert_array_equal(mirror_genes(genes), np.column_stack([genes[:, 0], legs]))


def test_primitive_outcomes_are_bit_identical_through_every_path(from_yaml):
    genes = np.vstack([np.random.default_rng(5).uniform(-1.0, 1.0, (12, 37)), tripod()])
    old_sim = reference.HexapodSim()
    try:
        old = reference.evaluate_genes(old_sim, genes, 2.0, 0.1, DISCARD_TILT)
    finally:
        old_sim.close()
    with HexapodSim() as sim:
        wrapped = evaluate_genes(sim, genes, 2.0, 0.1, DISCARD_TILT)
    with LeggedSim(from_yaml) as sim:
        generic = evaluate_genes(sim, genes, 2.0, 0.1, DISCARD_TILT)
    assert np.any(old[:, 4] > DISCARD_TILT) and np.any(old[:, 4] < DISCARD_TILT)
    np.testing.assert_array_equal(wrapped, old)
    np.testing.assert_array_equal(generic, old)


@pytest.fixture(scope="module")
def shipped():
    arb = ArbitratorFile.load(default_arbitrator("hexapod"))
    repertoire = Repertoire.load(default_repertoire("hexapod"))
    task = make_task(MazeTaskSettings(**arb.evolution["task"]), "hexapod", workers=1)
    controller = task.controller("evorbc", repertoire, arb.mapping)
    world, start = task.world, tuple(task.nominal_starts()[0, 1:])
    task.close()
    return arb.network, controller, world, start


def test_the_shipped_controllers_episode_is_bit_identical_through_every_path(
    shipped, from_yaml, monkeypatch
):
    network, controller, world, start = shipped
    runner = hexapod_episode.EpisodeRunner(world)
    try:
        wrapped = runner.run(network, controller, 0, start, record=True)
    finally:
        runner.close()
    generic_world = legged_episode.LeggedWorld(world.mazes, world.layout, from_yaml, world.n_cycles)
    generic_controller = legged_episode.LeggedController(
        "evorbc", controller.mapping, controller.genes, controller.behaviour, controller.key
    )
    runner = legged_episode.EpisodeRunner(generic_world)
    try:
        generic = runner.run(network, generic_controller, 0, start, record=True)
    finally:
        runner.close()
    # Today's code: the hexapod episode on the old simulation and gait.
    monkeypatch.setattr(hexapod_episode, "HexapodSim", reference.HexapodSim)
    monkeypatch.setattr(hexapod_episode, "GaitTable", reference.GaitTable)
    runner = hexapod_episode.EpisodeRunner(world)
    try:
        old = runner.run(network, controller, 0, start, record=True)
    finally:
        runner.close()
    assert old["reached"] and len(old["choice"]) > 200
    for result in (wrapped, generic):
        assert result.keys() == old.keys()
        for key, value in old.items():
            np.testing.assert_array_equal(result[key], value, err_msg=key)
