"""A robot in its own package, built in a temporary folder as docs/your-robot.md describes.

The package is the docs' example: ``evorbc_crab``, a 4WS body that steers all four wheels
together, with its own settings files, declared through the ``evorbc.robots`` entry-point
group in its ``pyproject.toml``. pip installs it into a folder of its own
(``--target``) that goes on ``PYTHONPATH`` (and ``sys.path``), never into the venv, so no
other test sees it.
"""

import subprocess
import sys
from pathlib import Path

from evorbc_ros.config import config_dir

PYPROJECT = """\
[build-system]
requires = ["setuptools>=61"]
build-backend = "setuptools.build_meta"

[project]
name = "evorbc-crab"
version = "0.1.0"
description = "A four-wheel-steering robot that steers all four wheels together"
dependencies = ["evorbc"]

[project.entry-points."evorbc.robots"]
crab = "evorbc_crab:robots"

[tool.setuptools.package-data]
evorbc_crab = ["*.yaml", "*.ini"]
"""

MODULE = '''\
"""evorbc_crab: a 4WS body that steers all four wheels together (crab steering)."""

from pathlib import Path

from evorbc_ros.robots.builtin.four_ws import four_ws_robot
from evorbc_ros.robots.four_ws import FourWSType, gene_matrix
from evorbc_ros.robots.registry import SettingsFiles

HERE = Path(__file__).resolve().parent

#: Two genes: the wheel speed (command 0) and one angle for all four wheels (1 to 4).
CRAB = FourWSType("crab", ("speed", "angle"), gene_matrix([(0,), (1, 2, 3, 4)]))


def robots():
    """The entry point: this package's robot registrations."""
    return four_ws_robot(
        CRAB,
        "4WS body steering all four wheels together: it translates, never turns",
        settings=SettingsFiles(
            repertoire=str(HERE / "repertoire.yaml"),
            arbitrator=str(HERE / "arbitrator.yaml"),
            neat=str(HERE / "neat.ini"),
            task=str(HERE / "task.yaml"),
        ),
        maze="gaps",
        episode_time=15.0,
        equal_budget_generations=2,
    )
'''

#: A small budget, so the test's pipeline takes seconds.
REPERTOIRE = """\
robot: crab
metric: distance          # a crab never turns: straight paths are its best primitives
bin_size: 0.04
eval_time: 2.0
initial_batch: 400
batch_size: 100
iterations: 10
"""
ARBITRATOR = """\
generations: 3
mapping: polar
neat: neat.ini            # beside this file
task: task.yaml
hall_of_fame: 4
post_samples: 1
"""
TASK = """\
mazes: [gaps]
episode_time: 15.0
samples_per_maze: 1
sensors: sensors.yaml       # beside this file (a copy of evorbc's 4WS layout)
"""


def write_package(root: Path, module: str = MODULE) -> Path:
    """The plugin's source tree under ``root/evorbc-crab``: pyproject, module, settings."""
    src = root / "evorbc-crab"
    package = src / "evorbc_crab"
    package.mkdir(parents=True)
    (src / "pyproject.toml").write_text(PYPROJECT)
    (package / "__init__.py").write_text(module)
    (package / "repertoire.yaml").write_text(REPERTOIRE)
    (package / "arbitrator.yaml").write_text(ARBITRATOR)
    (package / "task.yaml").write_text(TASK)
    (package / "sensors.yaml").write_text((config_dir() / "sensors" / "4ws.yaml").read_text())
    neat = (config_dir() / "neat" / "4ws.ini").read_text()
    small = neat.replace("pop_size              = 150", "pop_size              = 16")
    assert small != neat
    (package / "neat.ini").write_text(small)
    return src


def install(src: Path, site: Path) -> Path:
    """``pip install`` the package in ``src`` into ``site`` (a folder for ``PYTHONPATH``).

    As a user installs a robot package (docs/your-robot.md): pip builds it with its own
    build backend and writes its entry points; offline (``--no-index``, no build isolation,
    the dependency on evorbc already met by this environment).
    """
    command = [sys.executable, "-m", "pip", "install", "--no-deps", "--no-build-isolation"]
    command += ["--no-index", "--quiet", "--disable-pip-version-check", "--target", str(site)]
    out = subprocess.run([*command, str(src)], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    return site


def build_plugin(root: Path, module: str = MODULE) -> Path:
    """Write and install the plugin; the folder to put on ``PYTHONPATH``."""
    return install(write_package(root, module), root / "site")


#: A package with a robot of a family of its own, declared in each layer's group, and a
#: robot declared the deprecated way (factories on the record). Its "own" code is the 4WS
#: robots', so both must move exactly as 4ws-5 does.
TRACKS_PYPROJECT = """\
[build-system]
requires = ["setuptools>=61"]
build-backend = "setuptools.build_meta"

[project]
name = "evorbc-tracks"
version = "0.2.0"
dependencies = ["evorbc"]

[project.entry-points."evorbc.robots"]
tracks = "evorbc_tracks:robots"

[project.entry-points."evorbc.sim_adapters"]
tracked = "evorbc_tracks.sim:ADAPTERS"

[project.entry-points."evorbc.search_adapters"]
tracked = "evorbc_tracks.search:adapters"
"""
TRACKS_MODULE = '''\
"""evorbc_tracks: robots of a family of its own ("tracked") and one declared the old way."""

import dataclasses

from evorbc_ros.robots.builtin.four_ws import four_ws_robot
from evorbc_ros.robots.four_ws import ROBOT_TYPES


def robots():
    """The entry point: the onboard records only."""
    new = four_ws_robot(dataclasses.replace(ROBOT_TYPES["4ws-5"], name="tracks"), family="tracked")
    old = four_ws_robot(
        dataclasses.replace(ROBOT_TYPES["4ws-5"], name="oldtracks"),
        family="",
        simulation="sim_bridge.four_ws.robot:simulated_robot",
        task="offline_evolution.maze_task.factories:kinematic_task",
        bridge="sim_bridge.four_ws.bridge:FourWSBridge",
    )
    return [new, old]
'''
TRACKS_SIM = '''\
"""The simulation's adapters of the "tracked" family (the sim layer imports this)."""

from sim_bridge.robots.adapters import SimAdapters

ADAPTERS = SimAdapters(
    simulation="sim_bridge.four_ws.robot:simulated_robot",
    bridge="sim_bridge.four_ws.bridge:FourWSBridge",
)
'''
TRACKS_SEARCH = '''\
"""The search's adapters of the "tracked" family (the search layer imports this)."""

from offline_evolution.maze_task.adapters import SearchAdapters


def adapters():
    """A callable entry point, as a registration's may be."""
    return SearchAdapters(task="offline_evolution.maze_task.factories:kinematic_task")
'''


def build_tracks(root: Path) -> Path:
    """Write and install evorbc-tracks; the folder to put on ``PYTHONPATH``."""
    src = root / "evorbc-tracks"
    package = src / "evorbc_tracks"
    package.mkdir(parents=True)
    (src / "pyproject.toml").write_text(TRACKS_PYPROJECT)
    (package / "__init__.py").write_text(TRACKS_MODULE)
    (package / "sim.py").write_text(TRACKS_SIM)
    (package / "search.py").write_text(TRACKS_SEARCH)
    return install(src, root / "site")
