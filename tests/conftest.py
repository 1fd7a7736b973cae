"""Shared fixtures."""

import fcntl
import os
import signal

import pytest
import ros_domains

import evorbc_ros

# Processes the tests start (`python -m offline_evolution.cli`, the nodes) must not import
# the checkout's ROS package folders either.
os.environ.setdefault("PYTHONSAFEPATH", "1")

if getattr(evorbc_ros, "__file__", None) is None:
    # The checkout's ROS package folder evorbc_ros/ shadowed the installed Python package:
    # python put the current folder first on sys.path (docs/design.md section 10).
    pytest.exit("run the tests with `make test`, `.venv/bin/pytest` or `python -P -m pytest`", 2)
from study_helpers import run_study, write_tiny_study

from offline_evolution.repertoire.map_elites import generate_repertoire
from offline_evolution.repertoire.settings import load_settings

pytest_plugins = ["ros_helpers"]  # the `ros` fixture for in-process ROS 2 tests


def pytest_collection_modifyitems(items):
    """Run the files holding slow tests first, each file's tests in their own order.

    ``make test`` hands whole files to three workers in this order; the slow files (wheel
    and colcon installs, Ray clusters, ROS graphs) started first keep the last worker from
    starting one alone at the end.
    """
    slow = {item.module for item in items if item.get_closest_marker("slow")}
    items.sort(key=lambda item: item.module not in slow)


@pytest.fixture(autouse=True)
def _ros_domains():
    """Give back the ROS domains a test claimed (tests/ros_domains.py) once it ends."""
    yield
    ros_domains.release_all()


def small_settings(**overrides):
    """A quick 4WS MAP-Elites run: Table I settings with a small budget."""
    values = {
        "robot": "4ws-5",
        "initial_batch": 400,
        "batch_size": 100,
        "iterations": 25,
        "seed": 7,
    }
    values.update(overrides)
    return load_settings(**values)


@pytest.fixture(scope="session")
def small_repertoire():
    """A small 4ws-5 repertoire, generated once per test session."""
    return generate_repertoire(small_settings())


SMALL_TASK = {
    "mazes": ["obstacle", "gaps"],
    "episode_time": 15.0,
    "samples_per_maze": 1,
    "sensors": "sensors/4ws.yaml",
}


def evolution_settings(neat_file, repertoire, task, seed=3, generations=4, **changes):
    """EvolutionSettings of a small 4ws-5 EvoRBC run (hall of fame 3, 1 post-sample)."""
    from offline_evolution.arbitrator.evolve import EvolutionSettings, file_sha256

    return EvolutionSettings(
        **{
            "kind": "evorbc",
            "robot": "4ws-5",
            "generations": generations,
            "seed": seed,
            "neat_file": str(neat_file),
            "neat_sha256": file_sha256(neat_file),
            "task": task,
            "mapping": "polar",
            "repertoire_fingerprint": repertoire.fingerprint(),
            "hall_of_fame": 3,
            "post_samples": 1,
            **changes,
        }
    )


@pytest.fixture
def small_neat_file(tmp_path):
    """The shipped NEAT settings with a population of 24 (fast tests)."""
    from evorbc_ros.config import config_dir

    shipped = (config_dir() / "neat" / "4ws.ini").read_text()
    text = shipped.replace("pop_size              = 150", "pop_size              = 24")
    assert "pop_size              = 24" in text
    path = tmp_path / "small.ini"
    path.write_text(text)
    return path


@pytest.fixture
def small_task_file(tmp_path):
    """A two-maze, 15 s task file."""
    import yaml

    from evorbc_ros.config import config_dir

    path = tmp_path / "task.yaml"
    # Absolute: a relative path in a task file is from its folder (recorded from config/).
    sensors = str(config_dir() / SMALL_TASK["sensors"])
    path.write_text(yaml.safe_dump({**SMALL_TASK, "sensors": sensors}))
    return path


@pytest.fixture(scope="session")
def serial_results(tmp_path_factory, worker_id):
    """The tiny study (tests/study_helpers.py) run serially, uninterrupted: the reference
    of the study-runner and Ray tests (read only).

    Under pytest-xdist each worker has its own session; the study (about 30 s) is run once
    for all of them, in the run's shared temporary folder, by whichever worker needs it
    first, while the others wait on its lock.
    """
    root = tmp_path_factory.getbasetemp()
    if worker_id != "master":
        root = root.parent  # shared by the workers of one run
    folder = root / "serial"
    with open(root / "serial.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (folder / "done").exists():
            folder.mkdir(exist_ok=True)
            study = write_tiny_study(folder)
            result = run_study("run", study, "--results", folder / "results", "--jobs", "1")
            assert result.returncode == 0, result.stderr
            assert "study tiny: 2 done, 0 running, 0 left" in result.stderr
            (folder / "done").touch()
    return folder / "results"


@pytest.fixture(autouse=True)
def _restore_signal_handlers():
    """Give every test the SIGINT and SIGTERM handlers it started with.

    A node's or a command's main run in this process ends by ignoring SIGINT (it is
    finishing anyway); left so, every later subprocess would inherit SIG_IGN and shrug
    off the Ctrl-C a test sends it.
    """
    saved = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    # Whatever ran before (a test, or code run while collecting) must not have left them
    # ignored: pytest's own are Python's defaults.
    if saved[signal.SIGINT] is signal.SIG_IGN:
        saved[signal.SIGINT] = signal.default_int_handler
    if saved[signal.SIGTERM] is signal.SIG_IGN:
        saved[signal.SIGTERM] = signal.SIG_DFL
    for sig, handler in saved.items():
        if handler is not None:
            signal.signal(sig, handler)
    yield
    for sig, handler in saved.items():
        if handler is not None:
            signal.signal(sig, handler)
