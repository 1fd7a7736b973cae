"""The simulated graph's description (sim_bridge.graph), shared by evorbc-sim and the
launch file: which nodes, with which parameters, for which robot, and when the graph ends.
The launch file is run against stand-ins for ``launch`` and ``launch_ros``, so this runs
where ROS 2's launch is not installed; the real one is tried in test_install_wheel and
test_install_colcon where the ros2 CLI is installed."""

import json
import runpy
import sys
import types
from pathlib import Path

import numpy as np
import pytest

from evorbc_ros.config import ConfigError, config_dir
from evorbc_ros.defaults import default_arbitrator
from sim_bridge import bringup
from sim_bridge.graph import (
    ARGUMENTS,
    exit_ends_graph,
    graph_from_arguments,
    param_file,
    sim_graph,
)

ROOT = Path(__file__).resolve().parents[1]
NODES_FILE = config_dir() / "ros" / "arbitrator.yaml"
#: A lockstep graph's sensor nodes and arbitrator take scan and odom reliably.
RELIABLE_INPUTS = {"input_qos": "reliable"}


def params(graph):
    return {n.name: n.parameters for n in graph.nodes}


def test_the_default_graph_runs_the_shipped_4ws_5_controller_in_obstacle():
    graph = sim_graph()
    arb = str(default_arbitrator("4ws-5"))
    assert [n.name for n in graph.nodes] == [
        "laser_sensor",
        "radar_sensor",
        "arbitrator",
        "primitive_executor",
        "sim_bridge",
    ]
    assert params(graph) == {
        "laser_sensor": {"use_sim_time": True, "sensor_layout": arb, **RELIABLE_INPUTS},
        "radar_sensor": {"use_sim_time": True, "sensor_layout": arb, **RELIABLE_INPUTS},
        "arbitrator": {
            "use_sim_time": True,
            "arbitrator": arb,
            "robot": "4ws-5",
            **RELIABLE_INPUTS,
        },
        "primitive_executor": {"use_sim_time": True, "robot": "4ws-5", "lockstep": True},
        "sim_bridge": {
            "robot": "4ws-5",
            "maze": "obstacle",
            "mode": "lockstep",
            "gui": False,
            "start": "nominal",
            "seed": 0,
            "episode_time": 120.0,  # the controller's training episodes
        },
    }
    assert {n.name: n.param_file for n in graph.nodes} == {
        n.name: config_dir() / "ros" / f"{n.name}.yaml" for n in graph.nodes
    }
    assert all(param_file(n.name).is_file() for n in graph.nodes)
    assert [n.name for n in graph.nodes if n.required] == ["sim_bridge"]
    assert [n.name for n in graph.nodes if n.managed] == ["arbitrator", "primitive_executor"]
    assert {n.package for n in graph.nodes} == {"evorbc_ros", "sim_bridge"}
    assert graph.namespace == ""


def test_the_hexapod_gets_its_shipped_controller_and_maze():
    p = params(sim_graph(robot="hexapod", namespace="/robot1/"))
    arb = str(default_arbitrator("hexapod"))
    assert p["arbitrator"]["arbitrator"] == arb and p["arbitrator"]["robot"] == "hexapod"
    assert p["laser_sensor"]["sensor_layout"] == arb
    assert p["sim_bridge"]["maze"] == "hexapod" and p["sim_bridge"]["robot"] == "hexapod"
    assert p["primitive_executor"]["robot"] == "hexapod"
    assert sim_graph(robot="hexapod", namespace="/robot1/").namespace == "robot1"


def test_the_bridge_runs_episodes_as_long_as_the_controller_was_evolved_with(tmp_path):
    import json

    shipped = json.loads(Path(default_arbitrator("hexapod")).read_text())
    longer = tmp_path / "hexapod-60s.json"
    shipped["evolution"]["task"]["episode_time"] = 60.0
    longer.write_text(json.dumps(shipped))
    bridge = params(sim_graph(robot="hexapod", arbitrator=str(longer)))["sim_bridge"]
    assert bridge["episode_time"] == 60.0
    # A file that records no training task, or none that can be read: the robot's default
    # (the bridge's own parameter), and the arbitrator node reports a bad file.
    del shipped["evolution"]
    bare = tmp_path / "bare.json"
    bare.write_text(json.dumps(shipped))
    for arbitrator in (bare, tmp_path / "missing.json"):
        assert (
            "episode_time"
            not in params(sim_graph("hexapod", arbitrator=str(arbitrator)))["sim_bridge"]
        )


def test_a_robot_without_a_shipped_controller_leaves_the_arbitrator_to_refuse():
    p = params(sim_graph(robot="4ws-3"))
    # No file is filled in; the arbitrator node, told the robot, says none ships for it.
    assert "arbitrator" not in p["arbitrator"] and p["arbitrator"]["robot"] == "4ws-3"
    assert p["primitive_executor"]["robot"] == "4ws-3"
    given = params(sim_graph(robot="4ws-3", arbitrator="mine.json", repertoire="r.json"))
    assert given["arbitrator"]["arbitrator"] == "mine.json"
    assert given["arbitrator"]["repertoire"] == "r.json"


def test_launch_arguments_are_parsed_with_one_line_errors():
    assert graph_from_arguments({}) == sim_graph()
    graph = graph_from_arguments(
        {"gui": "True", "seed": "7", "mode": "realtime", "maze": "zigzag", "namespace": "r1"}
    )
    assert params(graph)["sim_bridge"] == {
        "robot": "4ws-5",
        "maze": "zigzag",
        "mode": "realtime",
        "gui": True,
        "start": "nominal",
        "seed": 7,
        "episode_time": 120.0,
    }
    assert graph.namespace == "r1"
    for values, message in [
        ({"robot": "tank"}, "argument robot must be one of 2ws-2, 2ws-3, 4ws-3, 4ws-5, hexapod"),
        ({"mode": "fast"}, "argument mode must be lockstep or realtime, got 'fast'"),
        ({"gui": "yes"}, "argument gui must be true or false, got 'yes'"),
        ({"seed": "-1"}, "argument seed must be an integer >= 0, got '-1'"),
        ({"seed": "x"}, "argument seed must be an integer >= 0, got 'x'"),
    ]:
        with pytest.raises(ConfigError) as info:
            graph_from_arguments(values)
        assert str(info.value).startswith(message)


def test_the_graph_ends_with_the_bridge_or_when_any_node_fails():
    graph = sim_graph()
    bridge, laser = graph.node("sim_bridge"), graph.node("laser_sensor")
    assert exit_ends_graph(bridge, 0) == "sim_bridge exited (the episode is over)"
    assert exit_ends_graph(bridge, 2) == "sim_bridge exited (status 2)"
    assert exit_ends_graph(laser, 0) == ""  # stopped with the rest
    assert exit_ends_graph(laser, None) == ""  # still running
    assert exit_ends_graph(laser, 2).startswith("laser_sensor failed (status 2)")
    assert exit_ends_graph(laser, -11).startswith("laser_sensor failed (status -11)")


class Recorded:
    """A stand-in for a launch class: keeps its arguments."""

    def __init__(self, *args, **kwargs):
        self.args, self.kwargs = args, kwargs


def fake_launch(monkeypatch, values):
    """``launch`` and ``launch_ros`` stand-ins; LaunchConfiguration reads ``values``."""

    class LaunchConfiguration(Recorded):
        def perform(self, context):
            return values.get(self.args[0], context[self.args[0]])

    class Node(Recorded):
        pass

    class LifecycleNode(Node):
        pass

    modules = {
        "launch": {"LaunchDescription": Recorded},
        "launch.actions": {
            "DeclareLaunchArgument": Recorded,
            "EmitEvent": Recorded,
            "OpaqueFunction": Recorded,
            "RegisterEventHandler": Recorded,
            "Shutdown": Recorded,
        },
        "launch.events": {"matches_action": lambda action: ("matches", action)},
        "launch.substitutions": {"LaunchConfiguration": LaunchConfiguration},
        "launch_ros": {},
        "launch_ros.actions": {"Node": Node, "LifecycleNode": LifecycleNode},
        "launch_ros.event_handlers": {"OnStateTransition": Recorded},
        "launch_ros.events": {},
        "launch_ros.events.lifecycle": {"ChangeState": Recorded},
    }
    for name, attrs in modules.items():
        module = types.ModuleType(name)
        module.__dict__.update(attrs)
        monkeypatch.setitem(sys.modules, name, module)


def launch_nodes(monkeypatch, **values):
    fake_launch(monkeypatch, values)
    description = runpy.run_path(str(ROOT / "launch" / "sim.launch.py"))[
        "generate_launch_description"
    ]()
    entities = description.args[0]
    declared = [e for e in entities if "default_value" in e.kwargs]
    defaults = {e.args[0]: e.kwargs["default_value"] for e in declared}
    opaque = entities[-1].kwargs["function"]
    actions = opaque(defaults)
    return declared, [a for a in actions if "executable" in a.kwargs], actions


def test_the_launch_file_declares_every_argument_with_a_description(monkeypatch):
    declared, _, _ = launch_nodes(monkeypatch)
    assert [(e.args[0], e.kwargs["default_value"]) for e in declared] == [
        (a.name, a.default) for a in ARGUMENTS
    ]
    assert all(len(e.kwargs["description"]) > 20 for e in declared)
    assert "namespace" in [e.args[0] for e in declared]


def test_the_launch_file_starts_the_shared_graph(monkeypatch):
    _, nodes, _ = launch_nodes(monkeypatch, robot="hexapod", namespace="robot1")
    graph = sim_graph(robot="hexapod", namespace="robot1")
    assert [n.kwargs["executable"] for n in nodes] == [n.name for n in graph.nodes]
    for node, spec in zip(nodes, graph.nodes, strict=True):
        assert node.kwargs["package"] == spec.package
        assert node.kwargs["namespace"] == "robot1"
        extra = {"autostart": False} if spec.managed else {}
        assert node.kwargs["parameters"] == [str(spec.param_file), spec.parameters | extra]
        assert type(node).__name__ == ("LifecycleNode" if spec.managed else "Node")


def test_the_launch_file_shuts_the_graph_down_and_fails_as_the_shared_rule_says(monkeypatch):
    _, nodes, _ = launch_nodes(monkeypatch)
    on_exit = {n.kwargs["executable"]: n.kwargs["on_exit"] for n in nodes}
    running = types.SimpleNamespace(is_shutdown=False)

    def exited(name, code, context=running):
        return on_exit[name](types.SimpleNamespace(returncode=code), context)

    (shutdown,) = exited("sim_bridge", 0)
    assert shutdown.kwargs["reason"] == "sim_bridge exited (the episode is over)"
    assert exited("laser_sensor", 0) is None
    # A node refused or dead fails the launch (ros2 launch: status 1), naming it.
    for name, code, reason in [
        ("arbitrator", 2, "arbitrator failed (status 2)"),
        ("laser_sensor", -9, "laser_sensor failed (status -9)"),
        ("sim_bridge", 2, "sim_bridge exited (status 2)"),
    ]:
        with pytest.raises(RuntimeError, match=reason.replace("(", r"\(").replace(")", r"\)")):
            exited(name, code)
    # Once the launch is shutting down, exits are expected.
    assert exited("arbitrator", -2, types.SimpleNamespace(is_shutdown=True)) is None


def test_the_launch_file_configures_then_activates_the_lifecycle_nodes(monkeypatch):
    from lifecycle_msgs.msg import Transition

    _, nodes, actions = launch_nodes(monkeypatch)
    managed = [n for n in nodes if type(n).__name__ == "LifecycleNode"]
    assert [n.kwargs["name"] for n in managed] == ["arbitrator", "primitive_executor"]
    for node in managed:
        emitted = [
            a.kwargs["event"].kwargs
            for a in actions
            if "event" in a.kwargs and a.kwargs["event"].kwargs["lifecycle_node_matcher"][1] is node
        ]
        assert [e["transition_id"] for e in emitted] == [Transition.TRANSITION_CONFIGURE]
        handlers = [
            a.args[0].kwargs
            for a in actions
            if a.args and a.args[0].kwargs.get("target_lifecycle_node") is node
        ]
        on = {(h["start_state"], h["goal_state"]): h for h in handlers}
        (activate,) = on["configuring", "inactive"]["entities"]
        assert activate.kwargs["event"].kwargs["transition_id"] == Transition.TRANSITION_ACTIVATE
        assert on["configuring", "inactive"]["handle_once"]  # not after a manual reconfigure
        for start in ("configuring", "errorprocessing"):
            (refused,) = on[start, "unconfigured"]["entities"]
            with pytest.raises(RuntimeError, match="could not be configured"):
                refused.kwargs["function"](None)


def test_evorbc_sim_starts_the_same_graph_with_the_parameter_files(monkeypatch):
    started = []

    class FakeGraph(bringup.Graph):
        def start(self, spec, namespace=""):
            started.append(bringup.node_command(spec.module, spec.parameters, spec.param_file))

    args = bringup.parse_args(["--maze", "zigzag", "--seed", "3", "--start", "random"])
    bringup.start_graph(FakeGraph({}, True), args, "4ws-5", "a.json", "out.json")
    expected = sim_graph(
        maze="zigzag", seed=3, start="random", arbitrator="a.json", result_file="out.json"
    )
    assert started == [
        bringup.node_command(n.module, n.parameters, n.param_file) for n in expected.nodes
    ]
    cmd = started[2]
    assert cmd[cmd.index("--params-file") + 1] == str(NODES_FILE)
    assert "robot:=4ws-5" in cmd and "arbitrator:=a.json" in cmd


def test_node_commands_carry_the_file_the_namespace_and_the_overrides():
    cmd = bringup.node_command("m", {"a": True, "b": "", "c": 1.5}, NODES_FILE, "robot1")
    assert cmd[1:] == [
        "-P",
        "-m",
        "m",
        "--ros-args",
        "--params-file",
        str(NODES_FILE),
        "-r",
        "__ns:=/robot1",
        "-p",
        "a:=true",
        "-p",
        "c:=1.5",
    ]


# -- evorbc-sim's own errors, before any node starts ---------------------------------------


@pytest.fixture
def no_graph(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("a node was started")

    monkeypatch.setattr(bringup, "start_graph", refuse)


def run_sim(capsys, *argv):
    code = bringup.main(list(argv))
    err = capsys.readouterr().err.strip().splitlines()
    assert "Traceback" not in "\n".join(err)
    return code, err


def test_a_mistyped_robot_is_one_line(capsys):
    with pytest.raises(SystemExit) as info:
        bringup.main(["--robot", "4ws5"])
    err = capsys.readouterr().err.strip().splitlines()
    assert info.value.code == 2
    assert err == [
        "evorbc-sim: error: argument --robot: invalid choice: '4ws5' (choose from '2ws-2', "
        "'2ws-3', '4ws-3', '4ws-5', 'hexapod', 'a1', 'turtlebot3-burger') (see evorbc-sim --help)"
    ]


def test_a_robot_without_a_shipped_controller_says_how_to_make_one(capsys, no_graph):
    code, err = run_sim(capsys, "--robot", "2ws-2")
    assert code == 2
    assert err == [
        "evorbc-sim: error: no controller ships for robot 2ws-2 (only for 4ws-5, a1 and hexapod); "
        "make one with 'evorbc-evolve repertoire --robot 2ws-2 --seed 1 --out r.json' and "
        "'evorbc-evolve arbitrator --repertoire r.json --seed 1 --out a.json', then run "
        "'evorbc-sim --arbitrator a.json --repertoire r.json'"
    ]


def test_a_maze_the_robot_does_not_fit_is_scaled_as_offline_and_not_blamed_on_start(
    capsys, tmp_path, no_graph
):
    from evorbc_ros.robots import registry
    from sim_bridge.maze import load_named_maze
    from sim_bridge.maze_fit import fit_scale

    radius = registry.lookup("hexapod").footprint_radius
    factor = fit_scale(load_named_maze("zigzag"), radius)
    assert factor > 1.0  # zigzag's start is too narrow for the hexapod's legs
    # The bridge gets the maze offline runs would use: scaled by the same factor, with the
    # same warning line, and the factor is passed on so that the bridge does not fit again.
    args = bringup.parse_args(["--robot", "hexapod", "--maze", "zigzag"])
    _, maze, _ = bringup.prepare(args)
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(
        f"evorbc: warning: maze zigzag scaled x{factor:g} to fit robot hexapod: "
    )
    assert args.maze_scale == factor and maze.start_misfit(radius, "hexapod") is None
    np.testing.assert_array_equal(maze.walls, load_named_maze("zigzag").walls * factor)
    bridge = sim_graph(robot="hexapod", maze="zigzag", maze_scale=factor).node("sim_bridge")
    assert bridge.parameters["maze_scale"] == factor
    # A factor the controller's task records is applied as it is, without the line: one
    # too small to clear the robot's start is refused, and not blamed on --start.
    arb = json.loads(Path(default_arbitrator("hexapod")).read_text())
    arb["evolution"]["task"].update(mazes=["zigzag"], maze_scale=[1.0])
    edited = tmp_path / "edited.json"
    edited.write_text(json.dumps(arb))
    code, err = run_sim(capsys, "--arbitrator", str(edited), "--maze", "zigzag")
    assert code == 2 and len(err) == 1
    assert err[0].startswith("evorbc-sim: error: robot hexapod does not fit maze zigzag: ")
    assert "--start" not in err[0] and err[0].endswith("its maze is hexapod")


def test_adaptation_turns_on_the_arbitrator_s_and_the_bridge_waits_for_its_odom():
    """evorbc-sim --adapt, launch adaptation:=true: the arbitrator adapts, and the bridge
    waits for both odom subscribers (radar, arbitrator) so that lockstep stays exact."""
    plain, adapting = sim_graph(), sim_graph(adaptation=True)
    arbitrator = adapting.node("arbitrator").parameters
    assert arbitrator["adaptation"] is True
    assert "adaptation" not in plain.node("arbitrator").parameters
    bridge = adapting.node("sim_bridge").parameters
    assert bridge["wait_for_subscribers"] == ["scan", "odom", "odom"]
    assert "wait_for_subscribers" not in plain.node("sim_bridge").parameters
    assert graph_from_arguments({"adaptation": "true"}) == adapting


def test_a_recorded_graph_counts_the_recorder_s_subscribers_before_the_first_state():
    """With a bag the recorder subscribes ``scan`` and ``odom`` too: the bridge waits for
    two of each, so that the recorder's alone cannot let the first state go out before
    the sensor nodes' subscriptions are discovered (a CI run lost the radar node's first
    odometry that way, and the state sent again 30 s later was answered twice)."""
    bag = sim_graph(bag="run-bag").node("sim_bridge").parameters
    assert bag["wait_for_subscribers"] == ["scan", "odom", "scan", "odom"]
    assert bag["wait_for_ready"] == ["recorder/ready"]
    both = sim_graph(bag="run-bag", adaptation=True).node("sim_bridge").parameters
    assert sorted(both["wait_for_subscribers"]) == ["odom", "odom", "odom", "scan", "scan"]


def test_adaptation_expected_settled_is_the_arbitrator_s_parameter():
    """evorbc-sim --adapt-expected settled, launch adaptation_expected:=settled: the
    arbitrator reads the settled outcomes shipped beside the repertoire; the default
    passes nothing, so a graph adapting as before is the same graph."""
    settled = sim_graph(adaptation=True, adaptation_expected="settled")
    assert settled.node("arbitrator").parameters["adaptation_expected"] == "settled"
    assert "adaptation_expected" not in sim_graph(adaptation=True).node("arbitrator").parameters
    given = {"adaptation": "true", "adaptation_expected": "settled"}
    assert graph_from_arguments(given) == settled
    assert (
        bringup.parse_args(["--adapt", "--adapt-expected", "settled"]).adapt_expected == "settled"
    )
    with pytest.raises(
        ConfigError,
        match=r"^argument adaptation_expected must be recorded or settled, got .learned.$",
    ):
        graph_from_arguments({"adaptation_expected": "learned"})
