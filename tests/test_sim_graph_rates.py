"""The simulated graph sends each legged robot's joint trajectories at its own rate.

``evorbc-sim`` and ``sim.launch.py`` start ``primitive_executor`` with the shipped
parameter file (``config/ros/primitive_executor.yaml``) and then the graph's own
parameters. A ``trajectory_rate`` (points per second) other than 0 in that file would
override every robot's own default, its physics rate (the A1: 100 Hz, the hexapod: 50 Hz),
and the A1's lockstep episode would no longer be the offline one. This checks the rate each
robot's executor gets.
"""

import yaml

from evorbc_ros.robots import registry
from sim_bridge.graph import sim_graph


def executor_parameters(robot: str) -> dict:
    """The executor's parameters in the graph for ``robot``: file, then the graph's."""
    spec = next(
        n for n in sim_graph(robot, arbitrator="a.json").nodes if n.name == "primitive_executor"
    )
    data = yaml.safe_load(spec.param_file.read_text())
    from_file = data["/**"]["ros__parameters"]
    return {**from_file, **spec.parameters}


def test_each_legged_robot_gets_its_own_trajectory_rate_in_the_sim_graph():
    checked, wrong = [], {}
    for robot in registry.robots():
        default_rate = getattr(robot.load("commands"), "default_rate", None)
        if default_rate is None:  # wheel or twist commands: no trajectories
            continue
        checked.append(robot.name)
        # Set in the file, it must be the robot's own rate; 0 or unset, the node takes that.
        rate = executor_parameters(robot.name).get("trajectory_rate") or default_rate(robot)
        if rate != default_rate(robot):
            wrong[robot.name] = (rate, default_rate(robot))
    assert checked == ["hexapod", "a1"] and wrong == {}


def test_the_a1_and_the_hexapod_rates_are_their_physics_rates():
    rates = {
        n: registry.lookup(n).load("commands").default_rate(registry.lookup(n))
        for n in ("a1", "hexapod")
    }
    assert rates == {"a1": 100.0, "hexapod": 50.0}
