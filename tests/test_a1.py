"""The Unitree A1 quadruped, registered as a legged robot from its settings file: the
registry, its settings files, its maze, its executor, and the CLI pipeline (repertoire,
arbitrator, replay)."""

import dataclasses
import json
import math
import os
import subprocess
import sys

import numpy as np
import pybullet as p
import pytest
from a1_helpers import a1_settings, trot_repertoire

from evorbc_ros.config import config_dir
from evorbc_ros.legged_executor import LeggedExecutor
from evorbc_ros.robots import registry
from evorbc_ros.robots.legged import LeggedGaitTable
from evorbc_ros.robots.record import load_path
from offline_evolution.mazes.paths import solve
from sim_bridge.legged.evaluate import HEADING, X, Y, evaluate_genes
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.maze import load_named_maze

BIN = os.path.dirname(sys.executable)


def test_the_a1_is_a_legged_robot_from_its_urdf_and_settings():
    a1 = registry.lookup("a1")
    assert "a1" in registry.names() and a1.n_parameters == 25
    settings = a1_settings()
    assert a1.parameters == settings.gait.parameter_specs()
    assert a1.max_speed == settings.speed_bound and a1.footprint_radius == 0.40
    assert settings.urdf.endswith(os.path.join("a1", "a1.urdf"))  # pybullet_data's
    from offline_evolution.maze_task import adapters as search
    from sim_bridge.robots import adapters as sim

    assert a1.family == "legged"
    for path in (*dataclasses.astuple(sim.TABLE.adapters(a1)), search.TABLE.adapters(a1).task):
        assert load_path(path, "a1") is not None  # every factory imports
    # Its joint trajectories come at its physics rate unless told otherwise.
    assert a1.load("commands").default_rate(a1) == settings.physics.rate == 100.0
    with LeggedSim(settings) as sim:
        c = sim.client
        revolute = [
            p.getJointInfo(sim.robot, j, physicsClientId=c)[1].decode()
            for j in range(p.getNumJoints(sim.robot, physicsClientId=c))
            if p.getJointInfo(sim.robot, j, physicsClientId=c)[2] == p.JOINT_REVOLUTE
        ]
        mass = sum(
            p.getDynamicsInfo(sim.robot, k, physicsClientId=c)[0]
            for k in range(-1, p.getNumJoints(sim.robot, physicsClientId=c))
        )
        # The registration's footprint holds the robot at rest.
        assert sim.reach_radius() <= a1.footprint_radius
    assert sorted(revolute) == sorted(settings.gait.joint_names) and len(revolute) == 12
    assert mass == pytest.approx(12.46, abs=0.01)


def test_the_a1_settings_files_belong_together():
    from offline_evolution.arbitrator.neat_config import load_neat_config
    from offline_evolution.arbitrator.settings import load_run_settings
    from offline_evolution.maze_task.task import MazeTaskSettings
    from offline_evolution.repertoire.settings import load_settings

    a1 = registry.lookup("a1")
    rep = load_settings(robot="a1")
    assert rep.robot == "a1" and rep.metric == "circular+tilt" and rep.eval_time == 2.0
    run = load_run_settings(robot="a1")
    task = MazeTaskSettings.load(run.task_path())
    assert task.mazes == ("a1",) and task.episode_time == a1.episode_time == 30.0
    assert config_dir() / task.sensors == a1.sensors_file()
    config = load_neat_config(run.neat_path(), 6, 2)  # 5 laser groups and the goal bearing
    assert config.pop_size == 150


def test_the_a1_maze_fits_the_a1():
    maze = load_named_maze("a1")
    radius = registry.lookup("a1").footprint_radius
    assert maze.clearance(*maze.start_pose[:2]) >= radius
    starts = maze.sample_starts(np.random.default_rng(0), 50, radius)
    assert min(maze.clearance(x, y) for x, y, _ in starts) >= radius
    # A path keeping the footprint clear of the walls leads from the start to the target.
    field = solve(maze, cell=0.02, margin=radius)
    assert 7.0 < field.distance_from(*maze.start_pose[:2]) < 8.5


def test_a_mirrored_trot_walks_the_mirrored_path():
    settings = a1_settings()
    rep = trot_repertoire()
    with LeggedSim(settings) as sim:
        out = evaluate_genes(sim, rep.genes, 2.0, 0.1, settings.discard_tilt)
    half = len(rep) // 2
    assert np.all(out[:half, X] > 0.15)  # every trot walks forward
    np.testing.assert_allclose(out[half:, X], out[:half, X], atol=0.04)
    np.testing.assert_allclose(out[half:, Y], -out[:half, Y], atol=0.04)
    np.testing.assert_allclose(out[half:, HEADING], -out[:half, HEADING], atol=0.06)


def test_the_executor_samples_the_a1_gait_at_the_physics_steps():
    settings = a1_settings()
    genes = np.linspace(-1, 1, 25)
    ex = LeggedExecutor("a1", settings.gait, ["a"], 0.3, settings.physics.rate)
    ex.on_input("a", 0.0)
    ex.on_primitive(genes, 0.0)
    with LeggedSim(settings) as sim:
        n = sim.physics.steps(0.1)
        assert n == 10  # 100 Hz
        for cycle in range(3):
            now = cycle * 100_000_000 * 1e-9  # the node's clock: integer ns
            ex.on_input("a", now)
            cmd = ex.command(now)
            assert not cmd.stopped and cmd.positions.shape == (30, 12)  # 0.3 s at 100 Hz
            table = LeggedGaitTable(genes, settings.gait)
            want = table.joint_targets(sim.step_times(n), np.zeros(n, dtype=int))
            np.testing.assert_array_equal(cmd.positions[:n], want)  # bit for bit
            sim.steps_done += n


def cli(tmp_path, *args):
    out = subprocess.run(
        [os.path.join(BIN, "evorbc-evolve"), *args],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr
    return out


@pytest.mark.slow
def test_a1_repertoire_arbitrator_and_replay_through_the_cli(tmp_path):
    from evorbc_ros.arbitrator import ArbitratorFile
    from evorbc_ros.repertoire import Repertoire

    cli(
        tmp_path, "repertoire", "--robot", "a1", "--seed", "1", "--initial-batch", "16",
        "--batch-size", "8", "--iterations", "1", "--workers", "1", "--out", "r.json",
        "--quiet",
    )  # fmt: skip
    rep = Repertoire.load(tmp_path / "r.json")
    assert rep.robot == "a1" and len(rep) > 0 and rep.algorithm["evaluations"] == 24
    assert rep.algorithm["simulation"] == a1_settings().describe()
    # A tiny arbitrator evolution over a trot repertoire: 2 generations of 16 genomes, 1 s
    # episodes, a one-episode post-evaluation.
    trot_repertoire().save(tmp_path / "trot.json")
    neat = (config_dir() / "neat" / "a1.ini").read_text()
    (tmp_path / "neat.ini").write_text(neat.replace("pop_size              = 150", "pop_size = 16"))
    (tmp_path / "task.yaml").write_text(
        "mazes: [a1]\nepisode_time: 1.0\nsamples_per_maze: 1\nsensors: sensors/a1.yaml\n"
    )
    (tmp_path / "run.yaml").write_text(
        "generations: 2\nmapping: polar\nneat: neat.ini\ntask: task.yaml\n"
        "hall_of_fame: 2\npost_samples: 1\n"
    )
    out = cli(
        tmp_path, "arbitrator", "--repertoire", "trot.json", "--config", "run.yaml",
        "--seed", "1", "--workers", "1", "--out", "a.json", "--quiet",
    )  # fmt: skip
    assert out.stdout.startswith("a1 arbitrator: ") and "2 generations" in out.stdout
    arb = ArbitratorFile.load(tmp_path / "a.json")
    assert arb.robot == "a1" and arb.evolution["task"]["mazes"] == ["a1"]
    assert arb.evolution["simulation"] == a1_settings().describe()
    out = cli(tmp_path, "replay", "--arbitrator", "a.json", "--repertoire", "trot.json", "--json")
    replayed = json.loads(out.stdout)["mazes"][0]
    assert math.isfinite(replayed["fitness"]) and not replayed["reached"]


def test_a1_episodes_are_identical_on_one_or_two_workers():
    from neat_helpers import neat_config, network_spec, random_genomes

    from offline_evolution.maze_task.legged_task import LeggedMazeTask
    from offline_evolution.maze_task.task import MazeTaskSettings

    rep = trot_repertoire()
    config = neat_config(6, 2, path="config/neat/a1.ini")
    nets = [network_spec(g, config) for g in random_genomes(config, 2, seed=1)]
    starts = np.array([[0, -3.45, 0.0, 0.0], [0, -3.5, 0.4, 1.0]])
    settings = MazeTaskSettings(("a1",), 1.0, 1, "sensors/a1.yaml")
    results = []
    for workers in (1, 2):
        with LeggedMazeTask(settings, a1_settings(), workers=workers) as task:
            controller = task.controller("evorbc", rep, "polar")
            results.append(task.evaluate(nets, controller, starts, record=True))
    for a, b in zip(*results, strict=True):
        np.testing.assert_array_equal(a, b)
    assert results[0].pose.shape == (4, 11, 3)
    assert set(np.unique(results[0].choice)) <= set(range(len(rep)))
