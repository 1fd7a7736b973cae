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
    for head in ("[1/4] urdf", "[2/4] design", "[3/4] repertoire", "[4/4] arbitrator"):
        assert f"{head} " in err and "running" in err
    controller = json.loads((tmp_path / "a1-urdf.arbitrator.json").read_text())
    assert controller["robot"] == "a1-urdf"
    assert "design_search" in (tmp_path / "a1-urdf-designed.yaml").read_text()
    rep = json.loads((tmp_path / "a1-urdf.repertoire.json").read_text())
    assert rep["robot"] == "a1-urdf"
    # A rerun finds every step done.
    code, _, err = run(capsys, "pybullet_data:a1/a1.urdf", "--out", str(tmp_path))
    assert code == 0 and err.count("done before, skipped") == 4


def test_a_settings_file_robot_resumes_an_interrupted_step(tmp_path, capsys):
    code, out, err = run(capsys, str(HUSKY), "--out", str(tmp_path))
    assert code == 0, err
    assert "husky at the quick profile: 2 steps done" in out
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
