"""Each layer's adapters for a robot, by family: built in, from plugins, the deprecated form.

docs/design.md section 19, docs/your-robot.md. The onboard record names no simulation or
search code; ``sim_bridge`` and ``offline_evolution`` find theirs by the record's family.
"""

import dataclasses
import sys

import numpy as np
import pytest
from plugin_helpers import build_tracks

from evorbc_ros.robots import registry
from evorbc_ros.robots.adapters import AdapterTable
from evorbc_ros.robots.record import LEGACY_NOTICE, RobotError, load_path
from offline_evolution.maze_task import adapters as search
from sim_bridge.robots import adapters as sim
from sim_bridge.robots import make_robot

FAMILIES = {
    "2ws-2": "four_ws",
    "2ws-3": "four_ws",
    "4ws-3": "four_ws",
    "4ws-5": "four_ws",
    "hexapod": "hexapod",
    "a1": "legged",
    "turtlebot3-burger": "diff_drive",
}


def test_every_shipped_robot_has_a_family_whose_adapters_import():
    assert {n: registry.lookup(n).family for n in registry.names()} == FAMILIES
    for name in registry.names():
        robot = registry.lookup(name)
        assert robot.legacy_factories == {}  # no shipped robot names a higher layer
        found = sim.TABLE.adapters(robot)
        paths = [found.simulation, found.bridge, search.TABLE.adapters(robot).task]
        paths += [found.design_check] if found.design_check else []
        for path in paths:
            assert load_path(path, name) is not None
    # Only the robots simulated in PyBullet check a controller's design.
    checked = [n for n in registry.names() if sim.TABLE.adapters(registry.lookup(n)).design_check]
    assert checked == ["hexapod", "a1"]


@pytest.fixture
def tracks(tmp_path, monkeypatch):
    """evorbc-tracks installed and on ``sys.path``; every table forgotten afterwards."""
    site = build_tracks(tmp_path)
    monkeypatch.syspath_prepend(str(site))
    registry.reset()
    sim.TABLE.reset()
    search.TABLE.reset()
    yield site
    registry.reset()
    sim.TABLE.reset()
    search.TABLE.reset()
    for name in [m for m in sys.modules if m.split(".")[0] == "evorbc_tracks"]:
        del sys.modules[name]


def test_a_plugin_declares_its_record_and_each_layers_adapters_in_their_own_groups(tracks, capsys):
    from offline_evolution.maze_task.task import MazeTaskSettings, make_task
    from sim_bridge.bridge_robots import bridge_robot_class
    from sim_bridge.four_ws.bridge import FourWSBridge

    robot = registry.lookup("tracks")
    assert robot.family == "tracked" and robot.legacy_factories == {}
    genes = np.random.default_rng(5).uniform(-1, 1, (50, 5))
    want = make_robot("4ws-5").evaluate_primitives(genes, 2.0)
    for name in ("tracks", "oldtracks"):
        got = make_robot(name).evaluate_primitives(genes, 2.0)
        np.testing.assert_array_equal(got.x, want.x)
        np.testing.assert_array_equal(got.heading, want.heading)
        assert bridge_robot_class(name) is FourWSBridge
        task = make_task(MazeTaskSettings(("gaps",), 15.0), name)
        assert task.robot.name == name
        task.close()
    # The old form still works, and says once what replaces it.
    assert registry.lookup("oldtracks").legacy_factories["bridge"].endswith(":FourWSBridge")
    assert capsys.readouterr().err.splitlines() == [
        f"evorbc: warning: robot oldtracks: {LEGACY_NOTICE}"
    ]
    assert registry.plugin_problems() == sim.TABLE.problems == search.TABLE.problems == []


class FakeEntryPoint:
    def __init__(self, name, loaded):
        self.name, self.value, self.dist, self.loaded = name, f"fake_{name}:A", None, loaded

    def load(self):
        if isinstance(self.loaded, Exception):
            raise self.loaded
        return self.loaded


def test_a_family_without_adapters_or_with_a_broken_plugin_is_one_line(monkeypatch):
    import importlib.metadata

    points = [
        FakeEntryPoint("crashes", ImportError("No module named 'pybulet'")),
        FakeEntryPoint("other", 5),
    ]
    monkeypatch.setattr(importlib.metadata, "entry_points", lambda group: points)
    reported = []
    table = AdapterTable(sim.SimAdapters, sim.GROUP, sim.BUILTIN, report=reported.append)
    tank = dataclasses.replace(registry.lookup("4ws-5"), name="tank", family="crashes")
    with pytest.raises(RobotError) as info:
        table.adapters(tank)
    assert str(info.value) == (
        "robot tank: no adapters for its family 'crashes' in evorbc.sim_adapters "
        "(docs/your-robot.md)"
    )
    assert (
        reported
        == table.problems
        == [
            "evorbc.sim_adapters plugin crashes (fake_crashes:A) cannot be loaded (ImportError: "
            "No module named 'pybulet'); left out",
            "evorbc.sim_adapters plugin other (fake_other:A) cannot be loaded (TypeError: 'int' "
            "object is not callable); left out",
        ]
    )
    # A built-in family is the layer's own object.
    assert table.adapters(registry.lookup("hexapod")) is sim.BUILTIN["hexapod"]
