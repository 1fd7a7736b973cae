"""Every registered robot starts in its own default maze (docs/your-robot.md).

``evorbc-sim --robot NAME`` and ``sim.launch.py robot:=NAME`` put the robot at the nominal
start of the registration's ``maze``; the bridge refuses a start whose nearest wall is
closer than the robot's ``footprint_radius`` (m). A registration whose default maze it does
not fit makes the default command fail, so this checks every robot evorbc ships.
"""

import pytest

from evorbc_ros.config import ConfigError
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


def test_a_task_maze_whose_start_the_robot_does_not_fit_is_refused_in_one_line(tmp_path, capsys):
    from offline_evolution import cli
    from offline_evolution.maze_task.base import MazeTaskSettings
    from offline_evolution.maze_task.task import make_task

    settings = MazeTaskSettings(("obstacle", "zigzag"), 120.0)
    with pytest.raises(ConfigError) as e:
        make_task(settings, "turtlebot3-burger")
    assert str(e.value) == (
        "mazes: robot turtlebot3-burger does not fit maze obstacle: at the maze's start "
        "(-5.46, 0.65) m the nearest wall is 0.094 m away, and the robot needs 0.105 m"
    )
    make_task(settings, "4ws-5").close()  # the 4WS robots' 0.05 m footprint fits
    task = tmp_path / "task.yaml"
    task.write_text("mazes: [obstacle, zigzag]\n")
    repertoire = tmp_path / "r.json"
    assert (
        cli.main(
            [
                "repertoire",
                "--robot",
                "turtlebot3-burger",
                "--iterations",
                "2",
                "--out",
                str(repertoire),
                "--quiet",
            ]
        )
        == 0
    )
    code = cli.main(
        [
            "arbitrator",
            "--repertoire",
            str(repertoire),
            "--task",
            str(task),
            "--out",
            str(tmp_path / "a.json"),
        ]
    )
    assert code == 1
    assert capsys.readouterr().err.strip().splitlines()[-1] == (
        f"evorbc-evolve: error: {task}: mazes: robot turtlebot3-burger does not fit maze "
        "obstacle: at the maze's start (-5.46, 0.65) m the nearest wall is 0.094 m away, and "
        "the robot needs 0.105 m"
    )
