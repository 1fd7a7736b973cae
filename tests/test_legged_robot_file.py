"""A legged robot declared in a settings file only (``kind: legged``, docs/legged.md): no
Python, no package. The A1's own settings under another name walk exactly as the A1."""

import textwrap

import numpy as np
import pytest

from evorbc_ros.config import ConfigError, config_dir
from evorbc_ros.robots import registry
from evorbc_ros.robots.settings_robots import PATH_VARIABLE, read_robot_file
from sim_bridge.robots import make_robot

DECLARATION = """\
    kind: legged
    model: mydog-model.yaml
    description: my quadruped
    settings:
      repertoire: repertoire/a1.yaml
      arbitrator: arbitrator/a1.yaml
      neat: neat/a1.ini
      task: tasks/maze-a1.yaml
    sensors: sensors/a1.yaml
    maze: a1
    episode_time: 30.0
"""


@pytest.fixture
def user_robots(tmp_path, monkeypatch):
    """mydog.yaml (the declaration) and mydog-model.yaml (the A1's settings, renamed) in a
    folder on $EVORBC_ROBOT_PATH."""
    model = (config_dir() / "robots" / "a1.yaml").read_text().replace("name: a1", "name: mydog")
    (tmp_path / "mydog-model.yaml").write_text(model)
    (tmp_path / "mydog.yaml").write_text(textwrap.dedent(DECLARATION))
    monkeypatch.setenv(PATH_VARIABLE, str(tmp_path))
    registry.reset()
    yield tmp_path
    registry.reset()


def test_a_legged_robot_file_registers_a_robot_that_walks_as_its_model(user_robots):
    robot = registry.lookup("mydog")
    a1 = registry.lookup("a1")
    assert robot.description == "my quadruped" and robot.maze == "a1"
    assert robot.parameter_names == a1.parameter_names  # the A1's 25 genes
    assert robot.commands == a1.commands and robot.family == a1.family == "legged"
    genes = np.random.default_rng(3).uniform(-1, 1, (3, a1.n_parameters))
    mine, theirs = make_robot("mydog", workers=1), make_robot("a1", workers=1)
    try:
        got = mine.evaluate_primitives(genes, 1.0)
        want = theirs.evaluate_primitives(genes, 1.0)
    finally:
        mine.close()
        theirs.close()
    for key in ("x", "y", "heading", "path", "max_tilt"):
        np.testing.assert_array_equal(getattr(got, key), getattr(want, key))
    assert np.abs(got.x).max() > 0.01  # it moved


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            ("model: mydog-model.yaml", "model: nothere.yaml"),
            r"model: no such file \S*/nothere.yaml \(relative",
        ),
        (("model: mydog-model.yaml\n", ""), "model: expected the legged settings file"),
        (("kind: legged", "kind: diff_drive"), "model is for legged robots; remove it"),
        (("kind: legged", "kind: legged\ntype: 4ws-5"), "type and geometry are not for legged"),
    ],
)
def test_a_bad_legged_robot_file_is_one_line_naming_the_file(user_robots, edit, message):
    path = user_robots / "mydog.yaml"
    path.write_text(path.read_text().replace(*edit))
    with pytest.raises(ConfigError, match=message) as err:
        read_robot_file(path)
    assert str(path) in str(err.value) and "\n" not in str(err.value)


def test_the_declared_name_must_be_the_models(user_robots):
    (user_robots / "mydog.yaml").rename(user_robots / "yourdog.yaml")
    with pytest.raises(ConfigError, match=r"named 'yourdog' but its model .* names 'mydog'"):
        read_robot_file(user_robots / "yourdog.yaml")
