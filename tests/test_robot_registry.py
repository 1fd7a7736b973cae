"""The robot registry: every robot declared once, looked up by name, plugins found lazily."""

import dataclasses
import subprocess
import sys

import pytest

from evorbc_ros.config import ConfigError, config_dir
from evorbc_ros.robots import registry
from evorbc_ros.robots.registry import Registry, RobotError, UnknownRobot

BUILTIN = ("2ws-2", "2ws-3", "4ws-3", "4ws-5", "hexapod", "a1")
#: Robots declared in config/robots/ settings files (after the built-in ones).
FROM_FILES = ("turtlebot3-burger",)
KNOWN = "known robots: 2ws-2, 2ws-3, 4ws-3, 4ws-5, hexapod, a1, turtlebot3-burger"


def test_the_builtin_robots_are_each_declared_once_and_completely():
    from evorbc_ros.defaults import default_arbitrator, default_repertoire
    from offline_evolution.arbitrator.settings import load_run_settings
    from offline_evolution.maze_task.task import MazeTaskSettings
    from offline_evolution.repertoire.settings import load_settings

    assert registry.names() == BUILTIN + FROM_FILES
    for name in BUILTIN + FROM_FILES:
        robot = registry.lookup(name)
        assert load_settings(robot=name).robot == name
        run = load_run_settings(robot=name)
        # The run settings name the robot's own NEAT and task files.
        assert run.neat_path() == robot.settings_file("neat")
        assert run.task_path() == robot.settings_file("task")
        task = MazeTaskSettings.load(robot.settings_file("task"))
        assert task.episode_time == robot.episode_time and robot.maze in task.mazes
        assert robot.sensors_file() == config_dir() / task.sensors
        if robot.shipped_arbitrator:
            assert default_arbitrator(name).is_file() and default_repertoire(name).is_file()
    equal = {n: registry.lookup(n).equal_budget_generations for n in BUILTIN + FROM_FILES}
    assert equal == {
        "2ws-2": 25,
        "2ws-3": 25,
        "4ws-3": 25,
        "4ws-5": 25,
        "hexapod": 455,
        "a1": 455,
        "turtlebot3-burger": 25,
    }
    assert [r.name for r in registry.robots() if r.shipped_arbitrator] == ["4ws-5", "hexapod", "a1"]


def test_a_4ws_registration_matches_its_simulated_robot():
    from sim_bridge.robots import make_robot

    for name in BUILTIN[:4]:
        robot, simulated = registry.lookup(name), make_robot(name)
        assert robot.parameters == simulated.parameter_specs
        assert robot.max_speed * 2.0 == simulated.max_reach(2.0)


def test_an_unknown_robot_is_refused_in_one_line_listing_the_known_ones():
    from offline_evolution.arbitrator.settings import load_run_settings
    from offline_evolution.maze_task.task import MazeTaskSettings, make_task
    from offline_evolution.repertoire.settings import default_settings_file
    from sim_bridge.robots import make_robot

    settings = MazeTaskSettings(("gaps",), 15.0)
    # Before the registry, an unknown name silently got the 4WS settings files.
    for call in (
        lambda: registry.lookup("tank"),
        lambda: default_settings_file("tank"),
        lambda: load_run_settings(robot="tank"),
        lambda: make_robot("tank"),
        lambda: make_task(settings, "tank"),
    ):
        with pytest.raises(UnknownRobot) as info:
            call()
        assert str(info.value) == f"unknown robot 'tank'; {KNOWN}"
    assert isinstance(info.value, KeyError) and isinstance(info.value, ConfigError)


def test_an_unknown_robot_in_a_settings_file_is_named_with_its_key(tmp_path):
    from offline_evolution.repertoire.settings import load_settings

    text = (config_dir() / "repertoire" / "4ws.yaml").read_text()
    path = tmp_path / "r.yaml"
    path.write_text(text.replace("robot: 4ws-5", "robot: tank"))
    with pytest.raises(ConfigError) as info:
        load_settings(path)
    assert str(info.value) == (
        f"{path}: robot must be one of 2ws-2, 2ws-3, 4ws-3, 4ws-5, hexapod, a1, turtlebot3-burger; "
        "got 'tank'"
    )


def test_a_factory_that_cannot_be_imported_is_one_line():
    from sim_bridge.robots import adapters

    # A record declared the deprecated way names its factory itself.
    robot = dataclasses.replace(registry.lookup("4ws-5"), simulation="nosuch.module:make")
    with pytest.raises(RobotError) as info:
        adapters.make_simulation(robot)
    assert str(info.value) == (
        "robot 4ws-5: its simulation 'nosuch.module:make' cannot be loaded "
        "(ModuleNotFoundError: No module named 'nosuch')"
    )
    # A family's adapters registered with a path that does not import.
    try:
        adapters.TABLE.register("tracked", adapters.SimAdapters("nosuch.module:make", "nosuch:B"))
        tank = dataclasses.replace(registry.lookup("4ws-5"), name="tank", family="tracked")
        with pytest.raises(RobotError, match=r"^robot tank: its bridge 'nosuch:B' cannot be"):
            adapters.bridge_class(tank)
    finally:
        adapters.TABLE.reset()


class FakeEntryPoint:
    """What importlib.metadata gives: a name, a value and load()."""

    def __init__(self, name, loaded, dist=None):
        self.name, self.value, self.dist = name, f"fake_{name}:robots", dist
        self.loaded = loaded

    def load(self):
        if isinstance(self.loaded, Exception):
            raise self.loaded
        return self.loaded


def variant(name, **changes):
    return dataclasses.replace(registry.lookup("4ws-5"), name=name, **changes)


def fake_registry(monkeypatch, points):
    import importlib.metadata

    calls = []

    def entry_points(group):
        calls.append(group)
        return points

    monkeypatch.setattr(importlib.metadata, "entry_points", entry_points)
    reported = []
    return Registry(report=reported.append), calls, reported


def test_plugins_are_looked_for_only_when_a_name_is_not_built_in(monkeypatch):
    reg, calls, _ = fake_registry(monkeypatch, [FakeEntryPoint("one", variant("one"))])
    assert reg.lookup("hexapod").name == "hexapod" and reg.known("4ws-5")
    assert calls == []  # built-in names never scan the installed packages
    assert reg.lookup("one").name == "one"
    assert calls == ["evorbc.robots"]
    # scanned once
    assert reg.names() == (*BUILTIN, *FROM_FILES, "one") and calls == ["evorbc.robots"]


def test_every_kind_of_plugin_and_every_broken_one(monkeypatch):
    class Dist:
        name, version = "evorbc-zoo", "1.2"

    points = [
        FakeEntryPoint("single", variant("single")),
        FakeEntryPoint("several", lambda: [variant("left"), variant("right")], Dist()),
        FakeEntryPoint("crashes", ImportError("No module named 'numpyy'")),
        FakeEntryPoint("number", 5),
        FakeEntryPoint("clash", variant("hexapod")),
        FakeEntryPoint("invalid", variant("bad", task="not a path")),
        FakeEntryPoint("half", lambda: (variant("fine"), variant("bad name"))),
    ]
    reg, _, reported = fake_registry(monkeypatch, points)
    # Entry points are read in name order, so the listing does not depend on install order.
    assert reg.names() == (*BUILTIN, *FROM_FILES, "fine", "left", "right", "single")
    assert reported == reg.problems
    assert reported == [
        "robot plugin clash (fake_clash:robots): robot hexapod is already registered; left out",
        "robot plugin crashes (fake_crashes:robots) cannot be loaded (ImportError: No module "
        "named 'numpyy'); its robots are left out",
        "robot plugin half (fake_half:robots): name 'bad name' must be letters, digits and "
        ". _ + - (starting with a letter or digit); left out",
        "robot plugin invalid (fake_invalid:robots): robot bad: task must be an import path "
        "'package.module:attribute'; left out",
        "robot plugin number (fake_number:robots) cannot be loaded (TypeError: gave a int, "
        "expected a Robot or a callable returning robots); its robots are left out",
    ]
    with pytest.raises(UnknownRobot) as info:
        reg.lookup("crashes")
    assert str(info.value).endswith("single (5 robot plugin(s) failed to load)")
    assert reg.lookup("left").parameters == reg.lookup("4ws-5").parameters


def test_a_script_can_register_its_own_robot_once(monkeypatch):
    reg, _, _ = fake_registry(monkeypatch, [])
    reg.register(variant("mine"))
    assert reg.lookup("mine").name == "mine"
    with pytest.raises(RobotError, match="robot mine is already registered"):
        reg.register(variant("mine"))


def test_looking_up_a_robot_onboard_loads_no_simulation_or_search_code():
    code = (
        "import sys\n"
        "from evorbc_ros.robots import registry\n"
        "from evorbc_ros.repertoire import Repertoire\n"
        "from evorbc_ros.defaults import default_repertoire\n"
        "Repertoire.load(default_repertoire('hexapod'))\n"
        "print(registry.names(), registry.lookup('hexapod').footprint_radius > 0)\n"
        "heavy = ('sim_bridge', 'offline_evolution', 'numba', 'pybullet', 'rclpy', 'ribs')\n"
        "print(sorted({m.split('.')[0] for m in sys.modules} & set(heavy)))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.splitlines()[1:] == ["[]"]


def test_the_names_are_live_choices():
    assert "hexapod" in registry.ROBOT_NAMES and "tank" not in registry.ROBOT_NAMES
    assert 5 not in registry.ROBOT_NAMES
    assert list(registry.ROBOT_NAMES) == [*BUILTIN, *FROM_FILES]
    assert len(registry.ROBOT_NAMES) == 7
