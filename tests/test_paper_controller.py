"""The paper-protocol controller by name (issue 21, item 5): a registration's
``paper_arbitrator`` is what ``evorbc_ros.defaults.paper_arbitrator``, ``evorbc-evolve
evaluate --paper``, ``evorbc-sim --paper`` and ``sim.launch.py paper:=true`` run, while
the shipped arbitrator stays the default; without the field both are the shipped one."""

import dataclasses
import json
import shutil

import pytest

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.config import ConfigError, config_dir
from evorbc_ros.defaults import (
    DATA_DIR,
    default_arbitrator,
    default_repertoire,
    paper_arbitrator,
)
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots import registry
from evorbc_ros.robots.registry import Registry, RobotError
from evorbc_ros.sensors import SensorLayout
from offline_evolution.cli import main as evolve
from sim_bridge import bringup
from sim_bridge.graph import graph_from_arguments, shipped_arbitrator, sim_graph

#: The error of --paper with --arbitrator (evorbc-evolve evaluate and evorbc-sim).
BOTH = (
    "--paper and --arbitrator cannot be combined: --paper picks the paper-protocol "
    "controller shipped for --robot"
)


def eight_sectors(path):
    """The paper-protocol 4ws-5 arbitrator with 8 goal sectors (the 4 new inputs unused),
    as a default trained on generated mazes would have; written to ``path``."""
    arb = ArbitratorFile.load(paper_arbitrator("4ws-5"))
    layout = SensorLayout.load(config_dir() / "sensors" / "4ws-8sectors.yaml")
    net = arb.network
    extra = tuple(range(-len(net.input_keys) - 1, -layout.n_inputs - 1, -1))
    evolution = {**arb.evolution, "task": {**arb.evolution["task"]}}
    evolution["task"]["sensors"] = "sensors/4ws-8sectors.yaml"
    dataclasses.replace(
        arb,
        network=dataclasses.replace(net, input_keys=net.input_keys + extra),
        sensors=layout,
        evolution=evolution,
    ).save(path)


@pytest.fixture
def mine(tmp_path, monkeypatch):
    """4ws-5 registered anew in this process, shipping two 4ws-5 arbitrators outside
    evorbc_ros/data: a default with 8 goal sectors and, named by ``paper_arbitrator``, a
    copy of the paper-protocol one."""
    files = {kind: tmp_path / f"{kind}.arbitrator.json" for kind in ("default", "paper")}
    eight_sectors(files["default"])
    shutil.copy(paper_arbitrator("4ws-5"), files["paper"])
    rep = tmp_path / "4ws-5.repertoire.json"
    shutil.copy(default_repertoire("4ws-5"), rep)
    robot = dataclasses.replace(
        registry.lookup("4ws-5"),
        shipped_repertoire=str(rep),
        shipped_arbitrator=str(files["default"]),
        paper_arbitrator=str(files["paper"]),
    )
    monkeypatch.setattr(registry, "_registry", Registry(builtin_modules=()))
    registry.register(robot)
    return files


def test_a_registration_resolves_its_paper_arbitrator(mine):
    assert paper_arbitrator("4ws-5") == mine["paper"]
    assert default_arbitrator("4ws-5") == mine["default"]
    assert shipped_arbitrator("4ws-5", paper=True) == str(mine["paper"])
    assert shipped_arbitrator("4ws-5") == str(mine["default"])
    # A relative name is in evorbc_ros/data, as the other shipped files are.
    relative = dataclasses.replace(registry.lookup("4ws-5"), name="rel", paper_arbitrator="x.json")
    registry.register(relative)
    assert paper_arbitrator("rel") == DATA_DIR / "x.json"


def test_every_shipped_paper_arbitrator_exists_and_without_the_field_is_the_shipped_one():
    for robot in registry.robots():
        if not robot.shipped_arbitrator:
            continue
        paper = ArbitratorFile.load(paper_arbitrator(robot.name))  # it ships, and loads
        assert paper.robot == robot.name
        if not robot.paper_arbitrator:
            assert paper_arbitrator(robot.name) == default_arbitrator(robot.name)
            assert shipped_arbitrator(robot.name, paper=True) == shipped_arbitrator(robot.name)
    assert registry.lookup("a1").paper_arbitrator == ""
    # The generalising controllers ship with the paper-protocol ones beside them.
    for robot in ("4ws-5", "hexapod"):
        assert paper_arbitrator(robot).name == f"{robot}-paper.arbitrator.json"
    assert shipped_arbitrator("4ws-3", paper=True) == ""  # none ships


def test_a_paper_arbitrator_without_a_shipped_controller_is_refused_in_one_line():
    robot = dataclasses.replace(registry.lookup("4ws-3"), name="half", paper_arbitrator="p.json")
    with pytest.raises(RobotError) as info:
        Registry().register(robot)
    assert str(info.value) == (
        "robot half: paper_arbitrator needs a shipped controller (shipped_repertoire and "
        "shipped_arbitrator)"
    )


def evaluate(capsys, tmp_path, *argv):
    out = tmp_path / "report.json"
    argv = ["evaluate", "--mazes", "gaps", "--starts", "1", "--out", str(out), *argv]
    code = evolve(argv)
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return code, (json.loads(out.read_text()) if code == 0 else err.strip().splitlines())


def test_evaluate_paper_runs_the_paper_protocol_controller(mine, capsys, tmp_path):
    code, report = evaluate(capsys, tmp_path, "--robot", "4ws-5", "--paper")
    assert code == 0, report
    assert report["arbitrator"] == str(mine["paper"])
    assert report["overall"]["episodes"] == 1
    code, report = evaluate(capsys, tmp_path, "--robot", "4ws-5")
    assert code == 0 and report["arbitrator"] == str(mine["default"])
    code, err = evaluate(capsys, tmp_path, "--paper", "--arbitrator", str(mine["default"]))
    assert code == 1 and err == [f"evorbc-evolve: error: {BOTH}"]


def test_evorbc_sim_and_the_launch_file_run_the_paper_protocol_controller(mine, capsys):
    def arbitrator(graph):
        return graph.node("arbitrator").parameters["arbitrator"]

    controller, _, _ = bringup.prepare(bringup.parse_args(["--robot", "4ws-5", "--paper"]))
    assert controller.arbitrator_path == str(mine["paper"])
    controller, _, _ = bringup.prepare(bringup.parse_args(["--robot", "4ws-5"]))
    assert controller.arbitrator_path == str(mine["default"])
    assert bringup.main(["--paper", "--arbitrator", str(mine["paper"])]) == 2
    assert capsys.readouterr().err.strip().splitlines() == [f"evorbc-sim: error: {BOTH}"]

    assert arbitrator(sim_graph(robot="4ws-5", paper=True)) == str(mine["paper"])
    graph = graph_from_arguments({"robot": "4ws-5", "paper": "True"})
    assert arbitrator(graph) == str(mine["paper"])
    assert graph.node("laser_sensor").parameters["sensor_layout"] == str(mine["paper"])
    assert arbitrator(graph_from_arguments({"robot": "4ws-5"})) == str(mine["default"])
    for values, message in [
        ({"paper": "yes"}, "argument paper must be true or false, got 'yes'"),
        (
            {"paper": "true", "arbitrator": "a.json"},
            "argument paper cannot be combined with arbitrator: paper picks the "
            "paper-protocol controller shipped for robot",
        ),
    ]:
        with pytest.raises(ConfigError) as info:
            graph_from_arguments(values)
        assert str(info.value) == message


def test_sensor_nodes_without_a_layout_read_the_shipped_default_controllers(mine):
    """Started by hand with no parameters, the sensor nodes feed the arbitrator's default
    controller: its layout (8 goal sectors here), not the paper's 4."""
    from evorbc_ros.nodes.common import load_sensor_layout

    layout = load_sensor_layout("")
    assert layout == ArbitratorFile.load(mine["default"]).sensors
    assert len(layout.goal_sectors.centres) == 8


def test_replay_refuses_a_network_for_another_layout(tmp_path):
    """An 8-sector controller replayed in a task of the paper's 4-sector layout: refused,
    where the episodes used to run on inputs that were not there."""
    from offline_evolution.maze_task.replay import replay
    from offline_evolution.maze_task.task import MazeTask, MazeTaskSettings

    eight_sectors(tmp_path / "a.json")
    arb = ArbitratorFile.load(tmp_path / "a.json")
    task = MazeTask(MazeTaskSettings(("gaps",), 1.0), "4ws-5")
    with pytest.raises(ValueError) as info:
        replay(arb, task, task.nominal_starts(), Repertoire.load(default_repertoire("4ws-5")))
    assert str(info.value) == (
        "the arbitrator's network takes 14 inputs, the task's sensor layout gives 10: make "
        "the task with the arbitrator's sensors"
    )
