"""A robot in its own package, through the whole pipeline (docs/your-robot.md).

The plugin (tests/plugin_helpers.py) is built in a temporary folder and put on the path of
this process and of every command and node it starts: a repertoire, three generations of
arbitrator evolution and a replay from ``evorbc-evolve``, then ``evorbc-sim``'s lockstep
ROS graph, which must drive the robot exactly as the offline replay does.
"""

import json
import os
import subprocess
import sys

import numpy as np
import pytest
from plugin_helpers import MODULE, build_plugin
from ros_domains import claim_domain

from evorbc_ros.robots import registry

BIN = os.path.dirname(sys.executable)


@pytest.fixture
def plugin(tmp_path, monkeypatch):
    """The plugin on ``sys.path`` and ``PYTHONPATH``; forgotten again afterwards."""
    site = build_plugin(tmp_path)
    monkeypatch.syspath_prepend(str(site))
    path = os.environ.get("PYTHONPATH")
    monkeypatch.setenv("PYTHONPATH", str(site) + (os.pathsep + path if path else ""))
    registry.reset()
    yield site
    registry.reset()
    for name in [m for m in sys.modules if m.split(".")[0] == "evorbc_crab"]:
        del sys.modules[name]


def cli(tmp_path, command, *args):
    out = subprocess.run(
        [os.path.join(BIN, command), *args],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr
    assert "evorbc: warning" not in out.stderr  # no plugin was broken
    return out


@pytest.mark.slow
def test_a_robot_in_its_own_package_goes_through_the_whole_pipeline(tmp_path, plugin):
    from evorbc_ros.arbitrator import ArbitratorFile
    from evorbc_ros.repertoire import Repertoire
    from offline_evolution.maze_task.replay import replay
    from offline_evolution.maze_task.task import MazeTaskSettings, make_task

    crab = registry.lookup("crab")
    assert crab.parameter_names == ("speed", "angle") and "crab" in registry.ROBOT_NAMES

    # Repertoire and arbitrator with nothing but the robot's name: its settings files.
    cli(
        tmp_path, "evorbc-evolve", "repertoire", "--robot", "crab", "--seed", "1", "--out", "r.json"
    )
    rep = Repertoire.load(tmp_path / "r.json")
    assert rep.robot == "crab" and rep.metric == "distance" and len(rep) > 10
    assert rep.algorithm["evaluations"] == 400 + 10 * 100
    headings = np.abs(rep.heading)
    assert headings.max() < 1e-9  # all four wheels steer together: it never turns
    out = cli(
        tmp_path, "evorbc-evolve", "arbitrator", "--repertoire", "r.json", "--seed", "1",
        "--out", "a.json", "--quiet",
    )  # fmt: skip
    assert out.stdout.startswith("crab arbitrator: ") and "3 generations" in out.stdout
    arb = ArbitratorFile.load(tmp_path / "a.json")
    assert arb.robot == "crab" and arb.evolution["task"]["mazes"] == ["gaps"]
    out = cli(
        tmp_path, "evorbc-evolve", "standard", "--robot", "crab", "--equal-budget", "--seed",
        "1", "--out", "s.json", "--quiet",
    )  # fmt: skip
    assert "crab standard-NEAT controller" in out.stdout and "5 generations" in out.stdout
    assert ArbitratorFile.load(tmp_path / "s.json").network.output_keys == (0, 1)
    out = cli(tmp_path, "evorbc-evolve", "replay", "--arbitrator", "a.json", "--json")
    replayed = json.loads(out.stdout)["mazes"][0]

    # The same episode offline, in this process, with its trace.
    task = make_task(MazeTaskSettings.load(crab.settings_file("task")), "crab")
    outcomes, result = replay(arb, task, task.nominal_starts(), rep)
    assert outcomes[0].fitness == replayed["fitness"]

    # The lockstep graph: evorbc-sim takes the maze (gaps) and the episode time (15 s)
    # from the registration; every node finds the robot through the plugin.
    cli(
        tmp_path, "evorbc-sim", "--arbitrator", "a.json", "--repertoire", "r.json",
        "--result", "run.json", "--plot", "run.png", "--quiet",
        "--domain-id", str(claim_domain(177)),
    )  # fmt: skip
    got = json.loads((tmp_path / "run.json").read_text())
    assert got["robot"] == "crab" and got["episode_time"] == 15.0
    cycles = int(result.cycles[0])
    np.testing.assert_allclose(np.array(got["trajectory"]), result.pose[0, : cycles + 1], atol=1e-9)
    assert got["fitness"] == pytest.approx(outcomes[0].fitness, abs=1e-12)
    assert got["reached"] == outcomes[0].reached


def test_a_broken_plugin_is_one_line_and_every_command_still_works(tmp_path):
    """A plugin that cannot be imported is named once; the built-in robots still work."""
    broken = build_plugin(
        tmp_path / "broken", MODULE.replace("from pathlib", "import nosuch\nfrom pathlib")
    )
    env = dict(os.environ, PYTHONPATH=str(broken))
    from evorbc_ros.defaults import default_repertoire

    out = subprocess.run(
        [
            os.path.join(BIN, "evorbc-evolve"),
            "export-csv",
            str(default_repertoire()),
            "--out",
            str(tmp_path / "r.csv"),
        ],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    assert out.stderr.splitlines() == [
        "evorbc: warning: robot plugin crab (evorbc_crab:robots in evorbc-crab 0.1.0) cannot "
        "be loaded (ModuleNotFoundError: No module named 'nosuch'); its robots are left out"
    ]
    out = subprocess.run(
        [os.path.join(BIN, "evorbc-evolve"), "standard", "--robot", "crab", "--out", "s.json"],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
        timeout=120,
    )
    assert out.returncode == 2
    lines = out.stderr.splitlines()
    assert len(lines) == 2 and lines[0].startswith("evorbc: warning: robot plugin crab (")
    assert (
        "invalid choice: 'crab' (choose from '2ws-2', '2ws-3', '4ws-3', '4ws-5', 'hexapod', 'a1', "
        "'turtlebot3-burger')" in lines[1]
    )
