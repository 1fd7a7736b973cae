"""evorbc-study: study files, the local runner, kill and resume, and a real Ray cluster."""

import json
import os
import shutil
import signal
import subprocess

import pytest
import yaml
from PIL import Image
from study_helpers import (
    first_checkpoint,
    results_contents,
    run_study,
    study_command,
    wait_for,
    write_tiny_study,
)

from evorbc_ros.config import ConfigError
from offline_evolution.study.spec import load_study, parse_study, study_names


def test_the_shipped_studies_state_the_full_protocol():
    assert study_names() == ["bin-time", "hexapod", "mappings", "metrics", "robot-types"]
    robot_types = load_study("robot-types")
    runs = robot_types.runs()
    assert len(runs) == 4 * 2 * 30
    evorbc = [r for r in runs if r.approach == "evorbc"]
    assert all(r.values["generations"] == 1000 for r in runs)
    # Each approach records only what it runs with.
    assert all("equal_budget" not in r.values and r.values["bin_size"] == 0.04 for r in evorbc)
    standard = [r for r in runs if r.approach == "standard"]
    assert all(r.values["equal_budget"] and "metric" not in r.values for r in standard)
    bin_time = load_study("bin-time")
    assert len(bin_time.settings()) == 36 - 7
    assert load_study("hexapod").runs()[0].values["generations"] == 200


def test_a_reduced_protocol_is_an_override_recorded_in_every_run():
    study = load_study("metrics")
    runs = study.runs(seeds=10, generations=300)
    assert len(runs) == 5 * 10
    assert {r.seed for r in runs} == set(range(1, 11))
    assert all(r.recorded_settings()["generations"] == 300 for r in runs)
    only = study.runs(seeds=2, only={"metric": "radial"})
    assert [r.setting_id for r in only] == ["metric-radial"] * 2


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"seeds": 0}, "seeds must be an integer from 1 to 1,000"),
        ({"grid": {"robot": ["4ws-9"]}}, "grid.robot: '4ws-9' is not one of"),
        ({"grid": {"bin_size": [-0.04]}}, "grid.bin_size: expected a positive number"),
        ({"fixed": {"speed": 3}}, "fixed.speed: unknown setting key"),
        ({"exclude": [{"metric": "circular"}]}, "exclude[0].metric is not a grid key"),
        ({"colour": "red"}, "unknown key 'colour'"),
    ],
)
def test_a_bad_study_file_is_refused_in_one_line(change, message):
    data = {"study": "s", "seeds": 2, "grid": {"robot": ["4ws-5"]}, **change}
    with pytest.raises(ConfigError, match=message.replace("[", r"\[")):
        parse_study(data, "s.yaml")


def test_an_unknown_study_lists_the_known_ones():
    result = run_study("status", "nonesuch", "--results", "/tmp/none")
    assert result.returncode == 1
    assert result.stderr.strip().splitlines() == [
        "evorbc-study: error: no study called 'nonesuch'; expected one of bin-time, hexapod, "
        "mappings, metrics, robot-types or a study file (.yaml)"
    ]


@pytest.mark.slow
def test_a_finished_run_holds_its_files_and_record(serial_results):
    run = serial_results / "approach-evorbc" / "seed-001"
    assert sorted(p.name for p in run.iterdir()) == [
        "arbitrator.json.xz",
        "repertoire.json.xz",
        "run.json",
        "run.log",
    ]
    record = json.loads((run / "run.json").read_text())
    assert record["settings"]["seed"] == 1 and record["settings"]["generations"] == 20
    assert record["summary"]["generations"] == 20
    assert record["seconds"] > 0 and record["cpu_seconds"] > 0


@pytest.mark.slow
def test_finished_runs_are_skipped_and_other_settings_refused(serial_results, tmp_path):
    # A copy: the runner takes its lock in the folder, which other workers read meanwhile.
    results = shutil.copytree(serial_results, tmp_path / "results")
    study = shutil.copy(serial_results.parent / "tiny.yaml", tmp_path)
    before = (results / "approach-evorbc" / "seed-002" / "run.json").read_text()
    again = run_study("run", study, "--results", results)
    assert again.returncode == 0
    assert "0 runs to go" in again.stderr
    assert (results / "approach-evorbc" / "seed-002" / "run.json").read_text() == before
    other = run_study("status", study, "--results", results, "--generations", "30")
    assert other.returncode == 1
    assert "was run with generations = 20, not 30; use another results folder" in other.stderr


@pytest.mark.slow
def test_a_killed_study_resumes_to_the_uninterrupted_results(serial_results, tmp_path):
    study = write_tiny_study(tmp_path)
    results = tmp_path / "results"
    proc = subprocess.Popen(
        study_command("run", study, "--results", results, "--jobs", "2"),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    try:
        wait_for(lambda: first_checkpoint(results), 300, "a NEAT checkpoint")
    finally:
        os.killpg(proc.pid, signal.SIGKILL)  # the runner and its commands, mid-run
        proc.wait()
    assert not any(results.rglob("run.json")) or len(list(results.rglob("run.json"))) < 2
    resumed = run_study("run", study, "--results", results)
    assert resumed.returncode == 0, resumed.stderr
    logs = [p.read_text() for p in results.rglob("run.log")]
    assert any(log.count("$ evorbc-evolve arbitrator") == 2 for log in logs)  # ran again
    # ... from its checkpoint, not from the start.
    assert any("resuming from the checkpoint: generations 1-" in log for log in logs)
    assert results_contents(results) == results_contents(serial_results)


@pytest.mark.slow
def test_a_second_runner_on_the_same_results_is_refused(tmp_path):
    study = write_tiny_study(tmp_path)
    results = tmp_path / "results"
    first = subprocess.Popen(
        study_command("run", study, "--results", results, "--jobs", "1"),
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    try:
        wait_for(lambda: (results / ".study.lock").exists(), 60, "the first runner's lock")
        second = run_study("run", study, "--results", results)
        assert second.returncode == 1
        assert "another evorbc-study is running on this results folder" in second.stderr
    finally:
        os.killpg(first.pid, signal.SIGINT)  # Ctrl-C: checkpoint and stop
        _, err = first.communicate(timeout=120)
    assert first.returncode == 130
    assert "interrupted; run the same command again to resume" in err


def test_the_study_file_is_checked_before_anything_runs(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump({"study": "bad", "seeds": 1, "grid": {"metric": ["round"]}}))
    result = run_study("run", path, "--results", tmp_path / "r")
    assert result.returncode == 1
    assert f"{path}: grid.metric: 'round' is not one of circular" in result.stderr
    assert not (tmp_path / "r").exists()


@pytest.mark.slow
def test_the_report_comes_from_the_results_folder_alone(serial_results, tmp_path):
    out = tmp_path / "report"
    result = run_study(
        "report", serial_results.parent / "tiny.yaml", "--results", serial_results, "--out", out
    )
    assert result.returncode == 0, result.stderr
    text = (out / "tiny.md").read_text()
    assert "* Runs finished: 2, 2 seeds per setting (the full protocol has 2)." in text
    assert "* NEAT generations per run: 20" in text
    record = json.loads((serial_results / "approach-evorbc" / "seed-001" / "run.json").read_text())
    best = [record["summary"]["best_fitness"]]
    record2 = json.loads((serial_results / "approach-evorbc" / "seed-002" / "run.json").read_text())
    best.append(record2["summary"]["best_fitness"])
    assert f"| evorbc | 2 | {sum(best) / 2:.3f} ± " in text
    for name in ("tiny-fitness.png", "tiny-boxplot.png", "tiny-repertoires.png"):
        with Image.open(out / name) as picture:  # a drawn figure, not a blank page
            assert picture.width >= 300 and len(picture.convert("RGB").getcolors(1 << 16)) > 20
        assert f"]({name})" in text
