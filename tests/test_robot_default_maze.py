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
