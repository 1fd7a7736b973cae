"""The repertoires and arbitrators shipped for robots (``evorbc_ros/data`` for built-ins).

They are produced by the offline CLI with the commands and seeds recorded in
``evorbc_ros/data/README.md``; the ROS nodes use them when no file is given. Which robot
ships which files is its registration's business (``shipped_repertoire`` and
``shipped_arbitrator``, :mod:`evorbc_ros.robots.registry`): relative paths are in
``evorbc_ros/data``, a plugin gives absolute ones.
"""

from __future__ import annotations

from pathlib import Path

from evorbc_ros.robots import registry
from evorbc_ros.robots.registry import DEFAULT_ROBOT

DATA_DIR = Path(__file__).resolve().parent / "data"


def _shipped(robot: str, kind: str) -> Path:
    """The shipped ``kind`` file of ``robot``.

    For a robot that ships none, the path it would have in ``evorbc_ros/data``, which does
    not exist, so loading it says so.
    """
    name = getattr(registry.lookup(robot), f"shipped_{kind}") or f"{robot}.{kind}.json"
    path = Path(name)
    return path if path.is_absolute() else DATA_DIR / path


def default_repertoire(robot: str = DEFAULT_ROBOT) -> Path:
    """The shipped repertoire file for ``robot``."""
    return _shipped(robot, "repertoire")


def default_arbitrator(robot: str = DEFAULT_ROBOT) -> Path:
    """The shipped EvoRBC arbitrator file for ``robot``."""
    return _shipped(robot, "arbitrator")


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
