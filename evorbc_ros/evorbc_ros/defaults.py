"""The repertoires and arbitrators shipped for robots (``evorbc_ros/data`` for built-ins).

They are produced by the offline CLI with the commands and seeds recorded in
``evorbc_ros/data/README.md``; the ROS nodes use them when no file is given. Which robot
ships which files is its registration's business (``shipped_repertoire`` and
``shipped_arbitrator``, :mod:`evorbc_ros.robots.registry`): relative paths are in
``evorbc_ros/data``, a plugin gives absolute ones.

The shipped arbitrator is the robot's default controller. When that default is not the
paper protocol's (one trained on generated mazes, say), the registration's
``paper_arbitrator`` names the paper-protocol one, for the same repertoire: the paper
check and ``--paper`` (``evorbc-evolve evaluate``, ``evorbc-sim``) use
:func:`paper_arbitrator`.
"""

from __future__ import annotations

from pathlib import Path

from evorbc_ros.robots import registry
from evorbc_ros.robots.registry import DEFAULT_ROBOT

DATA_DIR = Path(__file__).resolve().parent / "data"
#: The error of ``--paper`` given with ``--arbitrator`` (evorbc-evolve evaluate, evorbc-sim).
PAPER_WITH_FILE = (
    "--paper and --arbitrator cannot be combined: --paper picks the paper-protocol "
    "controller shipped for --robot"
)


def _shipped(robot: str, kind: str) -> Path:
    """The shipped ``kind`` file of ``robot``.

    For a robot that ships none, the path it would have in ``evorbc_ros/data``, which does
    not exist, so loading it says so.
    """
    return _in_data(getattr(registry.lookup(robot), f"shipped_{kind}") or f"{robot}.{kind}.json")


def _in_data(name: str) -> Path:
    """``name`` if absolute, else in ``evorbc_ros/data``."""
    path = Path(name)
    return path if path.is_absolute() else DATA_DIR / path


def default_repertoire(robot: str = DEFAULT_ROBOT) -> Path:
    """The shipped repertoire file for ``robot``."""
    return _shipped(robot, "repertoire")


def default_arbitrator(robot: str = DEFAULT_ROBOT) -> Path:
    """The shipped EvoRBC arbitrator file for ``robot``."""
    return _shipped(robot, "arbitrator")


def paper_arbitrator(robot: str = DEFAULT_ROBOT) -> Path:
    """The paper-protocol arbitrator file for ``robot`` (trained on the paper's mazes only).

    Its registration's ``paper_arbitrator``, or the shipped arbitrator when that field is
    "" (the shipped one is the paper protocol's). Both go with :func:`default_repertoire`.
    """
    name = registry.lookup(robot).paper_arbitrator
    return _in_data(name) if name else default_arbitrator(robot)


def ships_controller(robot: str) -> bool:
    """True if a controller (arbitrator and repertoire) ships for ``robot``."""
    return bool(registry.lookup(robot).shipped_arbitrator)


def shipped_robots() -> list[str]:
    """The robots a controller ships for, e.g. 4ws-5 and hexapod (sorted)."""
    return sorted(r.name for r in registry.robots() if r.shipped_arbitrator)


def no_shipped_controller(robot: str) -> str:
    """One phrase: no controller ships for ``robot``, and the commands that make one."""
    *others, last = shipped_robots() or ["none"]
    listed = f"{', '.join(others)} and {last}" if others else last
    return (
        f"no controller ships for robot {robot} (only for {listed}); "
        f"make one with 'evorbc-evolve repertoire --robot {robot} --seed 1 --out r.json' and "
        "'evorbc-evolve arbitrator --repertoire r.json --seed 1 --out a.json'"
    )
