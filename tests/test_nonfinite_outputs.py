"""Networks whose outputs are not finite: no primitive, the robot stops, nothing crashes.

An arbitrator file may hold any finite weights and biases and any neat-python activation,
so a network can overflow (``cube`` with bias 1e300, identity with 1e308 weights). Such a
cycle runs no primitive, onboard and offline alike: 4WS robots stop with the steering held,
the hexapod holds every joint at its last target. A lockstep graph still makes the offline
replay's choices cycle by cycle.
"""

import json
import math

import numpy as np
import pytest
from graph_helpers import GraphRun, assert_same_choices

from evorbc_ros.arbitration import Controller
from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.defaults import default_repertoire, paper_arbitrator
from evorbc_ros.executor import NO_PRIMITIVE_REASON, PrimitiveExecutor
from evorbc_ros.hexapod_executor import HexapodExecutor
from evorbc_ros.mapping import (
    NO_PRIMITIVE,
    MappingFunction,
    PrimitiveLookup,
    choose_primitive,
    clamped_cell,
)
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.four_ws import FourWSGeometry
from evorbc_ros.robots.registry import robot_type
from offline_evolution import cli
from offline_evolution.maze_task import kernel
from offline_evolution.maze_task.replay import replay
from offline_evolution.maze_task.task import MazeTask, MazeTaskSettings

# The paper-protocol networks: the edits below know their nodes and inputs, and the
# episodes their paths (baffles: drives about 29 s, then stops).
ARB = json.loads(paper_arbitrator().read_text())
HEX_ARB = json.loads(paper_arbitrator("hexapod").read_text())


def cube_1e300(data):
    """Every node ``cube`` with bias 1e300: outputs overflow to infinity (or NaN)."""
    for node in data["network"]["nodes"]:
        node.update(activation="cube", bias=1e300)


def identity_1e308(data):
    """Identity activations and 1e308 weights: sums overflow."""
    for node in data["network"]["nodes"]:
        node["activation"] = "identity"
    for c in data["network"]["connections"]:
        c["weight"] = 1e308


def stop_near_walls(data, front_input=-1, threshold=0.5):
    """m2 becomes infinite whenever the front rangefinder reads above ``threshold``.

    A relu node ``relu(1e308 (r - threshold))`` feeds m2 (made ``identity``, which does not
    clamp as sigmoid does) with weight 1e300: finite while the wall is far, infinite once
    it is near. So a run drives, then stops.
    """
    net = data["network"]
    net["nodes"][1]["activation"] = "identity"
    net["nodes"].append(
        {
            "key": 99999,
            "bias": -threshold * 1e308,
            "response": 1.0,
            "activation": "relu",
            "aggregation": "sum",
        }
    )
    net["connections"] += [
        {"source": front_input, "target": 99999, "weight": 1e308, "enabled": True},
        {"source": 99999, "target": 1, "weight": 1e300, "enabled": True},
    ]


def edited(data, edit, tmp_path=None, name="arb.json"):
    d = json.loads(json.dumps(data))
    edit(d)
    if tmp_path is None:
        return ArbitratorFile.from_dict(d)
    path = tmp_path / name
    path.write_text(json.dumps(d))
    return path


# -- onboard: the arbitrator's choice ------------------------------------------------------


@pytest.mark.parametrize("edit", [cube_1e300, identity_1e308])
def test_the_onboard_controller_chooses_no_primitive_and_does_not_raise(tmp_path, edit):
    path = edited(ARB, edit, tmp_path)
    controller = Controller(str(path), str(default_repertoire()))
    inputs = np.array([0.2, 0.0, 0.0, 0.1, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    genes, row = controller.step(inputs)
    assert genes.shape == (0,)
    assert row[4] == NO_PRIMITIVE and math.isnan(row[2]) and math.isnan(row[3])
    assert not all(map(math.isfinite, row[:2]))
    reason = controller.no_primitive_reason(inputs, genes, row)
    assert "not finite" in reason and "the robot stops" in reason


def standard_controller_file(tmp_path):
    """The shipped 4ws-5 arbitrator made a standard-NEAT one (5 outputs); its data, path."""
    data = json.loads(json.dumps(ARB))
    data.update(kind="standard", parameters=[p.as_dict() for p in Repertoire.load(
        default_repertoire()).parameters])  # fmt: skip
    del data["mapping"], data["repertoire"]
    net = data["network"]
    net["outputs"] = [0, 1, 2, 3, 4]
    net["nodes"] += [dict(net["nodes"][0], key=k) for k in (2, 3, 4)]
    path = tmp_path / "standard.json"
    path.write_text(json.dumps(data))
    return data, path


def test_a_standard_controller_with_non_finite_outputs_runs_no_genes(tmp_path):
    data, path = standard_controller_file(tmp_path)
    controller = Controller(str(path))
    inputs = np.full(10, 0.5)
    genes, row = controller.step(inputs)
    assert genes.shape == (5,) and row == []  # finite: the genes run
    cube_1e300(data)
    path.write_text(json.dumps(data))
    genes, row = Controller(str(path)).step(inputs)
    assert genes.shape == (0,) and row == []


def test_huge_but_finite_points_use_the_border_cell_in_python_and_compiled_code():
    b = np.array([[0.1, 0.0], [-0.1, 0.05], [0.0, -0.2]])
    fn = MappingFunction.for_behaviours("cartesian", b)
    lookup = PrimitiveLookup.build(b, fn.domain(), cells=8)
    origin, cell = np.array(lookup.origin), np.array(lookup.cell)
    for x, y in [(1e300, 1e300), (-1e300, 1e300), (1e300, -1e300), (0.05, 1e308)]:
        python = lookup.nearest(x, y)
        compiled = kernel._lookup(x, y, origin, cell, lookup.table)
        assert python == compiled
    assert clamped_cell(1e300, 8) == 7 and clamped_cell(-1e300, 8) == 0
    assert clamped_cell(3.7, 8) == 3
    # Outputs that are not finite, or map outside float range, choose nothing.
    polar = MappingFunction.for_behaviours("polar", b)
    for m in [(math.nan, 0.5), (0.5, math.inf), (1e308, 0.5)]:  # 2 x 1e308 overflows
        assert choose_primitive(polar, lookup, *m)[0] == NO_PRIMITIVE
    assert choose_primitive(fn, lookup, 1e308, 0.5)[0] == lookup.nearest(1e300, 0.0)


def test_python_and_compiled_networks_agree_when_values_overflow():
    """NaN and infinity inside a network give the same outputs onboard and offline."""
    from evorbc_ros.network import ConnectionSpec, NetworkSpec, NodeSpec
    from offline_evolution.arbitrator.compiled import activate_packed, pack_networks

    def node(key, activation, aggregation="sum", bias=0.0):
        return NodeSpec(key, bias, 1.0, activation, aggregation)

    spec = NetworkSpec(
        input_keys=(-1, -2, -3),
        output_keys=(0, 1),
        nodes=(
            node(5, "cube", bias=1e300),  # infinity
            node(6, "identity"),  # infinity - infinity: NaN
            node(0, "identity", "median"),  # the median of NaN and two inputs
            node(1, "log", "max"),
        ),
        connections=(
            ConnectionSpec(-1, 5, 1.0),
            ConnectionSpec(5, 6, 1.0),
            ConnectionSpec(5, 6, -1.0),
            ConnectionSpec(-1, 0, 1.0),
            ConnectionSpec(6, 0, 1.0),
            ConnectionSpec(-2, 0, 1.0),
            ConnectionSpec(6, 1, 1.0),
            ConnectionSpec(-3, 1, 1.0),
        ),
    )
    pack = pack_networks([spec])
    for inputs in ([0.1, 0.5, 0.2], [0.9, 0.3, 0.0], [0.0, 0.0, 1.0]):
        python = spec.compile().activate(inputs)
        compiled = activate_packed(pack, 0, inputs)
        np.testing.assert_array_equal(python, compiled)


# -- onboard: the executor -----------------------------------------------------------------


def test_an_empty_primitive_stops_a_4ws_robot_at_once_with_the_steering_held():
    ex = PrimitiveExecutor(robot_type("4ws-5"), FourWSGeometry(), ["rf", "goal"], 0.3)
    for name in ("rf", "goal"):
        ex.on_input(name, 0.0)
    ex.on_primitive([1.0, 0.5, 0.5, -0.5, -0.5], 0.0)
    running = ex.command(0.0)
    assert not running.stopped and running.speed > 0
    ex.on_primitive([], 0.1)
    stopped = ex.command(0.1)
    assert stopped.stopped and stopped.speed == 0.0 and stopped.reason == NO_PRIMITIVE_REASON
    np.testing.assert_array_equal(stopped.steering, running.steering)
    assert ex.stale(0.1) == []  # the arbitrator is alive: this is no stale stop
    ex.on_primitive([1.0, 0.5, 0.5, -0.5, -0.5], 0.2)
    assert not ex.command(0.2).stopped  # the next primitive runs at once


def test_an_empty_primitive_holds_the_hexapod_at_the_target_being_tracked():
    ex = HexapodExecutor(["a"], stale_timeout=0.3)
    ex.on_primitive([], 0.0)  # nothing sent yet: nothing to hold
    first = ex.command(0.0)
    assert first.stopped and len(first.positions) == 0 and ex.halted
    genes = np.linspace(-0.5, 0.5, 37)
    ex.on_input("a", 0.1)
    ex.on_primitive(genes, 0.1)
    walking = ex.command(0.1)
    assert not walking.stopped and len(walking.positions) == 15
    ex.on_input("a", 0.2)
    ex.on_primitive([], 0.2)
    held = ex.command(0.2)  # 0.1 s = 5 physics steps after the last command
    assert held.stopped and held.reason == NO_PRIMITIVE_REASON
    np.testing.assert_array_equal(held.positions, walking.positions[5:6])
    np.testing.assert_array_equal(ex.command(0.3).positions, walking.positions[5:6])
    ex.on_input("a", 0.4)
    ex.on_primitive(genes, 0.4)
    again = ex.command(0.4)  # the gait clock ran on: 15 steps since it started
    assert not again.stopped and ex.gait_step(0.4) == 15


# -- offline -------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def task():
    return MazeTask(MazeTaskSettings(("obstacle", "baffles"), 35.0), "4ws-5")


@pytest.mark.parametrize("edit", [cube_1e300, identity_1e308])
def test_offline_replay_stands_still_and_counts_the_stopped_cycles(task, edit):
    arb = edited(ARB, edit)
    outcomes, result = replay(arb, task, task.nominal_starts(), Repertoire.load(
        default_repertoire()))  # fmt: skip
    for k, o in enumerate(outcomes):
        n = int(result.cycles[k])
        assert o.stopped_cycles == n == 350 and not o.reached
        assert np.all(result.choice[k, :n] == NO_PRIMITIVE)
        np.testing.assert_array_equal(result.pose[k, : n + 1], result.pose[k, :1].repeat(n + 1, 0))


def test_the_kernel_stops_like_the_onboard_controller_cycle_by_cycle(task):
    """A network that drives, then stops near a wall: the compiled kernel and the onboard
    controller (pure Python) choose the same, no-primitive cycles included."""
    from sim_bridge.four_ws.motion import STATE_SIZE, speed_through_wheels, step_robot
    from sim_bridge.sensors import read_sensors

    arb = edited(ARB, stop_near_walls)
    rep = Repertoire.load(default_repertoire())
    starts = task.nominal_starts()
    outcomes, result = replay(arb, task, starts, rep)
    assert any(0 < o.stopped_cycles < 350 for o in outcomes)  # drove, then stopped
    controller = task.controller("evorbc", rep, "polar")
    from evorbc_ros.arbitrator import Arbitrator

    onboard = Arbitrator(arb, rep)
    for e, row in enumerate(starts):
        maze = task.mazes[int(row[0])]
        every = np.arange(len(maze.boxes), dtype=np.int64)
        state = np.zeros((1, STATE_SIZE))
        state[0, :3] = row[1:]
        inputs = np.empty(task.sensors.n_inputs)
        command = np.zeros(5)
        for t in range(int(result.cycles[e])):
            np.testing.assert_array_equal(result.pose[e, t], state[0, :3])
            read_sensors(
                *state[0, :3], *maze.target, *state[0, :2], task.sensors, maze.boxes, every, inputs
            )
            choice, _ = onboard.choose(inputs)
            assert choice == result.choice[e, t], (e, t)
            if choice == NO_PRIMITIVE:
                command[0] = 0.0  # the executor's stop: steering held
            else:
                command = controller.primitive_commands[choice].copy()
                # The speed as onboard, through wheel rad/s (docs/design.md section 2).
                command[0] = speed_through_wheels(command[0], task.robot.speed_wheel_radius)
            step_robot(state, 0, command, task.robot.limits, maze.boxes, every)


def test_replay_command_warns_about_the_stopped_cycles(tmp_path, capsys):
    path = edited(ARB, cube_1e300, tmp_path)
    assert cli.main(["replay", "--arbitrator", str(path), "--maze", "obstacle"]) == 0
    err = capsys.readouterr().err
    assert "obstacle: the network's outputs were not finite in 1200 of 1200 cycles" in err


def test_a_hexapod_episode_holds_its_joints_when_the_network_stops(tmp_path):
    """Offline hexapod: walks, then no primitive; every joint holds the tracked target."""
    from offline_evolution.maze_task.hexapod_task import HexapodMazeTask

    arb = edited(HEX_ARB, lambda d: stop_near_walls(d, front_input=-3, threshold=0.3))
    rep = Repertoire.load(default_repertoire("hexapod"))
    task = HexapodMazeTask(MazeTaskSettings(("hexapod",), 4.0, 1, "sensors/hexapod.yaml"), 1)
    try:
        _, result = replay(arb, task, task.nominal_starts(), rep)
        all_stop = replay(edited(HEX_ARB, cube_1e300), task, task.nominal_starts(), rep)
    finally:
        task.close()
    choice = result.choice[0, :40]
    first = int(np.argmax(choice == NO_PRIMITIVE))
    assert first > 0 and np.all(choice[first:] == NO_PRIMITIVE) and np.all(choice[:first] >= 0)
    pose = result.pose[0]
    walked = np.hypot(*(pose[first, :2] - pose[0, :2]))
    after = np.hypot(*(pose[40, :2] - pose[first + 3, :2]))
    assert walked > 0.3 and after < 0.03  # it walked (about 0.16 m/s), then stood
    stood = all_stop[1].pose[0]
    assert np.max(np.hypot(*(stood[:41, :2] - stood[0, :2]).T)) < 0.01


# -- through the ROS graph -----------------------------------------------------------------


def test_lockstep_graph_stops_like_the_offline_replay_and_logs_it(tmp_path, task):
    path = edited(ARB, stop_near_walls, tmp_path)
    rep = Repertoire.load(default_repertoire())
    k = 1  # baffles: drives about 29 s, then stops in front of a wall
    _, result = replay(ArbitratorFile.load(path), task, task.nominal_starts(), rep)
    run = GraphRun(tmp_path, 190, "baffles", episode_time=35.0, arbitrator=path)
    got = run.finish(timeout=120)
    choices = run.recorded_choices()
    cycles = assert_same_choices(choices, result, k)
    assert 0 < np.sum(choices[:cycles] == NO_PRIMITIVE) < cycles
    np.testing.assert_allclose(np.array(got["trajectory"]), result.pose[k, : cycles + 1], atol=1e-9)
    log = (tmp_path / "baffles-lockstep.log").read_text()
    assert "Traceback" not in log
    assert "no primitive, the robot stops" in log  # the arbitrator's warning
    assert f"stopping the robot: {NO_PRIMITIVE_REASON}" in log  # the executor's


def test_lockstep_hexapod_graph_holds_from_the_first_cycle_like_the_offline_episode(tmp_path):
    from offline_evolution.maze_task.hexapod_task import HexapodMazeTask

    path = edited(HEX_ARB, cube_1e300, tmp_path)
    rep = Repertoire.load(default_repertoire("hexapod"))
    task = HexapodMazeTask(MazeTaskSettings(("hexapod",), 1.0, 1, "sensors/hexapod.yaml"), 1)
    try:
        _, result = replay(ArbitratorFile.load(path), task, task.nominal_starts(), rep)
    finally:
        task.close()
    run = GraphRun(
        tmp_path, 191, "hexapod", episode_time=1.0, arbitrator=path, robot="hexapod",
        repertoire=default_repertoire("hexapod"),
    )  # fmt: skip
    got = run.finish(timeout=120)
    cycles = assert_same_choices(run.recorded_choices(), result)
    assert cycles == 10
    np.testing.assert_array_equal(np.array(got["trajectory"]), result.pose[0, : cycles + 1])
    log = (tmp_path / "hexapod-lockstep.log").read_text()
    assert "Traceback" not in log and "no primitive, the robot stops" in log
