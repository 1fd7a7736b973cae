"""The hexapod through the ROS 2 graph: the executor's trajectories and lockstep parity
with the offline episode, cycle by cycle."""

import numpy as np
import pytest
from graph_helpers import GraphRun
from hexapod_helpers import tripod_repertoire
from neat_helpers import neat_config, network_spec, random_genomes

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.hexapod_executor import HexapodExecutor
from evorbc_ros.robots.hexapod import GaitTable
from offline_evolution.maze_task.hexapod_task import HexapodMazeTask
from offline_evolution.maze_task.replay import replay
from offline_evolution.maze_task.task import MazeTaskSettings
from sim_bridge.hexapod.physics import HexapodSim

EPISODE = 4.0  # s: 40 cycles


def test_executor_samples_the_gait_at_the_simulations_step_times():
    genes = np.linspace(-1, 1, 37)
    ex = HexapodExecutor(["a"], stale_timeout=0.3, trajectory_rate=60.0)
    ex.on_input("a", 0.0)
    ex.on_primitive(genes, 0.0)
    sim = HexapodSim()
    try:
        for cycle in range(4):
            now = cycle * 100_000_000 * 1e-9  # the node's clock: integer ns
            ex.on_input("a", now)
            cmd = ex.command(now)
            assert not cmd.stopped and cmd.positions.shape == (6, 18)
            want = GaitTable(genes).joint_targets(sim.step_times(6), np.zeros(6, dtype=int))
            np.testing.assert_array_equal(cmd.positions, want)  # bit for bit
            sim.steps_done += 6
    finally:
        sim.close()
    # stale input: hold the last target, one point
    held = ex.command(10.0)
    assert held.stopped and "stale" in held.reason
    np.testing.assert_array_equal(held.positions, cmd.positions[-1:])


@pytest.fixture(scope="module")
def controller(tmp_path_factory):
    """A repertoire, an arbitrator that switches primitives, and the offline episode."""
    tmp = tmp_path_factory.mktemp("hexapod")
    rep = tripod_repertoire()
    rep_path = tmp / "hexapod.repertoire.json"
    rep.save(rep_path)
    task = HexapodMazeTask(
        MazeTaskSettings(("hexapod",), EPISODE, 1, "sensors/hexapod.yaml"), workers=1
    )
    config = neat_config(6, 2, path="config/neat/hexapod.ini")
    try:
        for seed in range(20):
            network = network_spec(random_genomes(config, 1, seed=seed)[0], config)
            arb = ArbitratorFile(
                kind="evorbc",
                robot="hexapod",
                network=network,
                sensors=task.layout,
                mapping="polar",
                repertoire={"fingerprint": rep.fingerprint(), "robot": "hexapod", "count": 6},
            )
            outcomes, result = replay(arb, task, task.nominal_starts(), rep)
            if len(set(result.choice[0, : result.cycles[0]].tolist())) >= 3:
                break
    finally:
        task.close()
    arb_path = tmp / "hexapod.arbitrator.json"
    arb.save(arb_path)
    return arb_path, rep_path, outcomes[0], result


def test_lockstep_graph_reproduces_the_offline_episode(tmp_path, controller):
    arb_path, rep_path, outcome, result = controller
    run = GraphRun(
        tmp_path,
        170,
        "hexapod",
        episode_time=EPISODE,
        arbitrator=arb_path,
        repertoire=rep_path,
        robot="hexapod",
    )
    try:
        got = run.wait(timeout=120)
    finally:
        run.stop()
    cycles = int(result.cycles[0])
    choices = run.recorded_choices()
    assert len(choices) in (cycles, cycles + 1)
    np.testing.assert_array_equal(choices[:cycles], result.choice[0, :cycles])
    assert len(set(choices.tolist())) >= 3  # the arbitrator switched primitives
    trajectory = np.array(got["trajectory"])
    np.testing.assert_array_equal(trajectory, result.pose[0, : cycles + 1])  # bit for bit
    assert got["robot"] == "hexapod" and got["fitness"] == pytest.approx(outcome.fitness)
    assert np.hypot(*(trajectory[-1, :2] - trajectory[0, :2])) > 0.2  # it walked
