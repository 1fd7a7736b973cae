"""The A1 quadruped through the ROS 2 graph: joint trajectories at its physics rate, lockstep
parity with the offline episode, and ``evorbc-sim --robot a1``."""

import json

import numpy as np
import pytest
from a1_helpers import a1_settings, trot_repertoire
from graph_helpers import assert_lockstep_reproduces, switching_arbitrator
from ros_domains import claim_domain
from trajectory_msgs.msg import JointTrajectory

from evorbc_ros.nodes.common import vector_message
from evorbc_ros.nodes.primitive_executor import PrimitiveExecutorNode
from evorbc_ros.robots.legged import LeggedGaitTable
from offline_evolution.maze_task.legged_task import LeggedMazeTask
from offline_evolution.maze_task.task import MazeTaskSettings

EPISODE = 3.0  # s: 30 cycles of 10 physics steps


@pytest.fixture(scope="module")
def controller(tmp_path_factory):
    """A trot repertoire, an arbitrator that switches primitives, and the offline episode."""
    tmp = tmp_path_factory.mktemp("a1")
    rep = trot_repertoire()
    rep_path = tmp / "a1.repertoire.json"
    rep.save(rep_path)
    settings = MazeTaskSettings(("a1",), EPISODE, 1, "sensors/a1.yaml")
    task = LeggedMazeTask(settings, a1_settings(), workers=1)
    try:
        arb, outcome, result = switching_arbitrator(
            task, rep, "a1", "config/neat/a1.ini", evolution={"simulation": task.describe()}
        )
    finally:
        task.close()
    arb_path = tmp / "a1.arbitrator.json"
    arb.save(arb_path)
    return arb_path, rep_path, outcome, result


def test_lockstep_graph_reproduces_the_offline_a1_episode(tmp_path, controller):
    trajectory = assert_lockstep_reproduces(tmp_path, 171, "a1", "a1", controller, EPISODE)
    assert np.hypot(*(trajectory[-1, :2] - trajectory[0, :2])) > 0.1  # it walked


def test_the_a1_executor_sends_its_joints_at_the_physics_rate(ros):
    node = ros.make(PrimitiveExecutorNode, sim_time=True, robot="a1")
    got = ros.listen(JointTrajectory, "joint_trajectory_controller/joint_trajectory")
    prim, rf, gs = ros.executor_inputs()
    settings = a1_settings()
    rate = settings.physics.rate  # 100 Hz, not the hexapod's 50
    genes = np.linspace(-1, 1, 25)
    ros.set_clock(2.0)
    rf.publish(vector_message([0.0] * 5))
    gs.publish(vector_message([0.5]))
    prim.publish(vector_message(genes))
    points = round(0.3 * rate)  # one per physics step of the 0.3 s stale timeout
    assert ros.spin_until(lambda: got and len(got[-1].points) == points)
    msg = got[-1]
    assert list(msg.joint_names) == list(settings.gait.joint_names)
    steps = [q.time_from_start.sec + 1e-9 * q.time_from_start.nanosec for q in msg.points]
    np.testing.assert_allclose(steps, np.arange(points) / rate, atol=1e-9)
    want = LeggedGaitTable(genes, settings.gait).joint_targets(
        np.arange(points) / rate, np.zeros(points, dtype=int)
    )
    np.testing.assert_array_equal([q.positions for q in msg.points], want)
    assert not node.stopped_reason


def test_evorbc_sim_runs_the_a1(tmp_path, controller, capsys):
    from sim_bridge.bringup import main

    arb_path, rep_path, _, _ = controller
    result = tmp_path / "run.json"
    # Started a few cm from the target: the episode ends at the first cycle, reached.
    argv = ["--robot", "a1", "--arbitrator", str(arb_path), "--repertoire", str(rep_path)]
    picture = tmp_path / "run.png"  # not <maze>-run.png in the working directory
    argv += ["--start=3.3,-0.45,0", "--result", str(result), "--plot", str(picture), "--quiet"]
    assert main([*argv, "--domain-id", str(claim_domain(172))]) == 0
    assert picture.is_file()
    got = json.loads(result.read_text())
    assert got["robot"] == "a1" and got["maze"] == "a1" and got["reached"]
    assert got["episode_time"] == 30.0


def test_evorbc_sim_refuses_an_a1_repertoire_of_another_design(tmp_path, controller, capsys):
    import dataclasses

    from evorbc_ros.repertoire import Repertoire
    from sim_bridge.bringup import main

    arb_path, rep_path, _, _ = controller
    rep = Repertoire.load(rep_path)
    simulation = rep.algorithm["simulation"]
    other = {**simulation, "physics": {**simulation["physics"], "rate_hz": 50.0}}
    path = tmp_path / "other.json"
    dataclasses.replace(rep, algorithm={"simulation": other}).save(path)
    assert main(["--robot", "a1", "--arbitrator", str(arb_path), "--repertoire", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        f"evorbc-sim: error: {path}: was evolved for a different robot "
        "(simulation.physics.rate_hz is 50.0 in the repertoire but 100.0 now)"
    ]
