"""Legged robots' offline episodes with the onboard adaptation (docs/design/adaptation.md).

The PyBullet episode feeds the onboard :class:`~evorbc_ros.adaptation.OnlineAdaptation`
as the arbitrator node does (the body's odometry pose at each cycle's start, then the
choice): under a locked knee the shipped hexapod controller takes observations and
chooses differently, deterministically; off, the episode is the one it was. The node's
:class:`~evorbc_ros.arbitration.Controller`, fed the episode's poses and network outputs,
chooses what the episode chose at every cycle.
"""

from __future__ import annotations

import numpy as np
import pytest

from evorbc_ros.adaptation import AdaptationSettings, OnlineAdaptation, adapted_choice
from evorbc_ros.adaptation.model import LEGGED_SETTINGS
from evorbc_ros.arbitration import Controller
from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.defaults import default_arbitrator, default_repertoire
from evorbc_ros.mapping import choose_primitive
from evorbc_ros.repertoire import Repertoire
from offline_evolution.maze_task.base import MazeTaskSettings
from offline_evolution.maze_task.hexapod_task import HexapodMazeTask
from sim_bridge.perturbation import load_perturbations

EPISODE = 15.0  # s: 150 cycles, several 0.5 s executions of the shipped controller
SEED = 4  # the damaged leg of the drawn world


@pytest.fixture(scope="module")
def episodes():
    """The shipped hexapod controller in its ``hexapod`` maze, knee locked: off, on, on, off."""
    path = default_arbitrator("hexapod")
    arb = ArbitratorFile.load(path)
    rep = Repertoire.load(default_repertoire("hexapod"))
    settings = MazeTaskSettings(("hexapod",), EPISODE, 1, arb.evolution["task"]["sensors"])
    task = HexapodMazeTask(settings, workers=1)
    try:
        controller = task.controller("evorbc", rep, arb.mapping)
        starts = task.nominal_starts()
        world = load_perturbations("hexapod-knee-locked").draw(np.random.default_rng([SEED, 1]), 1)

        def run():
            return task.evaluate([arb.network], controller, starts, record=True, world=world)

        off = run()
        task.adapt(task.adapting_for(rep, LEGGED_SETTINGS))
        on = run()
        observations = list(task.observations)
        again = run()
        task.adapt(None)
        back = run()
    finally:
        task.close()
    return path, off, on, again, back, observations, task.dt


def test_a_knee_locked_hexapod_adapting_observes_and_chooses_otherwise(episodes):
    _, off, on, again, back, observations, _ = episodes
    assert observations[0] >= 2  # whole 0.5 s executions observed
    np.testing.assert_array_equal(on.pose, again.pose)  # each episode from the prior
    np.testing.assert_array_equal(on.choice, again.choice)
    n = min(on.cycles[0], off.cycles[0])
    assert (on.choice[0, :n] != off.choice[0, :n]).any()
    # Until the first observation (at least 6 cycles in) it chooses as the evolved one.
    np.testing.assert_array_equal(on.choice[0, :6], off.choice[0, :6])
    # Off again: the episode it was, bit for bit.
    np.testing.assert_array_equal(back.pose, off.pose)
    np.testing.assert_array_equal(back.choice, off.choice)


def test_the_nodes_controller_fed_the_episode_chooses_as_the_episode(episodes):
    # The arbitrator node's Controller, adaptation on with its defaults for the robot, fed
    # each cycle's odometry pose (stamped as the bridge stamps it) and the network's
    # outputs: the choices of the adapted episode, at every cycle.
    path, _, on, _, _, _, dt = episodes
    controller = Controller(str(path))
    controller.enable_adaptation()
    adaptation = controller.adaptation
    assert adaptation.settings == LEGGED_SETTINGS
    arbitrator = controller.arbitrator
    k = int(on.cycles[0])
    for t in range(k):
        x, y, h = (float(v) for v in on.pose[0, t])
        # The trace's heading is the body quaternion's yaw by the node's own formula
        # (evorbc_ros.goal.quaternion_yaw); the bridge stamps the pose round(t dt 1e9) ns.
        controller.put_pose(round(t * dt * 1e9), x, y, h)
        m1, m2 = (float(v) for v in on.outputs[0, t, :2])
        index, px, py = choose_primitive(arbitrator.mapping, arbitrator.lookup, m1, m2)
        assert adapted_choice(adaptation, arbitrator.lookup, index, px, py) == on.choice[0, t]
    assert adaptation.model.observations >= 2


def test_the_held_rule_sums_whole_executions_and_the_agree_rule_keeps_its_bits():
    # A body that sways (heading +-0.1 rad every cycle) while walking 0.02 m a cycle: the
    # wheeled rule's cycles never agree, the held rule observes each whole 5-cycle run.
    recorded = np.array([[0.4, 0.0, 0.0], [0.0, 0.4, 1.0], [-0.4, 0.0, 0.0]])
    agree = OnlineAdaptation(recorded, 2.0, AdaptationSettings())
    held = OnlineAdaptation(recorded, 2.0, LEGGED_SETTINGS)
    for t in range(40):
        primitive = 0 if t < 20 else 2
        for a in (agree, held):
            a.put_pose(t * 100_000_000, 0.02 * t, 0.0, 0.1 * (-1) ** t)
            a.before_choice()
            a.after_choice(primitive)
    assert agree.model.observations == 0
    # Run of 20 then of 20 (still running): cycles 2-6, 7-11, 12-16 of the first (17-20
    # end short at the switch), 2-6, 7-11, 12-16 of the second.
    assert held.model.observations == 6
    with pytest.raises(ValueError, match="min_cycles"):
        AdaptationSettings(window=3, min_cycles=4)
    with pytest.raises(ValueError, match="steady"):
        AdaptationSettings(steady="always")


def test_the_lockstep_graph_adapting_walks_the_damaged_hexapod_as_the_offline_episode(
    tmp_path, episodes
):
    # The arbitrator node with its adaptation parameter on and the bridge with the same
    # locked knee: the same primitive at every cycle and the same poses, bit for bit.
    from graph_helpers import GraphRun, assert_same_choices

    path, off, on, _, _, _, _ = episodes
    bridge = {"perturb": "hexapod-knee-locked", "seed": SEED,
              "wait_for_subscribers": ["scan", "odom", "odom"]}  # fmt: skip
    params = {"adaptation": True}
    run = GraphRun(tmp_path, 197, "hexapod", episode_time=EPISODE, arbitrator=path,
                   robot="hexapod", bridge=bridge, arbitrator_params=params)  # fmt: skip
    got = run.finish(timeout=300)
    choices = run.recorded_choices()
    cycles = assert_same_choices(choices, on)
    np.testing.assert_array_equal(np.array(got["trajectory"]), on.pose[0, : cycles + 1])
    n = min(cycles, off.cycles[0])
    assert (choices[:n] != off.choice[0, :n]).any()  # adaptation changed the choices
