"""The 4WS geometry and limits come from a settings file (docs/design.md section 19).

``config/robots/4ws.yaml`` holds the paper's body; it must give the values that were
written in the code before, bit for bit, so every existing result stays as it was. A 4WS
robot of other dimensions is a settings file with ``kind: four_ws``, and it must really
move differently.
"""

import math
import textwrap

import numpy as np
import pytest

from evorbc_ros.config import ConfigError, config_dir
from evorbc_ros.robots import registry
from evorbc_ros.robots.four_ws import FourWSGeometry, paper_geometry
from evorbc_ros.robots.settings_robots import PATH_VARIABLE, read_robot_file

#: The values the code held before they moved to config/robots/4ws.yaml.
PAPER = {
    "wheel_x": 0.025,
    "wheel_y": 0.025,
    "footprint_radius": 0.05,
    "max_wheel_angle": math.radians(45.0),
    "max_wheel_rate": math.radians(90.0),
    "max_speed": 0.20,
    "max_acceleration": 0.40,
    "control_period": 0.1,
    "max_slip": math.radians(10.0),
    "parallel_tolerance": math.radians(1.0),
    "wheel_radius": 0.02,
}


def test_the_shipped_file_gives_the_paper_values_bit_for_bit():
    loaded = FourWSGeometry.load(config_dir() / "robots" / "4ws.yaml")
    for key, value in PAPER.items():
        assert getattr(loaded, key) == value, key  # exact, not approximately
    assert loaded == paper_geometry() == FourWSGeometry()
    for name in ("2ws-2", "2ws-3", "4ws-3", "4ws-5"):
        robot = registry.lookup(name)
        assert robot.model.body() == loaded
        assert robot.footprint_radius == PAPER["footprint_radius"]
        assert robot.max_speed == PAPER["max_speed"]
        assert robot.node_default("wheel_radius", None) == PAPER["wheel_radius"]


def write(folder, name, text):
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text(textwrap.dedent(text))
    return path


@pytest.fixture
def user_robots(tmp_path, monkeypatch):
    """A folder of the user's robot settings files on $EVORBC_ROBOT_PATH."""
    folder = tmp_path / "robots"
    folder.mkdir()
    monkeypatch.setenv(PATH_VARIABLE, str(folder))
    registry.reset()
    yield folder
    registry.reset()


def big_4ws(folder, **geometry):
    lines = "\n".join(f"  {k}: {v}" for k, v in geometry.items())
    return write(folder, "big-4ws.yaml", f"kind: four_ws\ntype: 4ws-5\ngeometry:\n{lines}\n")


def test_a_4ws_robot_of_other_dimensions_moves_differently(user_robots):
    from sim_bridge.robots import make_robot

    # Twice the top speed and acceleration, wheels twice as far out, bigger wheels.
    big_4ws(
        user_robots,
        max_speed=0.4,
        max_acceleration=0.8,
        wheel_x=0.05,
        wheel_y=0.05,
        footprint_radius=0.1,
        wheel_radius=0.04,
    )
    big = registry.lookup("big-4ws")
    assert big.model.body().max_speed == 0.4 and big.max_speed == 0.4
    assert big.footprint_radius == 0.1
    # Keys the file does not give keep the paper's values.
    assert big.model.body().max_wheel_angle == PAPER["max_wheel_angle"]
    assert big.parameters[0].high == 0.4 and big.parameters[1].high == PAPER["max_wheel_angle"]
    # The executor and the bridge turn its speed into wheel velocities with its radius.
    assert big.node_default("wheel_radius", None) == 0.04

    paper, mine = make_robot("4ws-5"), make_robot("big-4ws")
    assert mine.describe()["geometry"]["wheel_x"] == 0.05 and paper.describe() is None
    straight = np.array([[1.0, 0.0, 0.0, 0.0, 0.0]])
    a = paper.evaluate_primitives(straight, 2.0)
    b = mine.evaluate_primitives(straight, 2.0)
    # Full speed ahead: twice the speed and acceleration, exactly twice the displacement.
    assert b.x[0] == pytest.approx(2.0 * a.x[0], rel=1e-12) and a.x[0] > 0.3
    # The same steering on a body twice as long: half the curvature, so half the turn.
    turn = np.array([[0.5, 0.3, 0.3, -0.3, -0.3]])
    a = paper.evaluate_primitives(turn, 2.0)
    b = mine.evaluate_primitives(turn, 2.0)
    assert abs(a.heading[0]) > 0.1
    assert b.heading[0] == pytest.approx(a.heading[0], rel=1e-9)  # twice the speed, half ...
    np.testing.assert_allclose([b.x[0], b.y[0]], [2 * a.x[0], 2 * a.y[0]], rtol=1e-9)


def test_its_repertoire_records_its_body_and_the_paper_robots_record_none(user_robots):
    from offline_evolution.repertoire.map_elites import generate_repertoire
    from offline_evolution.repertoire.settings import load_settings

    big_4ws(user_robots, max_speed=0.3)
    tiny = {"initial_batch": 50, "batch_size": 10, "iterations": 1, "seed": 1}
    mine = generate_repertoire(load_settings(robot="big-4ws", **tiny))
    assert mine.algorithm["simulation"]["geometry"]["max_speed"] == 0.3
    paper = generate_repertoire(load_settings(robot="4ws-5", **tiny))
    assert "simulation" not in paper.algorithm  # files of the paper's robots are unchanged

    # The same robot's file edited afterwards: its old repertoire is refused for the task.
    from evorbc_ros.repertoire import RepertoireError
    from offline_evolution.maze_task.task import MazeTask, MazeTaskSettings
    from sim_bridge.robots.design import check_simulation

    big_4ws(user_robots, max_speed=0.35)
    registry.reset()
    task = MazeTask(MazeTaskSettings(("gaps",), 15.0), "big-4ws")
    with pytest.raises(RepertoireError, match=r"evolved for a different robot .*max_speed"):
        check_simulation(mine, task.describe())


HEAD = "kind: four_ws\ntype: 4ws-5\n"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            HEAD + "geometry: {wheel_xx: 0.1}\n",
            "geometry: unknown setting 'wheel_xx' (did you mean 'wheel_x'?)",
        ),
        (HEAD + "geometry: {max_speed: -1}\n", "geometry: max_speed must be >= 1e-06, got -1.0"),
        (
            HEAD + "geometry: {max_speed: fast}\n",
            "geometry: max_speed must be a number, got 'fast'",
        ),
        (
            HEAD + "geometry: {wheel_x: 0.2}\n",
            "geometry: footprint_radius 0.05 m must hold the wheels at (0.2, 0.025) m",
        ),
        ("kind: four_ws\ntype: 6ws\n", "type must be one of 2ws-2, 2ws-3, 4ws-3, 4ws-5"),
        (
            "kind: four_wheels\n",
            "kind must be one of four_ws, diff_drive, legged; got 'four_wheels'",
        ),
    ],
)
def test_a_bad_4ws_file_is_one_line_naming_file_and_key(user_robots, text, message):
    path = write(user_robots, "bad.yaml", text)
    with pytest.raises(ConfigError) as info:
        read_robot_file(path)
    assert str(info.value).startswith(f"{path}: {message}")
    assert "\n" not in str(info.value)


def test_the_paper_file_needs_every_key(tmp_path):
    path = write(tmp_path, "4ws.yaml", "wheel_x: 0.025\n")
    with pytest.raises(ConfigError, match=r"4ws.yaml: missing setting 'wheel_y'$"):
        FourWSGeometry.load(path)
