"""Every registered robot starts in its own default maze (docs/your-robot.md).

``evorbc-sim --robot NAME`` and ``sim.launch.py robot:=NAME`` put the robot at the nominal
start of the registration's ``maze``; the bridge refuses a start whose nearest wall is
closer than the robot's ``footprint_radius`` (m). A registration whose default maze it does
not fit makes the default command fail, so this checks every robot evorbc ships.
"""

import pytest

from evorbc_ros.robots import registry
from sim_bridge.bridge_node import SimBridgeNode
from sim_bridge.graph import default_maze
from sim_bridge.maze import load_named_maze


@pytest.mark.parametrize("name", registry.names())
def test_each_robot_fits_the_nominal_start_of_its_default_maze(name):
    robot = registry.lookup(name)
    maze = load_named_maze(default_maze(name))
    x, y, _ = maze.start_pose
    assert maze.clearance(x, y) >= robot.footprint_radius, (name, maze.name)
    # The bridge's own start check (what evorbc-sim runs before any node starts) agrees.
    assert SimBridgeNode._start_pose(maze, "nominal", 0, robot.footprint_radius, name) == (
        maze.start_pose
    )


@pytest.mark.parametrize("name", registry.names())
def test_each_robots_default_task_builds_with_starts_that_clear_its_footprint(name):
    from offline_evolution.arbitrator.settings import load_run_settings
    from offline_evolution.maze_task.base import MazeTaskSettings

    robot = registry.lookup(name)
    settings = MazeTaskSettings.load(load_run_settings(None, name).task_path())
    for maze_name in settings.mazes:
        assert load_named_maze(maze_name).start_misfit(robot.footprint_radius, name) is None


def test_a_task_maze_whose_start_the_robot_does_not_fit_is_scaled_to_fit(capsys):
    """Offline tasks scale such a maze up (docs/design.md section 21); see test_maze_fit."""
    from offline_evolution.maze_task.base import MazeTaskSettings
    from offline_evolution.maze_task.task import make_task

    settings = MazeTaskSettings(("obstacle", "zigzag"), 120.0)
    task = make_task(settings, "turtlebot3-burger")
    task.close()
    assert task.settings.maze_scale == (1.12, 1.0)
    assert capsys.readouterr().err == ""  # told by the run that builds it (its reporters)
    assert task.warnings == [
        "maze obstacle scaled x1.12 to fit robot turtlebot3-burger: its "
        "start is 0.094 m from a wall and the robot needs 0.105 m"
    ]
    assert task.task_mazes[0].start_misfit(0.105, "turtlebot3-burger") is None
    make_task(settings, "4ws-5").close()  # the 4WS robots' 0.05 m footprint fits
    assert capsys.readouterr().err == ""
