"""The hexapod through the ROS 2 graph: the executor's trajectories and lockstep parity
with the offline episode, cycle by cycle."""

import math

import numpy as np
import pytest
from builtin_interfaces.msg import Duration
from graph_helpers import assert_lockstep_reproduces, switching_arbitrator
from hexapod_helpers import tripod_repertoire
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.hexapod_executor import HexapodExecutor
from evorbc_ros.nodes.common import vector_message
from evorbc_ros.nodes.primitive_executor import PrimitiveExecutorNode
from evorbc_ros.robots.hexapod import JOINT_NAMES, SERVO_RATE, GaitTable
from offline_evolution.maze_task.hexapod_task import HexapodMazeTask
from offline_evolution.maze_task.task import MazeTaskSettings
from sim_bridge.hexapod.physics import HexapodSim

EPISODE = 4.0  # s: 40 cycles


def test_executor_samples_the_gait_at_the_simulations_step_times():
    genes = np.linspace(-1, 1, 37)
    ex = HexapodExecutor(["a"], stale_timeout=0.3)
    ex.on_input("a", 0.0)
    ex.on_primitive(genes, 0.0)
    sim = HexapodSim()
    n = sim.physics.steps(0.1)  # the executor's default rate is the simulation's
    try:
        for cycle in range(4):
            now = cycle * 100_000_000 * 1e-9  # the node's clock: integer ns
            ex.on_input("a", now)
            cmd = ex.command(now)
            assert not cmd.stopped and cmd.positions.shape == (3 * n, 18)
            want = GaitTable(genes).joint_targets(sim.step_times(n), np.zeros(n, dtype=int))
            np.testing.assert_array_equal(cmd.positions[:n], want)  # bit for bit
            sim.steps_done += n
    finally:
        sim.close()
    # A command covers the stale timeout ahead (0.3 s), so a late one finds the legs walking.
    assert len(cmd.positions) == round(0.3 * SERVO_RATE)
    # Input "a" last came at 0.3 s; at 0.62 s it is stale: hold the point that was being
    # tracked, 0.32 s into the command sent at 0.3 s (past its end: its last point).
    held = ex.command(0.62)
    assert held.stopped and "stale" in held.reason
    np.testing.assert_array_equal(held.positions, cmd.positions[-1:])
    assert ex.command(0.7).positions.tolist() == held.positions.tolist()  # and keep it


def test_executor_holds_the_point_being_tracked_when_an_input_goes_stale():
    ex = HexapodExecutor(["a"], stale_timeout=0.3)
    ex.on_input("a", 0.0)
    ex.on_primitive(np.linspace(-1, 1, 37), 0.0)
    ex.on_primitive(np.linspace(-1, 1, 37), 0.2)  # primitives keep coming, "a" does not
    cmd = ex.command(0.2)
    held = ex.command(0.36)  # "a" is 0.36 s old; the command sent at 0.2 s is at point 8
    assert held.stopped
    np.testing.assert_array_equal(held.positions, cmd.positions[8:9])


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
    try:
        arb, outcome, result = switching_arbitrator(task, rep, "hexapod", "config/neat/hexapod.ini")
    finally:
        task.close()
    arb_path = tmp / "hexapod.arbitrator.json"
    arb.save(arb_path)
    return arb_path, rep_path, outcome, result


def test_lockstep_graph_reproduces_the_offline_episode(tmp_path, controller):
    trajectory = assert_lockstep_reproduces(
        tmp_path, 170, "hexapod", "hexapod", controller, EPISODE
    )
    assert np.hypot(*(trajectory[-1, :2] - trajectory[0, :2])) > 0.2  # it walked


def test_executor_node_sends_the_stale_timeout_ahead_and_holds_on_stale_input(ros):
    node = ros.make(PrimitiveExecutorNode, sim_time=True, robot="hexapod")
    got = ros.listen(JointTrajectory, "joint_trajectory_controller/joint_trajectory")
    prim, rf, gs = ros.executor_inputs()
    genes = np.linspace(-1, 1, 37)
    ros.set_clock(2.0)
    rf.publish(vector_message([0.0] * 5))
    gs.publish(vector_message([0.5]))
    prim.publish(vector_message(genes))
    points = round(0.3 * SERVO_RATE)  # one per physics step of the 0.3 s stale timeout
    assert ros.spin_until(lambda: got and len(got[-1].points) == points)
    msg = got[-1]
    assert list(msg.joint_names) == list(JOINT_NAMES) and len(msg.points) == points
    steps = [p.time_from_start.sec + 1e-9 * p.time_from_start.nanosec for p in msg.points]
    np.testing.assert_allclose(steps, np.arange(points) / SERVO_RATE, atol=1e-9)
    want = GaitTable(genes).joint_targets(
        np.arange(points) / SERVO_RATE, np.zeros(points, dtype=int)
    )
    np.testing.assert_array_equal([p.positions for p in msg.points], want)
    assert not node.stopped_reason
    # Nothing new for more than 0.3 s: the legs hold the trajectory's end, where a
    # controller following it stands by then.
    ros.set_clock(2.5)
    assert ros.spin_until(lambda: node.stopped_reason != "")
    assert ros.spin_until(lambda: len(got[-1].points) == 1)
    np.testing.assert_array_equal(got[-1].points[0].positions, want[-1])


def test_bridge_skips_malformed_trajectories_and_holds_the_last_targets():
    class Node:  # the adapter needs a node only for parameters, subscriptions and logs
        def __init__(self):
            self.warnings = []

        def declare_parameter(self, name, value, descriptor=None):
            return type("P", (), {"value": value})()

        def get_logger(self):
            node = self

            class Log:
                def warning(self, text, **_):
                    node.warnings.append(text)

            return Log()

    from sim_bridge.hexapod.bridge import HexapodBridge
    from sim_bridge.maze import load_named_maze

    node = Node()
    bridge = HexapodBridge(node, "hexapod", load_named_maze("hexapod"), None, 30.0, False)
    try:
        stored = []
        good = JointTrajectory(joint_names=list(reversed(JOINT_NAMES)))
        q = np.arange(18, dtype=float) / 100.0
        good.points = [
            JointTrajectoryPoint(positions=q[::-1].tolist(), time_from_start=Duration()),
            JointTrajectoryPoint(
                positions=(2 * q[::-1]).tolist(), time_from_start=Duration(nanosec=50_000_000)
            ),
        ]
        bridge._store(good, stored.append)
        # reordered by joint name; step k at k / 50 s holds the last point due by then,
        # through the step that reaches the last point (0.06 s)
        assert bridge.dt == pytest.approx(1.0 / 50.0)
        np.testing.assert_allclose(bridge.trajectory, [q, q, q, 2 * q])
        bad = JointTrajectory(joint_names=list(JOINT_NAMES))
        bad.points = [JointTrajectoryPoint(positions=[math.nan] * 18)]
        bridge._store(bad, stored.append)
        bridge._store(JointTrajectory(joint_names=["x"]), stored.append)
        assert stored == ["trajectory"] and len(node.warnings) == 2
        assert "finite" in node.warnings[0] and "18 joints" in node.warnings[1]
        far = JointTrajectory(joint_names=list(JOINT_NAMES))
        far.points = [JointTrajectoryPoint(positions=q.tolist(), time_from_start=Duration()),
                      JointTrajectoryPoint(positions=q.tolist(),
                                           time_from_start=Duration(sec=2**31 - 1))]  # fmt: skip
        bridge._store(far, [].append)  # 68 years ahead: resampled through the episode only
        assert len(bridge.trajectory) == 30 * 50 + 1
        bridge._store(good, stored.append)
        bridge.advance()
        np.testing.assert_allclose(bridge.world.targets, 2 * q)
        # A trajectory of three periods: without a new one the legs walk on through it,
        # then hold its last point.
        long = JointTrajectory(joint_names=list(JOINT_NAMES))
        long.points = [
            JointTrajectoryPoint(
                positions=(k * q).tolist(), time_from_start=Duration(nanosec=20_000_000 * k)
            )
            for k in range(15)
        ]
        bridge._store(long, stored.append)
        for last in (4, 9, 14, 14):
            bridge.advance()
            np.testing.assert_allclose(bridge.world.targets, last * q)
    finally:
        bridge.world.close()


def test_evorbc_sim_refuses_a_start_inside_the_legs_reach_before_starting_the_graph(
    tmp_path, controller, capsys
):
    from evorbc_ros.robots import registry
    from sim_bridge.bringup import main, parse_args, prepare

    arb_path, rep_path, _, _ = controller
    old = tmp_path / "result.json"
    old.write_text('{"reached": true}')
    argv = ["--arbitrator", str(arb_path), "--repertoire", str(rep_path), "--quiet"]
    # The obstacle maze's nominal start is 0.09 m from a wall; the legs reach 0.31 m. No
    # --start was given: the maze is scaled up to fit the robot, as offline runs do.
    _, maze, _ = prepare(parse_args([*argv, "--maze", "obstacle"]))
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("evorbc: warning: maze obstacle scaled x")
    assert maze.start_misfit(registry.lookup("hexapod").footprint_radius, "hexapod") is None
    # A start the user gives, 0.1 m inside the top wall's outer surface, is what is blamed.
    x, top = maze.start_pose[0], maze.bounds()[3] - 0.1
    start = f"--start={x:.2f},{top:.2f},0"
    assert main([*argv, "--maze", "obstacle", start, "--result", str(old), "--plot", ""]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and err[0].startswith("evorbc: warning: maze obstacle scaled x")
    assert err[1].startswith(f"evorbc-sim: error: --start: ({x:.2f}, {top:.2f}) m is")
    assert "m from a wall of maze obstacle" in err[1]
    assert old.exists()  # refused before anything ran: nothing of the user's is touched


def test_evorbc_sim_refuses_a_repertoire_of_another_design(tmp_path, controller, capsys):
    import dataclasses

    from evorbc_ros.repertoire import Repertoire
    from sim_bridge.bringup import main

    arb_path, rep_path, _, _ = controller
    rep = Repertoire.load(rep_path)
    simulation = rep.algorithm["simulation"]
    other = {**simulation, "physics": {**simulation["physics"], "rate_hz": 60.0}}
    path = tmp_path / "other.json"
    dataclasses.replace(rep, algorithm={"simulation": other}).save(path)
    assert main(["--arbitrator", str(arb_path), "--repertoire", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        f"evorbc-sim: error: {path}: was evolved for a different robot "
        "(simulation.physics.rate_hz is 60.0 in the repertoire but 50.0 now)"
    ]


def test_evorbc_sim_refuses_an_arbitrator_for_another_robot(capsys):
    from evorbc_ros.defaults import default_arbitrator
    from sim_bridge.bringup import main

    assert main(["--robot", "hexapod", "--arbitrator", str(default_arbitrator())]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        f"evorbc-sim: error: {default_arbitrator()}: is for robot 4ws-5, not --robot hexapod"
    ]


def test_evorbc_sim_refuses_an_arbitrator_evolved_with_another_laser(tmp_path, controller, capsys):
    import dataclasses

    from evorbc_ros.sensors import SensorLayout
    from sim_bridge.bringup import main

    arb_path, rep_path, _, _ = controller
    arb = ArbitratorFile.load(arb_path)
    layout = arb.sensors.to_dict()
    layout["rangefinders"] = {**layout["rangefinders"], "range": 4.0}  # a longer-range laser
    path = tmp_path / "other-laser.json"
    dataclasses.replace(arb, sensors=SensorLayout.from_dict(layout)).save(path)
    assert main(["--arbitrator", str(path), "--repertoire", str(rep_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"evorbc-sim: error: {path}: its sensor layout")
