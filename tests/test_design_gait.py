"""``evorbc-evolve design-gait``: the gait design search (docs/legged.md, "The gait design
search") on the A1 at a tiny budget.

The search is seeded (an interrupted and resumed search ends where an uninterrupted one
does, every design scored alike), resumes without scoring again what its checkpoint holds,
writes a settings file that loads as the design chosen with its record, and refuses bad
input in one line.
"""

import dataclasses
import json
from pathlib import Path

import pytest
import yaml

from evorbc_ros.config import ConfigError, config_dir
from offline_evolution.checkpoint import Interrupted
from offline_evolution.cli import main
from offline_evolution.gait_design.objective import Budget
from offline_evolution.gait_design.run import design_gait
from offline_evolution.gait_design.space import DesignSpace
from sim_bridge.legged.settings import load_robot_settings, robot_settings_from_mapping

A1 = config_dir() / "robots" / "a1.yaml"
TINY = Budget(gaits=3, accuracy=1, episodes=1, episode_time=0.5, sobol=2, refine=1, validate=1)


def search(out: Path, lines: list, stop_after: int | None = None):
    calls = []

    def should_stop() -> bool:
        calls.append(1)
        return stop_after is not None and len(calls) > stop_after

    return design_gait(A1, out, 5, "tiny", TINY, progress=lines.append, should_stop=should_stop)


@pytest.fixture(scope="module")
def whole(tmp_path_factory):
    out = tmp_path_factory.mktemp("whole") / "a1-designed.yaml"
    lines = []
    return search(out, lines), out, lines


def test_an_interrupted_search_resumes_to_the_same_result(whole, tmp_path):
    result, _, _ = whole
    out = tmp_path / "a1-designed.yaml"
    first = []
    with pytest.raises(Interrupted):
        search(out, first, stop_after=3)
    checkpoint = out.with_name(out.name + ".checkpoint.json")
    saved = json.loads(checkpoint.read_text())
    assert [c["stage"] for c in saved["candidates"]] == ["current", "sobol", "sobol"]
    assert not out.exists()
    again = []
    resumed = search(out, again)
    # The three designs of the checkpoint are read, not scored again; the rest are scored.
    assert sum("from the checkpoint" in line for line in again) == 3
    assert all("from the checkpoint" not in line for line in again[4:])
    assert resumed.chosen == result.chosen
    assert [(c.stage, c.values, c.score) for c in resumed.candidates] == [
        (c.stage, c.values, c.score) for c in result.candidates
    ]
    assert [c.measures.upright for c in resumed.candidates] == [
        c.measures.upright for c in result.candidates
    ]
    assert not checkpoint.exists()  # removed once the settings file is written


def test_the_search_follows_its_stages(whole):
    result, _, lines = whole
    stages = [c.stage for c in result.candidates]
    assert stages[0] == "current" and stages[-2:] == ["validate", "validate"]
    assert stages.count("sobol") <= 2 and stages.count("refine") <= 1
    assert result.chosen in [c.values for c in result.candidates if c.stage == "validate"]
    assert lines[0].startswith("a1: searching servo gain")
    assert f"; {len(result.candidates)} designs scored; wrote " in lines[-1]


def test_the_written_file_loads_as_the_design_chosen(whole):
    result, out, _ = whole
    written = load_robot_settings(out)
    data = yaml.safe_load(A1.read_text())
    space = DesignSpace.of(data, A1)
    assert written.describe() == space.design(result.chosen).describe()
    assert written.servo.gain == result.chosen["gain"]
    assert written.gait.frequency == result.chosen["frequency_hz"]
    assert written.physics.rate == result.chosen["rate_hz"]
    text = out.read_text()
    record = yaml.safe_load(text)["design_search"]
    assert record["seed"] == 5 and record["budget"] == "tiny"
    assert record["candidates_evaluated"] == len(result.candidates)
    assert record["score"] == round(result.chosen_validation.score, 4)
    assert record["replaced"]["servo.gain"] == 10.0
    assert record["replaced"]["ranges_deg"]["FL_knee"] == [-118.0, -88.0]
    for line in text.split("design_search:")[0].splitlines():
        if line.lstrip().startswith(("gain:", "frequency_hz:", "rate_hz:", "FL_swing:")):
            assert "# " in line and "design-gait, seed 5, tiny budget (was " in line


def test_a_record_that_is_not_a_mapping_is_refused(tmp_path):
    data = yaml.safe_load(A1.read_text())
    data["design_search"] = "by hand"
    with pytest.raises(ConfigError, match="design_search: expected a mapping"):
        robot_settings_from_mapping(data, A1)


def refusal(capsys, *argv) -> str:
    try:
        code = main(["design-gait", *argv])
    except SystemExit as e:  # argparse's usage errors
        code = e.code
    _, err = capsys.readouterr()
    assert code != 0
    assert err.count("\n") == 1 and "Traceback" not in err
    return err


def test_bad_input_is_refused_in_one_line(capsys, tmp_path):
    out = str(tmp_path / "new.yaml")
    err = refusal(capsys, str(tmp_path / "none.yaml"), "--out", out)
    assert "none.yaml: no such settings file" in err
    burger = str(config_dir() / "robots" / "turtlebot3-burger.yaml")
    assert "not a legged robot's settings file" in refusal(capsys, burger, "--out", out)
    assert "--out" in refusal(capsys, str(A1), "--out", str(tmp_path))
    assert "--budget" in refusal(capsys, str(A1), "--out", out, "--budget", "huge")
    assert "--seed" in refusal(capsys, str(A1), "--out", out, "--seed", "-1")
    other = tmp_path / "other.json"
    other.write_text("not json")
    err = refusal(capsys, str(A1), "--out", out, "--checkpoint", str(other))
    assert "not a checkpoint" in err and "choose another --checkpoint" in err
    foreign = tmp_path / "foreign.json"
    foreign.write_text(json.dumps({"kind": "design-gait", "version": 1, "seed": 9}))
    err = refusal(capsys, str(A1), "--out", out, "--checkpoint", str(foreign))
    assert "another search's" in err and "--restart" in err


def test_validation_chains_a_trial_repertoire_s_primitives(tmp_path):
    """With ``trial_evaluations`` each validated design grows a small repertoire, and its
    primitives, not random gaits, are chained for the switching measure: the A1's
    repertoire fell where random gaits did not (offline_evolution/gait_design/trial.py)."""
    budget = dataclasses.replace(TINY, trial_evaluations=24, trial_episodes=1)
    lines = []
    result = design_gait(A1, tmp_path / "a1.yaml", 5, "tiny", budget, progress=lines.append)
    for c in result.candidates:
        trial = c.measures.trial_primitives
        assert (trial > 0) == (c.stage == "validate"), (c.stage, trial)
        if trial:
            assert c.measures.trial_reach > 0.0 and c.measures.exposure > 0.0
    validated = [line for line in lines if "(validate)" in line]
    assert validated and all(" among a trial repertoire's " in line for line in validated)
