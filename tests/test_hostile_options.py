"""Hostile options and outputs (issue 39): every output is a file, every count is bounded.

* An output that exists and is not a regular file (a device, a named pipe, a socket, a
  folder) is refused in one line before any work; a write never replaces one. A symbolic
  link is written through: its target is replaced, the link kept.
* One writer per file, whatever its name: a second run that would write a file of a
  running one (through a link, as its --out, its --csv or its checkpoint) is refused.
* A count past its bound (offline_evolution/bounds.py) is refused in one line.
* A study run whose command dies of a signal is a failed run, not an interruption.
"""

import os
import signal
import socket
import stat
import subprocess
import sys
import time

import pytest
import yaml
from study_helpers import write_tiny_study

from evorbc_ros.atomic_io import atomic_write_text
from evorbc_ros.config import ConfigError, config_dir
from evorbc_ros.defaults import default_repertoire
from offline_evolution.cli import main

TINY = ["--initial-batch", "20", "--batch-size", "10", "--iterations", "2", "--quiet"]


def run_cli(capsys, *argv) -> tuple[int, str]:
    """``evorbc-evolve ARGV`` in this process: the status and its one line of stderr."""
    try:
        code = main([str(a) for a in argv])
    except SystemExit as e:  # argparse's errors
        code = e.code
    err = capsys.readouterr().err.strip()
    assert "Traceback" not in err and "internal error" not in err, err
    assert len(err.splitlines()) <= 1, err
    return code, err


def special_file(folder, kind: str, suffix: str = ""):
    """A ``kind`` of file that is not a regular one, in ``folder``."""
    path = folder / (kind + suffix)
    if kind == "device":
        if os.geteuid() != 0:
            pytest.skip("mknod needs root")
        os.mknod(path, 0o666 | stat.S_IFCHR, os.makedev(1, 3))  # a private /dev/null
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "socket":
        sock = socket.socket(socket.AF_UNIX)
        sock.bind(str(path))
        sock.close()
    else:
        path.mkdir()
    return path


def is_unchanged(path, kind: str) -> bool:
    mode = os.lstat(path).st_mode
    test = {"device": stat.S_ISCHR, "fifo": stat.S_ISFIFO, "socket": stat.S_ISSOCK}
    return test.get(kind, stat.S_ISDIR)(mode)


# -- outputs are files -----------------------------------------------------------------------

KINDS = ["device", "fifo", "socket", "folder"]


@pytest.mark.parametrize("kind", KINDS)
def test_a_write_never_replaces_a_special_file(tmp_path, kind):
    path = special_file(tmp_path, kind)
    with pytest.raises(OSError) as info:
        atomic_write_text(path, "x")
    assert info.value.filename == str(path)
    assert "not a regular file" in info.value.strerror
    assert is_unchanged(path, kind)
    assert sorted(p.name for p in tmp_path.iterdir()) == [kind]  # no temporary left


def test_a_write_through_a_link_replaces_its_target_and_keeps_the_link(tmp_path):
    shared = tmp_path / "shared"
    shared.mkdir()
    (shared / "r.csv").write_text("old")
    link = tmp_path / "r.csv"
    link.symlink_to(shared / "r.csv")
    atomic_write_text(link, "new")
    assert link.is_symlink() and (shared / "r.csv").read_text() == "new"
    dangling = tmp_path / "new.csv"
    dangling.symlink_to(shared / "new.csv")
    atomic_write_text(dangling, "made")
    assert dangling.is_symlink() and (shared / "new.csv").read_text() == "made"


def test_export_csv_to_a_device_is_refused_and_leaves_it(tmp_path, capsys):
    null = special_file(tmp_path, "device")
    code, err = run_cli(capsys, "export-csv", default_repertoire(), "--out", null)
    assert code == 1
    assert err == (
        f"evorbc-evolve: error: --out {null}: is a character device, not a regular file; "
        "outputs are written as new files, so give a file name"
    )
    assert stat.S_ISCHR(os.lstat(null).st_mode)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize(
    "argv",
    [
        ["repertoire", *TINY, "--out", "{x}"],
        ["repertoire", *TINY, "--out", "r.json", "--csv", "{x}"],
        ["repertoire", *TINY, "--out", "r.json", "--plot", "{x}"],
        ["repertoire", *TINY, "--out", "r.json", "--checkpoint", "{x}"],
        ["standard", "--robot", "2ws-2", "--out", "a.json", "--plot", "{x}"],
        ["standard", "--robot", "2ws-2", "--out", "a.json", "--checkpoint", "{x}"],
        ["evaluate", "--out", "{x}"],
        ["replay", "--arbitrator", "missing.json", "--heatmap", "{x}"],
    ],
    ids=lambda a: a if isinstance(a, str) else " ".join(a[:1] + a[-2:-1]),
)
def test_every_output_that_is_not_a_file_is_refused_before_any_work(
    tmp_path, capsys, monkeypatch, argv, kind
):
    monkeypatch.chdir(tmp_path)
    path = special_file(tmp_path, kind, ".png")
    argv = [str(path) if a == "{x}" else a for a in argv]
    option = argv[argv.index(str(path)) - 1]
    code, err = run_cli(capsys, *argv)
    assert code == 1
    expected = "is a folder, expected a file name" if kind == "folder" else "not a regular file"
    assert err.startswith(f"evorbc-evolve: error: {option} {path}: is ") and expected in err
    assert is_unchanged(path, kind)
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]  # no work was done


# -- one writer per file ---------------------------------------------------------------------


def evolve_cmd(*argv):
    return [sys.executable, "-P", "-m", "offline_evolution.cli", *map(str, argv)]


@pytest.fixture(scope="module")
def first_run(tmp_path_factory):
    """A repertoire run writing r.json (and its checkpoint) in a folder, for minutes."""
    folder = tmp_path_factory.mktemp("locks")
    log = open(folder / "first.log", "w")  # noqa: SIM115
    # 10^8 evaluations: far longer than the tests; killed at the end.
    argv = ["repertoire", "--iterations", 100000, "--out", folder / "r.json"]
    first = subprocess.Popen(evolve_cmd(*argv), stderr=log)
    deadline = time.monotonic() + 120
    while "iteration" not in (folder / "first.log").read_text():
        assert first.poll() is None, (folder / "first.log").read_text()
        assert time.monotonic() < deadline
        time.sleep(0.2)
    yield folder, first.pid
    first.send_signal(signal.SIGKILL)
    first.wait()
    log.close()


def second_run(folder, *argv):
    done = subprocess.run(
        evolve_cmd("repertoire", *TINY, *argv),
        capture_output=True,
        text=True,
        timeout=120,
        cwd=folder,
        check=False,
    )
    return done.returncode, done.stderr.strip()


def test_the_same_output_through_a_linked_name_is_refused(first_run):
    folder, pid = first_run
    (folder / "link.json").symlink_to(folder / "r.json")
    code, err = second_run(folder, "--out", "link.json")
    assert code == 1
    assert err == (
        f"evorbc-evolve: error: --out link.json (the file {folder / 'r.json'}): another run "
        f"(pid {pid}) is writing it; wait for it to finish or choose another --out"
    )


def test_an_output_that_is_a_running_runs_checkpoint_is_refused(first_run):
    folder, pid = first_run
    code, err = second_run(folder, "--out", "r.json.checkpoint.npz")
    assert code == 1
    assert err == (
        f"evorbc-evolve: error: --out r.json.checkpoint.npz: another run (pid {pid}) is "
        "writing it; wait for it to finish or choose another --out"
    )


def test_a_csv_that_is_a_running_runs_output_is_refused(first_run):
    folder, pid = first_run
    code, err = second_run(folder, "--out", "other.json", "--csv", "r.json")
    assert code == 1
    assert err == (
        f"evorbc-evolve: error: --csv r.json: another run (pid {pid}) is writing it; wait "
        "for it to finish or choose another --csv"
    )
    assert not (folder / "other.json").exists()


# -- counts are bounded ----------------------------------------------------------------------


def neat_file(tmp_path, **changes):
    text = (config_dir() / "neat" / "4ws.ini").read_text()
    lines = [
        f"{line.split('=')[0].strip()} = {changes[line.split('=')[0].strip()]}"
        if "=" in line and line.split("=")[0].strip() in changes
        else line
        for line in text.splitlines()
    ]
    path = tmp_path / "n.ini"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize(
    ("argv", "code", "needle"),
    [
        (
            ["repertoire", "--initial-batch", 10**10, "--out", "r.json"],
            1,
            "--initial-batch: must be <= 100000000, got 10000000000",
        ),
        (
            ["repertoire", "--iterations", 10**5, "--batch-size", 10**5, "--out", "r.json"],
            1,
            "= 10,000,010,000 evaluations, more than the bound of 1,000,000,000 a run "
            "(docs/design.md section 12); lower --iterations, --batch-size or initial_batch",
        ),
        (
            ["arbitrator", "--repertoire", "r.json", "--generations", 10**30, "--out", "a.json"],
            2,
            "argument --generations: expected an integer from 1 to 100000, got '1" + "0" * 30,
        ),
        (
            ["mazes", "--count", 10**12, "--out", "m"],
            2,
            "argument --count: expected an integer from 1 to 10000",
        ),
        (
            ["evaluate", "--generated", 10**9],
            2,
            "argument --generated: expected an integer from 1 to 10000",
        ),
        (
            ["repertoire", "--checkpoint-every", 0, "--out", "r.json"],
            2,
            "argument --checkpoint-every: expected an integer >= 1, got '0'",
        ),
        (
            ["standard", "--robot", "2ws-2", "--checkpoint-every", 0, "--out", "a.json"],
            2,
            "argument --checkpoint-every: expected an integer >= 1, got '0'",
        ),
        (
            ["repertoire", "--workers", 0, "--out", "r.json"],
            2,
            "argument --workers: expected an integer from 1 to 1024, got '0'",
        ),
        (["repertoire", "--out", ""], 1, "--out '': an empty name, expected a file name"),
        (["standard", "--robot", "2ws-2", "--out", ""], 1, "--out '': an empty name"),
        (["evaluate", "--out", ""], 1, "--out '': an empty name, expected a file name"),
        (["export-csv", default_repertoire(), "--out", ""], 1, "--out '': an empty name"),
        (["mazes", "--out", ""], 1, "--out '': an empty name, expected a folder"),
    ],
    ids=lambda v: v if isinstance(v, str) else None,
)
def test_a_count_past_its_bound_is_refused_in_one_line(
    tmp_path, capsys, monkeypatch, argv, code, needle
):
    monkeypatch.chdir(tmp_path)
    status, err = run_cli(capsys, *argv)
    assert status == code and needle in err, err
    assert sorted(os.listdir(tmp_path)) == []


@pytest.mark.parametrize(
    ("changes", "needle"),
    [
        ({"num_hidden": 5000}, "[EvoRBCGenome] num_hidden must be at most 100, got 5000; lower it"),
        ({"pop_size": 10**6}, "[NEAT] pop_size must be at most 10,000, got 1,000,000; lower it"),
    ],
)
def test_neat_settings_past_their_bound_are_refused(tmp_path, capsys, changes, needle):
    neat = neat_file(tmp_path, **changes)
    out = tmp_path / "a.json"
    code, err = run_cli(capsys, "standard", "--robot", "2ws-2", "--neat-config", neat, "--out", out)
    assert code == 1 and err.startswith(f"evorbc-evolve: error: {neat}: {needle}")


def test_the_memory_check_names_the_setting_that_causes_the_excess(monkeypatch):
    from offline_evolution import memory
    from offline_evolution.maze_task.base import MazeTaskSettings

    monkeypatch.setattr(memory, "machine_memory", lambda: 24 << 30)
    task = MazeTaskSettings.from_dict({"mazes": ["obstacle"]}, "t.yaml")
    with pytest.raises(ConfigError) as info:
        memory.check_evolution_memory(task, 10**8, "4ws-5", "t.yaml", 75, 10, neat_source="n.ini")
    message = str(info.value)
    assert message.startswith("n.ini: [NEAT] pop_size 100000000 (100,000,000 episodes")
    assert message.endswith("lower pop_size, samples_per_maze or the number of mazes")
    with pytest.raises(ConfigError) as info:
        memory.check_evolution_memory(task, 150, "4ws-5", "t.yaml", 75, 10**9, run_source="r.yaml")
    assert str(info.value).startswith("r.yaml: post_samples 1000000000: the post-evaluation")
    assert str(info.value).endswith("lower post_samples, hall_of_fame or samples_per_maze")


def study_cli(capfd, *argv) -> tuple[int, str]:
    from offline_evolution.study.cli import main as study_main

    try:
        code = study_main([str(a) for a in argv])
    except SystemExit as e:
        code = e.code
    err = capfd.readouterr().err.strip()
    assert "Traceback" not in err and "internal error" not in err, err
    return code, err


@pytest.mark.parametrize(
    ("study", "argv", "needle"),
    [
        ({"seeds": 10**12}, [], "seeds must be an integer from 1 to 1,000, got 1000000000000"),
        (
            {
                "grid": {
                    k: list(range(1, 101))
                    for k in (
                        "generations",
                        "iterations",
                        "eval_time",
                        "initial_batch",
                        "batch_size",
                        "bin_size",
                    )
                }
            },
            [],
            "grid has 1,000,000,000,000 combinations of settings, more than the bound of 10,000",
        ),
        ({"fixed": {"robot": "2ws-2", "generations": 10**30}}, [], "fixed.generations: expected"),
        ({}, ["--seeds", 10**12], "argument --seeds: expected an integer from 1 to 1000"),
    ],
)
def test_a_study_past_its_bounds_is_refused_before_listing_its_runs(
    tmp_path, capfd, study, argv, needle
):
    data = {"study": "big", "seeds": 2, "grid": {"approach": ["evorbc"]}, "fixed": {}}
    data.update(study)
    path = tmp_path / "big.yaml"
    path.write_text(yaml.safe_dump(data))
    code, err = study_cli(capfd, "status", path, "--results", tmp_path / "res", *argv)
    assert code in (1, 2) and needle in err and len(err.splitlines()) == 1, err


def test_too_many_study_runs_are_refused(tmp_path, capfd):
    grid = {"approach": ["evorbc"], "generations": list(range(1, 202))}
    path = tmp_path / "big.yaml"
    path.write_text(yaml.safe_dump({"study": "big", "seeds": 1000, "grid": grid}))
    code, err = study_cli(capfd, "status", path, "--results", tmp_path / "res")
    assert code == 1
    assert err == (
        f"evorbc-study: error: {path}: 201 settings x 1,000 seeds = 201,000 runs, more than "
        "the bound of 100,000 a study (docs/design.md section 12); lower seeds (or give "
        "--seeds) or list fewer grid values"
    )


@pytest.mark.parametrize(
    ("option", "value", "needle"),
    [
        ("--threads", 1000000, "argument --threads: expected an integer from 1 to 256"),
        ("--jobs", 0, "argument --jobs: expected an integer from 1 to 1024"),
        ("--retries", -1, "argument --retries: expected an integer from 0 to 100"),
    ],
)
def test_study_run_options_are_bounded(tmp_path, capfd, option, value, needle):
    study = write_tiny_study(tmp_path)
    code, err = study_cli(capfd, "run", study, "--results", tmp_path / "res", option, value)
    assert code == 2 and needle in err
    assert not (tmp_path / "res").exists()


# -- a run that dies of a signal -------------------------------------------------------------


@pytest.mark.parametrize("sig", [signal.SIGSEGV, signal.SIGKILL])
def test_a_study_run_that_dies_of_a_signal_fails_and_is_not_an_interruption(
    tmp_path, capfd, monkeypatch, sig
):
    from offline_evolution.study import run as study_run

    # Each command of the run kills itself, as numba's thread pool did with 10^6 threads.
    crash = f"import os; os.kill(os.getpid(), {int(sig)})"
    monkeypatch.setattr(study_run, "WORKER", (sys.executable, "-c", crash))
    study = write_tiny_study(tmp_path)
    results = tmp_path / "res"
    code, err = study_cli(capfd, "run", study, "--results", results, "--seeds", 1, "--jobs", 1)
    folder = results / "approach-evorbc" / "seed-001"
    assert code == 1, err
    assert (
        f"run approach-evorbc/seed-001: repertoire died of signal {sig.name} "
        f"({signal.strsignal(sig)}); its checkpoint, if any, is kept; see {folder / 'run.log'}"
    ) in err
    assert "run the same command again" not in err
    assert err.splitlines()[-1].startswith("1 runs failed (see run.log)")


def test_a_run_log_that_is_a_pipe_is_refused_before_the_run(tmp_path, capfd):
    study = write_tiny_study(tmp_path)
    folder = tmp_path / "res" / "approach-evorbc" / "seed-001"
    folder.mkdir(parents=True)
    os.mkfifo(folder / "run.log")
    code, err = study_cli(capfd, "run", study, "--results", tmp_path / "res", "--seeds", 1)
    assert code == 1
    assert f"{folder / 'run.log'}: is a named pipe (FIFO), not a regular file" in err
