"""``evorbc-evolve repertoire``: outputs, summary, and clean errors for bad input."""

import json
import os
import signal
import subprocess
import sys

import pytest

from evorbc_ros.repertoire import Repertoire
from offline_evolution.cli import main

SMALL = ["--initial-batch", "300", "--batch-size", "100", "--iterations", "20", "--quiet"]


def run_cli(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_repertoire_writes_file_plot_csv_and_a_summary_line(tmp_path, capsys):
    out = tmp_path / "rep" / "r.json"
    code, stdout, stderr = run_cli(
        capsys,
        "repertoire",
        "--robot",
        "2ws-3",
        "--seed",
        "3",
        "--bin-size",
        "0.05",
        "--eval-time",
        "1.5",
        "--metric",
        "radial",
        *SMALL,
        "--out",
        str(out),
        "--plot",
        str(tmp_path / "r.png"),
        "--csv",
        str(tmp_path / "r.csv"),
    )
    assert code == 0, stderr
    lines = stdout.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("2ws-3 repertoire: ")
    assert "mean quality" in lines[0] and "2,300 evaluations" in lines[0]
    r = Repertoire.load(out)
    assert (r.robot, r.seed, r.bin_size, r.eval_time, r.metric) == ("2ws-3", 3, 0.05, 1.5, "radial")
    assert (tmp_path / "r.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert len((tmp_path / "r.csv").read_text().splitlines()) == len(r) + 1
    assert not (tmp_path / "rep" / "r.json.checkpoint.npz").exists()


def test_config_file_and_override(tmp_path, capsys):
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        "robot: 4ws-3\nmetric: distance\nbin_size: 0.08\neval_time: 1.0\n"
        "initial_batch: 200\nbatch_size: 50\niterations: 4\nseed: 5\n"
    )
    code, _, err = run_cli(
        capsys,
        "repertoire",
        "--config",
        str(cfg),
        "--seed",
        "6",
        "--out",
        str(tmp_path / "r.json"),
        "--quiet",
    )
    assert code == 0, err
    r = Repertoire.load(tmp_path / "r.json")
    assert (r.robot, r.metric, r.seed, r.algorithm["evaluations"]) == ("4ws-3", "distance", 6, 400)


def test_export_csv(tmp_path, capsys, small_repertoire):
    small_repertoire.save(tmp_path / "r.json")
    code, out, _ = run_cli(capsys, "export-csv", str(tmp_path / "r.json"))
    assert code == 0 and (tmp_path / "r.csv").exists() and "primitives" in out


@pytest.mark.parametrize(
    ("argv", "code", "needle"),
    [
        (["repertoire", "--robot", "tank", "--out", "x.json"], 2, "invalid choice: 'tank'"),
        (["repertoire", "--bin-size", "-3", "--out", "x.json"], 2, "positive number"),
        (["repertoire", "--iterations", "many", "--out", "x.json"], 2, "expected an integer"),
        (
            ["repertoire", "--eval-time", "0.25", "--out", "x.json"],
            1,
            "multiple of the 0.1 s control period",
        ),
        (
            ["repertoire", "--config", "missing.yaml", "--out", "x.json"],
            1,
            "missing.yaml: no such settings file",
        ),
        (["export-csv", "missing.json"], 1, "missing.json: no such repertoire file"),
    ],
)
def test_bad_arguments_exit_non_zero_without_traceback(
    tmp_path, capsys, monkeypatch, argv, code, needle
):
    monkeypatch.chdir(tmp_path)
    if code == 2:
        with pytest.raises(SystemExit) as info:
            main(argv)
        assert info.value.code == 2
        err = capsys.readouterr().err
    else:
        got, _, err = run_cli(capsys, *argv)
        assert got == code
        assert len(err.strip().splitlines()) == 1
    assert needle in err and "Traceback" not in err and "internal error" not in err


def test_bad_yaml_and_corrupt_checkpoint(tmp_path, capsys):
    cfg = tmp_path / "c.yaml"
    cfg.write_text("robot: 4ws-5\n  metric: circular\n")
    code, _, err = run_cli(
        capsys, "repertoire", "--config", str(cfg), "--out", str(tmp_path / "r.json")
    )
    assert code == 1 and f"{cfg}: invalid YAML at line 2" in err
    # Not recognisably a checkpoint: maybe someone's file, so even --restart keeps it.
    (tmp_path / "r.json.checkpoint.npz").write_bytes(b"not a checkpoint")
    code, _, err = run_cli(capsys, "repertoire", *SMALL, "--out", str(tmp_path / "r.json"))
    assert code == 1 and "not a checkpoint (not an .npz archive)" in err
    code, _, err = run_cli(
        capsys, "repertoire", *SMALL, "--restart", "--out", str(tmp_path / "r.json")
    )
    assert code == 1 and "--restart does not delete it" in err
    assert (tmp_path / "r.json.checkpoint.npz").read_bytes() == b"not a checkpoint"


@pytest.mark.slow
def test_ctrl_c_saves_a_checkpoint_and_the_same_command_resumes(tmp_path):
    out = tmp_path / "r.json"
    cmd = [
        sys.executable,
        "-m",
        "offline_evolution.cli",
        "repertoire",
        "--robot",
        "4ws-5",
        "--seed",
        "2",
        "--initial-batch",
        "1000",
        "--batch-size",
        "1000",
        "--iterations",
        "150",
        "--checkpoint-every",
        "1000000",
        "--out",
        str(out),
    ]
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True, env=env)
    first = proc.stderr.readline()  # first progress line: the run is under way
    assert first.startswith("iteration"), first
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "run the same command again to resume" in err
    assert (tmp_path / "r.json.checkpoint.npz").exists() and not out.exists()
    resumed = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=120)
    assert resumed.returncode == 0, resumed.stderr
    assert "resuming from the checkpoint at iteration" in resumed.stderr
    straight = subprocess.run(
        [*cmd[:-1], str(tmp_path / "s.json")], capture_output=True, text=True, env=env, timeout=120
    )
    assert straight.returncode == 0
    a = json.loads(out.read_text())["primitives"]
    b = json.loads((tmp_path / "s.json").read_text())["primitives"]
    assert a == b
