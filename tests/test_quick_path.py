"""``evorbc-evolve from-robot``: a URDF or a robot settings file to a controller at a
profile's budgets (docs/your-robot.md, "The quick path"), here at the small budget.

The A1 from pybullet_data's URDF goes through every step (robot-from-urdf, design-gait,
repertoire, arbitrator); the Husky-like settings-file robot through its repertoire and
arbitrator; a rerun resumes; bad input is refused in one line.
"""

import json
import os
from pathlib import Path

import pytest

from evorbc_ros.robots import registry
from evorbc_ros.robots.settings_robots import PATH_VARIABLE
from offline_evolution.cli import main
from offline_evolution.gait_design.maze_needs import fitted_episode_time
from offline_evolution.recipes.digest import content_sha256
from offline_evolution.recipes.profiles import write_profile_recipe
from offline_evolution.recipes.spec import load_recipe

HUSKY = Path(__file__).parent / "robots" / "husky" / "husky.yaml"


@pytest.fixture(autouse=True)
def _robot_path(monkeypatch):
    """The runner puts the recipe's robot folders on the path; undo it after each test."""
    monkeypatch.setenv(PATH_VARIABLE, os.environ.get(PATH_VARIABLE, ""))
    yield
    registry.reset()


def run(capsys, *argv) -> tuple[int, str, str]:
    code = main(["from-robot", *argv, "--budget", "small", "--quiet", "--workers", "1"])
    out, err = capsys.readouterr()
    return code, out, err


def test_the_a1_urdf_to_a_controller(tmp_path, capsys):
    code, out, err = run(capsys, "pybullet_data:a1/a1.urdf", "--out", str(tmp_path))
    assert code == 0, err
    assert "a1-urdf at the quick profile: 4 steps done" in out
    assert "not beside this file" not in err  # its robot file names config:NAME
    for head in ("[1/4] urdf", "[2/4] design", "[3/4] repertoire", "[4/4] arbitrator"):
        assert f"{head} " in err and "running" in err
    controller = json.loads((tmp_path / "a1-urdf.arbitrator.json").read_text())
    assert controller["robot"] == "a1-urdf"
    assert "design_search" in (tmp_path / "a1-urdf-designed.yaml").read_text()
    declared = (tmp_path / "robots" / "a1-urdf.yaml").read_text()
    assert "episode_time: " in declared and "# s, " in declared  # fitted, and says how
    rep = json.loads((tmp_path / "a1-urdf.repertoire.json").read_text())
    assert rep["robot"] == "a1-urdf"
    # Each stage's time is recorded (bench/bench_profiles.py reports it).
    times = json.loads((tmp_path / "recipe-times.json").read_text())
    assert list(times) == ["urdf", "design", "repertoire", "arbitrator"]
    assert all(t["runs"] == 1 and t["wall_s"] > 0 and t["cpu_s"] > 0 for t in times.values())
    # A rerun finds every step done, and times none.
    code, _, err = run(capsys, "pybullet_data:a1/a1.urdf", "--out", str(tmp_path))
    assert code == 0 and err.count("done before, skipped") == 4
    assert json.loads((tmp_path / "recipe-times.json").read_text()) == times


def test_a_settings_file_robot_resumes_an_interrupted_step(tmp_path, capsys):
    code, out, err = run(capsys, str(HUSKY), "--out", str(tmp_path))
    assert code == 0, err
    assert "husky at the quick profile: 2 steps done" in out
    # Its own maze is scaled to size the generated mazes it trains on: said once.
    assert err.count("generated mazes: maze gaps scaled x5.342 to fit robot husky") == 1
    first = content_sha256(tmp_path / "husky.arbitrator.json")
    # Interrupted: the arbitrator's output gone, as before it was written; the rerun skips
    # the repertoire and runs the arbitrator again, to the same controller.
    (tmp_path / "husky.arbitrator.json").unlink()
    code, out, err = run(capsys, str(HUSKY), "--out", str(tmp_path))
    assert code == 0, err
    assert "repertoire (repertoire)" in err and "done before, skipped" in err
    assert content_sha256(tmp_path / "husky.arbitrator.json") == first  # seeded


def test_the_profiles_budgets_reach_the_recipe(tmp_path):
    path = write_profile_recipe(str(HUSKY), "quick", tmp_path, 3)
    recipe = load_recipe(path)
    assert [s.run for s in recipe.steps] == ["repertoire", "arbitrator"]
    assert recipe.steps[0].seed == recipe.steps[1].seed == 3
    task = (tmp_path / "profile" / "task.yaml").read_text()
    assert "generated: 2" in task  # the generalisation recipe's training
    path = write_profile_recipe("pybullet_data:a1/a1.urdf", "quick", tmp_path, 1)
    rep = load_recipe(path).step("repertoire")
    assert (rep.archive, rep.variation, rep.initial_batch, rep.iterations) == (
        "cvt",
        "iso_line_dd",
        6000,
        30,
    )


def test_a_urdf_robots_episode_is_as_long_as_its_designed_gait_needs(tmp_path):
    # The Laikago's quick design: random gaits' p90 0.103 m/s, a 9.47 m maze path asked
    # 0.47 m/s of a 30 s episode; 2 x 0.103 m/s covers it in 2/3 of 69 s.
    laikago = {"maze": {"episode_time": 30.0, "path": 9.4699}, "measures": {"speed": 0.1028}}
    seconds, why = fitted_episode_time(laikago)
    assert seconds == 70.0 and "9.47 m of maze path at 0.21 m/s" in why
    fast = {"maze": {"episode_time": 30.0, "path": 8.67}, "measures": {"speed": 0.33}}
    assert fitted_episode_time(fast)[0] == 30.0  # its gait covers its mazes: unchanged
    assert fitted_episode_time(None) == (30.0, "the A1's")
    # The profile's arbitrator step takes the robot's episode time for a URDF robot only.
    path = write_profile_recipe("pybullet_data:a1/a1.urdf", "quick", tmp_path, 1)
    assert load_recipe(path).step("arbitrator").robot_episode_time
    path = write_profile_recipe(str(HUSKY), "quick", tmp_path, 1)
    assert not load_recipe(path).step("arbitrator").robot_episode_time


@pytest.mark.parametrize(
    "source, words",
    [
        ("no/such/robot.urdf", "no such URDF file"),
        ("robot.txt", "expected a URDF (.urdf or pybullet_data:PATH) or a robot settings"),
    ],
)
def test_bad_input_is_refused_in_one_line(tmp_path, capsys, source, words):
    code, _, err = run(capsys, source, "--out", str(tmp_path / "o"))
    assert code != 0
    assert words in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_a_urdfs_standing_options_reach_its_step(tmp_path):
    standing = {"up": "y", "turn": (90.0, 0.0, 0.0), "stance": 0.55}
    path = write_profile_recipe(
        "pybullet_data:laikago/laikago_toes.urdf", "quick", tmp_path, 1, None, standing
    )
    step = load_recipe(path).step("urdf")
    assert (step.up, step.turn, step.stance) == ("y", (90.0, 0.0, 0.0), 0.55)


def test_a_y_up_urdf_stands_with_up_given(tmp_path, capsys):
    """The A1 turned Y-up: refused without --up, naming it; its step stands it with it."""
    import numpy as np
    import pybullet_data

    from offline_evolution.recipes.robot_steps import run_robot_from_urdf
    from sim_bridge.legged.urdf_model import read_urdf, turned_urdf_text

    yup = tmp_path / "a1_yup.urdf"
    to_yup = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]).T
    a1 = read_urdf(Path(pybullet_data.getDataPath()) / "a1" / "a1.urdf")
    yup.write_text(turned_urdf_text(a1, to_yup, "A1, Y-up"))
    code, _, err = run(capsys, str(yup), "--out", str(tmp_path / "a"))
    assert code != 0 and "is Y-up" in err and "pass --up y" in err and "Traceback" not in err
    path = write_profile_recipe(str(yup), "quick", tmp_path, 1, "dog", {"up": "y"})
    lines: list[str] = []
    run_robot_from_urdf(load_recipe(path).step("urdf"), tmp_path, lines.append)
    assert "up y" in lines[0] and (tmp_path / "dog.urdf").is_file()
    assert any("it stands" in line for line in lines)


def test_standing_options_are_refused_for_a_settings_file(tmp_path, capsys):
    code, _, err = run(capsys, str(HUSKY), "--out", str(tmp_path), "--up", "y")
    assert code != 0 and "--up: only for a URDF" in err and "Traceback" not in err
