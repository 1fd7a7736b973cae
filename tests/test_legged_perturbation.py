"""Perturbed worlds for any legged robot (docs/design.md section 21), shown on the A1.

The A1's maze task runs on the legged robots' one episode runner, which the hexapod's also
runs on; so it takes every quantity the hexapod takes: ground friction, the trunk's mass
and a payload, servo strength and speed, latency, laser noise and dropouts, start errors.
"""

import json

import numpy as np
import pytest
from a1_helpers import a1_settings, trot_repertoire
from hexapod_pins import digest
from neat_helpers import neat_config, network_spec, random_genomes

from evorbc_ros.arbitrator import ArbitratorFile
from offline_evolution.cli import main
from offline_evolution.maze_task.legged_task import LeggedMazeTask
from offline_evolution.maze_task.perturbation import PYBULLET_LEGGED, QUANTITIES, PerturbationSet
from offline_evolution.maze_task.task import MazeTaskSettings
from sim_bridge.legged.perturbed import perturbed_ranges, perturbed_sim
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.quiet_pybullet import p

EPISODE = 1.5  # s: 15 control cycles of 10 physics steps


@pytest.fixture(scope="module")
def a1():
    """The A1's task (1 worker), a trot repertoire's controller and a random network."""
    rep = trot_repertoire()
    settings = MazeTaskSettings(("a1",), EPISODE, 1, "sensors/a1.yaml")
    task = LeggedMazeTask(settings, a1_settings(), workers=1)
    config = neat_config(6, 2, path="config/neat/a1.ini")
    network = network_spec(random_genomes(config, 1, seed=3)[0], config)
    yield task, task.controller("evorbc", rep, "polar"), network, rep
    task.close()


def run(a1, perturbation=None, starts=None):
    """The episode from the maze's nominal start (recorded), in ``perturbation``'s world."""
    task, controller, network, _ = a1
    starts = task.nominal_starts() if starts is None else starts
    world = None
    if perturbation is not None:
        world = perturbation.draw(np.random.default_rng([0, 1]), len(starts))
    return task.evaluate([network], controller, starts, record=True, world=world)


#: Every quantity at its identity value, given explicitly.
IDENTITY = PerturbationSet(name="identity", **{q: (v, v) for q, (v, _, _) in QUANTITIES.items()})


def world_row(**values) -> dict:
    """A world row (:meth:`WorldDraw.row`): ``values``, every other quantity the identity."""
    return {**{q: v for q, (v, _, _) in QUANTITIES.items()}, "key": 0, **values}


def test_the_a1_is_a_perturbable_legged_robot(a1):
    task = a1[0]
    assert task.perturbations_applied == PYBULLET_LEGGED
    assert set(PYBULLET_LEGGED) == set(QUANTITIES) - {"wheel_speed_gain"}


@pytest.mark.parametrize(
    "quantity, value",
    [
        ("friction", 0.3),
        ("body_mass", 1.5),
        ("payload", 0.5),
        ("servo_strength", 0.3),
        ("latency_cycles", 1),
        ("range_noise", 0.05),
        ("dropout", 0.5),
    ],
)
def test_each_perturbation_acts_on_the_a1_and_is_undone(a1, quantity, value):
    # Servo speed is not here: the trots' joints never ask for 2.1 rad/s, a tenth of the
    # A1 motor's top speed; the next test shows the limit acting.
    nominal = digest(run(a1))
    assert digest(run(a1, IDENTITY)) == nominal  # identity values touch nothing
    perturbed = run(a1, PerturbationSet(name=quantity, **{quantity: (value, value)}))
    assert digest(perturbed) != nominal
    assert digest(run(a1)) == nominal  # the nominal dynamics were put back


def test_the_a1s_dynamics_are_put_back_after_a_perturbed_block():
    settings = a1_settings()
    world = world_row(friction=0.5, body_mass=1.2, payload=0.1, servo_strength=0.7, servo_speed=0.8)
    with LeggedSim(settings) as sim:

        def state():
            trunk = p.getDynamicsInfo(sim.robot, -1, physicsClientId=sim.client)
            ground = p.getDynamicsInfo(sim.ground, -1, physicsClientId=sim.client)
            return trunk[0], trunk[2], ground[1], list(sim.torques), sim.settings

        before = state()
        with perturbed_sim(sim, world):
            mass, inertia, friction, torques, during = state()
            assert mass == pytest.approx(1.3 * before[0])  # 12.5 kg robot, trunk only
            assert inertia == pytest.approx([1.3 * i for i in before[1]])
            assert friction == pytest.approx(0.5 * before[2])
            assert torques == pytest.approx([0.7 * t for t in before[3]])
            assert during.servo.max_velocity == pytest.approx(0.8 * settings.servo.max_velocity)
        assert state() == before


def test_a_slower_servo_limits_the_a1s_joint_speed():
    settings = a1_settings()
    world = world_row(servo_speed=0.1)
    with LeggedSim(settings) as sim:
        target = settings.gait.standing_pose() + 0.5  # rad: every joint far from its target

        def fastest_joint():
            sim.reset()
            sim.run(np.tile(target, (3, 1)))
            return np.abs(sim.joint_states()[1]).max()  # rad/s

        nominal = fastest_joint()
        with perturbed_sim(sim, world):
            slow = fastest_joint()
        # The motor is solved implicitly and the trunk moves: within 10 % of the limit.
        assert slow < 1.1 * 0.1 * settings.servo.max_velocity < nominal
        assert fastest_joint() == nominal


def test_laser_noise_is_seeded_by_the_key_and_the_cycle():
    ranges = np.linspace(0.5, 2.0, 25, dtype=np.float32)
    world = world_row(range_noise=0.02, dropout=0.2, key=7)
    a, b = perturbed_ranges(ranges, world, 3), perturbed_ranges(ranges, world, 3)
    np.testing.assert_array_equal(a, b)
    assert np.isinf(a).any() and not np.array_equal(a, perturbed_ranges(ranges, world, 4))
    quiet = world_row(key=7)
    assert perturbed_ranges(ranges, quiet, 3) is ranges  # untouched, same dtype and bits


def test_evorbc_evolve_evaluates_the_a1_in_realistic_worlds(a1, tmp_path, capsys):
    task, _, network, rep = a1
    rep_path, arb_path, task_path = (
        tmp_path / "trot.json",
        tmp_path / "a.json",
        tmp_path / "task.yaml",
    )
    rep.save(rep_path)
    ArbitratorFile(
        kind="evorbc",
        robot="a1",
        network=network,
        sensors=task.layout,
        mapping="polar",
        repertoire={"fingerprint": rep.fingerprint(), "robot": "a1", "count": len(rep)},
        evolution={"simulation": task.describe()},
    ).save(arb_path)
    task_path.write_text(
        f"mazes: [a1]\nepisode_time: {EPISODE}\nsamples_per_maze: 1\nsensors: sensors/a1.yaml\n"
    )
    args = ["evaluate", "--arbitrator", str(arb_path), "--repertoire", str(rep_path)]
    args += ["--task", str(task_path), "--starts", "2", "--json"]
    reports = {}
    for name in ("none", "realistic"):
        assert main([*args, "--perturb", name]) == 0
        out, err = capsys.readouterr()
        reports[name] = json.loads(out)
        if name == "realistic":  # the one quantity a legged robot cannot model
            assert "cannot model wheel_speed_gain;" in err
    report, nominal = reports["realistic"], reports["none"]
    assert report["perturbation"]["name"] == "realistic"
    assert report["overall"]["episodes"] == 2 and report["mazes"] == ["a1"]
    assert report["not_applicable"] == ["wheel_speed_gain"]
    assert set(report["applied"]) == set(PYBULLET_LEGGED)
    # Other worlds, other starts (the drawn start errors) and other outcomes.
    for perturbed, plain in zip(report["episodes"], nominal["episodes"], strict=True):
        assert perturbed["start"] != plain["start"]
        assert perturbed["final_distance"] != plain["final_distance"]
