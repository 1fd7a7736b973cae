"""The task stored in an arbitrator file is checked like ``--task``, and settings that would
exhaust memory are refused up front, in one line that says what to lower."""

import json
import resource
import subprocess
import sys

import pytest
import yaml
from test_errors_checkpoints import one_line_error

from evorbc_ros.config import ConfigError
from evorbc_ros.defaults import default_arbitrator
from offline_evolution import memory
from offline_evolution.cli import main

ARB = json.loads(default_arbitrator().read_text())
GIB = 1 << 30


@pytest.fixture(autouse=True)
def a_24_gib_machine(monkeypatch):
    """The limits as on the 24 GiB machines the project runs on, whatever runs the test."""
    monkeypatch.setattr(memory, "machine_memory", lambda: 24 * GIB)


def run_limited(*argv):
    """``evorbc-evolve ARGV`` on a 24 GiB machine, in a process limited to 6 GiB.

    Should a check fail, the run then dies of a MemoryError rather than taking the
    machine's memory (and the test fails).
    """

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (6 * GIB, 6 * GIB))

    code = (
        "import sys; import offline_evolution.memory as m; m.machine_memory = lambda: 24 << 30;"
        "from offline_evolution.cli import main; sys.exit(main(sys.argv[1:]))"
    )
    done = subprocess.run(
        [sys.executable, "-c", code, *map(str, argv)],
        capture_output=True,
        text=True,
        timeout=300,
        preexec_fn=limit,
        check=False,
    )
    err = done.stderr.strip()
    assert "internal error" not in err and "Traceback" not in err, err
    assert done.returncode == 1 and len(err.splitlines()) == 1, err
    return err


def arbitrator_with_task(tmp_path, **task):
    data = json.loads(json.dumps(ARB))
    data["evolution"]["task"].update(task)
    path = tmp_path / "a.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize(
    ("task", "needle"),
    [
        ({"episode_time": 0.15}, "evolution.task: episode_time must be a positive multiple of"),
        ({"mazes": []}, "evolution.task: mazes must name at least one maze"),
        ({"mazes": ["nowhere"]}, "evolution.task: mazes: "),
        ({"sensors": "sensors/none.yaml"}, "evolution.task: sensors: no such file"),
    ],
)
def test_the_task_inside_an_arbitrator_file_is_checked_like_task(tmp_path, capsys, task, needle):
    path = arbitrator_with_task(tmp_path, **task)
    err = one_line_error(capsys, "replay", "--arbitrator", path)
    assert err.startswith("evorbc-evolve: error: ") and needle in err


def test_a_day_long_replay_says_what_to_lower(tmp_path):
    err = run_limited("replay", "--arbitrator", arbitrator_with_task(tmp_path, episode_time=1e7))
    assert (
        "replaying 5 episodes of 100,000,000 control cycles (episode_time 10000000.0 s in "
        + (f"{tmp_path / 'a.json'}: evolution.task)")
        in err
    )
    assert "needs about 29.4 GiB of memory" in err and "(12.0 GiB, half of its 24.0 GiB)" in err
    assert err.endswith("lower episode_time, --episodes or the number of mazes")


def test_samples_per_maze_that_would_exhaust_memory_is_refused_before_evolving(
    tmp_path, monkeypatch, small_repertoire
):
    rep = tmp_path / "r.json"
    small_repertoire.save(rep)
    task = tmp_path / "task.yaml"
    task.write_text(yaml.safe_dump({"mazes": ["obstacle"] * 5, "samples_per_maze": 100000}))
    argv = ["arbitrator", "--repertoire", rep, "--task", task, "--out", tmp_path / "a.json"]
    err = run_limited(*argv)
    assert err.startswith(f"evorbc-evolve: error: {task}: samples_per_maze 100000 (75,000,000 ")
    assert "150 genomes x 5 mazes x 100000 starts" in err and "needs about 28.3 GiB" in err
    assert err.endswith("lower samples_per_maze, the number of mazes or pop_size")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.json", "task.yaml"]
    # A sane task gets as far as the evolution.
    task.write_text(yaml.safe_dump({"mazes": ["obstacle"], "samples_per_maze": 3}))
    monkeypatch.setattr(
        "offline_evolution.arbitrator.evolve.Evolution.__init__",
        lambda *a, **k: pytest.fail("evolution started"),
    )
    with pytest.raises(BaseException, match="evolution started"):
        main([str(a) for a in argv])


def test_a_repertoire_archive_that_cannot_fit_is_refused(tmp_path):
    out = tmp_path / "r.json"
    err = run_limited("repertoire", "--bin-size", "0.0001", "--eval-time", "20", "--out", out)
    assert "--bin-size 0.0001 (6,400,160,001 archive cells for eval_time 20.0 s)" in err
    assert err.endswith("raise bin_size or lower eval_time") and not out.exists()
    err = run_limited("repertoire", "--batch-size", str(10**8), "--out", out)
    assert "--batch-size 100000000 (primitives evaluated at once" in err


def test_the_limit_follows_the_machine(monkeypatch):
    monkeypatch.setattr(memory, "machine_memory", lambda: 64 * GIB)
    memory.check_memory(20 * GIB, "x", "y")  # fits in half of 64 GiB
    with pytest.raises(ConfigError, match=r"needs about 40\.0 GiB of memory, more than"):
        memory.check_memory(40 * GIB, "x", "y")
