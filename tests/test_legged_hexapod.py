"""The hexapod is an instance of the generic legged robot, and its results are unchanged.

Three paths give every primitive outcome: the code that simulated the hexapod before the
generic legged robot existed (``reference_hexapod.py``), the hexapod's own modules (now
thin wrappers over ``sim_bridge/legged``) and the generic legged robot built from
``config/robots/hexapod.yaml``; they agree bit for bit. The hexapod's maze episodes run on
the legged robots' one episode runner (``sim_bridge/legged/episode.py``); they equal the
episodes on the old simulation and gait, and, perturbed or not, the digests the hexapod's
own runner gave before the two runners became one (``hexapod_pins.py``).
"""

import dataclasses

import numpy as np
import pytest
import reference_hexapod as reference
from hexapod_helpers import tripod
from hexapod_pins import cases, digest

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.config import config_dir
from evorbc_ros.defaults import default_repertoire, paper_arbitrator
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.hexapod import GaitTable, HexapodGeometry, hexapod_gait, mirror_genes
from offline_evolution.maze_task.task import MazeTaskSettings, make_task
from sim_bridge.hexapod.physics import HexapodSim, PhysicsSettings, hexapod_settings
from sim_bridge.hexapod.robot import DISCARD_TILT, HexapodRobot, describe_simulation
from sim_bridge.hexapod.urdf import hexapod_urdf
from sim_bridge.legged import episode as legged_episode
from sim_bridge.legged.evaluate import HEADING, PATH, TILT, X, Y, evaluate_genes
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.legged.robot import LeggedRobot
from sim_bridge.legged.settings import load_robot_settings

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


def test_the_hexapod_robot_is_the_settings_files_legged_robot(from_yaml):
    genes = np.vstack([np.random.default_rng(6).uniform(-1.0, 1.0, (8, 37)), tripod()])
    with HexapodSim() as sim:
        want = evaluate_genes(sim, genes, 2.0, 0.1, DISCARD_TILT)
    robot = HexapodRobot(workers=1)
    try:
        assert isinstance(robot, LeggedRobot) and robot.settings == from_yaml
        assert robot.describe() == describe_simulation(HexapodGeometry(), PhysicsSettings())
        got = robot.evaluate_primitives(genes, 2.0)
    finally:
        robot.close()
    for name, column in (("x", X), ("y", Y), ("heading", HEADING), ("path", PATH)):
        np.testing.assert_array_equal(getattr(got, name), want[:, column], err_msg=name)
    np.testing.assert_array_equal(got.max_tilt, want[:, TILT])


@pytest.fixture(scope="module")
def shipped():
    arb = ArbitratorFile.load(paper_arbitrator("hexapod"))
    repertoire = Repertoire.load(default_repertoire("hexapod"))
    task = make_task(MazeTaskSettings(**arb.evolution["task"]), "hexapod", workers=1)
    controller = task.controller("evorbc", repertoire, arb.mapping)
    world, start = task.world, tuple(task.nominal_starts()[0, 1:])
    task.close()
    return arb.network, controller, world, start


def test_the_hexapods_task_runs_the_settings_files_robot(shipped, from_yaml):
    _, controller, world, _ = shipped
    assert isinstance(controller, legged_episode.LeggedController)
    assert world.settings == from_yaml


def test_the_shipped_controllers_episode_equals_the_old_simulations(shipped, monkeypatch):
    network, controller, world, start = shipped
    runner = legged_episode.EpisodeRunner(world)
    try:
        new = runner.run(network, controller, 0, start, record=True)
    finally:
        runner.close()
    # The same episode on the code that simulated the hexapod before: its simulation and
    # gait in place of the legged robot's.
    monkeypatch.setattr(
        legged_episode, "LeggedSim", lambda settings, walls: reference.HexapodSim(walls=walls)
    )
    monkeypatch.setattr(
        legged_episode, "LeggedGaitTable", lambda genes, gait, name: reference.GaitTable(genes)
    )
    runner = legged_episode.EpisodeRunner(world)
    try:
        old = runner.run(network, controller, 0, start, record=True)
    finally:
        runner.close()
    assert old["reached"] and len(old["choice"]) > 200
    assert new.keys() == old.keys()
    for key, value in old.items():
        np.testing.assert_array_equal(new[key], value, err_msg=key)


#: :func:`hexapod_pins.digest` of each case of :func:`hexapod_pins.cases` on the hexapod's
#: own episode runner (``offline_evolution/maze_task/hexapod_episode.py``, commit 9ef42ce),
#: with cycles and final distances (m, float.hex) for a readable failure.
PINS = {
    "shipped": (
        "9862a5514b022dd674ab618b1d002b6a8cfed2067d2843420e296cd7c4512d3c",
        [288],
        ["0x1.f020dceea7a7cp-3"],
    ),
    "shipped-realistic": (
        "baea1894b651f9c3d37bf436e252d641d0a52c277444545eb27422ddc2c73f52",
        [300, 300, 300],
        ["0x1.047b680d5b643p+1", "0x1.12fc69f61af27p+2", "0x1.fa8dcba3c2fbap+0"],
    ),
    "standard-harsh": (
        "ee6f38ffe3f166afe34c17a0021010ced7964c1d872903d93252edde882678a0",
        [40, 40],
        ["0x1.bef8ce4c3fe18p+2", "0x1.bcc10975a4e24p+2"],
    ),
}


def test_perturbed_and_nominal_episodes_equal_the_hexapods_old_runners():
    got = cases()
    assert got.keys() == PINS.keys()
    _, world = got["shipped-realistic"]
    assert world.values["latency_cycles"].tolist() == [0.0, 1.0, 0.0]
    for name, (result, _) in got.items():
        pin, cycles, final = PINS[name]
        assert result.cycles.tolist() == cycles, name
        assert [float(d).hex() for d in result.final_distance] == final, name
        assert digest(result) == pin, name
