"""A robot from a settings file, in a maze scaled to fit it, through the lockstep ROS graph.

The Husky-like robot (``tests/robots/husky/``: a 0.6 m footprint radius, declared by its
dimensions only) fits the A1's maze only scaled up x1.211. The offline episode runs in the
scaled maze (docs/design.md section 21); the bridge fits the maze the same way, with the same
warning, so the lockstep graph makes the offline episode's choices and poses bit for bit
(docs/design.md section 9, "Lockstep parity").
"""

from pathlib import Path

import numpy as np
import pytest
from graph_helpers import GraphRun, assert_same_choices, switching_arbitrator

from evorbc_ros.robots import registry
from evorbc_ros.robots.settings_robots import PATH_VARIABLE
from sim_bridge.maze import load_named_maze

HUSKY = Path(__file__).parent / "robots" / "husky"
MAZE = "a1"  # 8 x 2.5 m; its narrowest gap (1.19 m) is short of the 1.44 m the robot needs
FACTOR = 1.211
EPISODE = 12.0  # s: 120 cycles
DOMAIN = 180  # the ROS domain of this file's graph (tests/ros_domains.py)


@pytest.fixture(scope="module")
def husky_path():
    """The robot's folder on $EVORBC_ROBOT_PATH, in this process and the graph's."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(PATH_VARIABLE, str(HUSKY))
        registry.reset()
        yield
    registry.reset()


@pytest.fixture(scope="module")
def controller(tmp_path_factory, husky_path):
    """A small repertoire, an arbitrator that switches primitives, and the offline episode."""
    from evorbc_ros.repertoire import Repertoire
    from offline_evolution import cli
    from offline_evolution.maze_task.base import MazeTaskSettings
    from offline_evolution.maze_task.task import make_task

    tmp = tmp_path_factory.mktemp("husky")
    rep_path = tmp / "husky.repertoire.json"
    args = ["repertoire", "--robot", "husky", "--iterations", "2", "--quiet"]
    assert cli.main([*args, "--out", str(rep_path)]) == 0
    rep = Repertoire.load(rep_path)
    sensors = str(HUSKY / "sensors.yaml")
    task = make_task(MazeTaskSettings((MAZE,), EPISODE, 1, sensors), "husky")
    try:
        assert task.settings.maze_scale == (FACTOR,)
        evolution = {"task": task.settings.as_dict()}
        arb, outcome, result = switching_arbitrator(
            task, rep, "husky", "config/neat/4ws.ini", evolution=evolution
        )
    finally:
        task.close()
    arb_path = tmp / "husky.arbitrator.json"
    arb.save(arb_path)
    return arb_path, rep_path, outcome, result


def test_the_graph_drives_the_scaled_maze_exactly_as_offline(tmp_path, controller, monkeypatch):
    from sim_bridge.graph import sim_graph

    monkeypatch.setenv(PATH_VARIABLE, str(HUSKY))  # the graph's processes register it too
    arb_path, rep_path, outcome, result = controller
    # evorbc-sim and the launch file give the bridge the factor the controller's task
    # recorded; this graph leaves it to the bridge, which fits the maze as offline did.
    bridge = sim_graph(robot="husky", maze=MAZE, arbitrator=str(arb_path)).node("sim_bridge")
    assert bridge.parameters["maze_scale"] == FACTOR
    # Its rangefinders reach 5.9 m from the centre: the scan must too (docs/design.md s. 9).
    assert bridge.parameters["laser_range"] == pytest.approx(5.9)
    run = GraphRun(
        tmp_path,
        DOMAIN,
        MAZE,
        episode_time=EPISODE,
        arbitrator=arb_path,
        repertoire=rep_path,
        robot="husky",
        bridge={"laser_range": bridge.parameters["laser_range"]},
    )
    got = run.finish(timeout=120.0)
    choices = run.recorded_choices()
    cycles = assert_same_choices(choices, result)  # every cycle, the offline choice
    assert len(set(choices.tolist())) >= 3  # the arbitrator switched primitives
    trajectory = np.array(got["trajectory"])
    np.testing.assert_array_equal(trajectory, result.pose[0, : cycles + 1])  # bit for bit
    assert got["fitness"] == outcome.fitness and got["reached"] == outcome.reached
    assert got["maze_scale"] == FACTOR and got["robot"] == "husky"
    log = (tmp_path / f"{MAZE}-lockstep.log").read_text()
    assert f"maze a1 scaled x{FACTOR:g} to fit robot husky: its narrowest gap" in log
    assert np.hypot(*(trajectory[-1, :2] - trajectory[0, :2])) > 0.5  # it drove
    # Both started at the scaled maze's nominal start.
    x, y, _ = load_named_maze(MAZE).start_pose
    assert tuple(trajectory[0, :2]) == (x * FACTOR, y * FACTOR)


def test_the_bridge_fits_the_maze_or_applies_the_factor_given(husky_path):
    from evorbc_ros.nodes.common import StartupError
    from sim_bridge.bridge_node import robot_maze

    maze, factor, warning = robot_maze(MAZE, 0.0, 0.6, "husky")
    assert factor == FACTOR and maze.target_radius == load_named_maze(MAZE).target_radius * FACTOR
    assert warning == (
        "maze a1 scaled x1.211 to fit robot husky: its narrowest gap on the way is 1.190 m "
        "and the robot needs 1.440 m (1.2 x its 0.600 m footprint radius each side)"
    )
    # A recorded factor is applied as it is, without the line, as offline.
    maze, factor, warning = robot_maze(MAZE, 2.0, 0.6, "husky")
    assert factor == 2.0 and warning is None and maze.start_pose[0] == 2.0 * -3.4
    # A robot that fits gets the maze as its file has it.
    assert robot_maze(MAZE, 0.0, 0.05, "4ws-5")[1:] == (1.0, None)
    with pytest.raises(StartupError, match=r"^parameter maze_scale must be 0 \(fit the robot\) "):
        robot_maze(MAZE, 0.5, 0.6, "husky")
    with pytest.raises(StartupError, match=r"^parameter maze: unknown maze 'nosuch'"):
        robot_maze("nosuch", 0.0, 0.6, "husky")
