"""The repertoires and arbitrators shipped with the package (``evorbc_ros/data``).

They are produced by the offline CLI with the commands and seeds recorded in
``evorbc_ros/data/README.md``; the ROS nodes use them when no file is given.
"""

from __future__ import annotations

from pathlib import Path

DATA_DIR = Path(__file__).resolve().parent / "data"


def default_repertoire(robot: str = "4ws-5") -> Path:
    """The shipped repertoire file for ``robot``."""
    return DATA_DIR / f"{robot}.repertoire.json"


def default_arbitrator(robot: str = "4ws-5") -> Path:
    """The shipped EvoRBC arbitrator file for ``robot``."""
    return DATA_DIR / f"{robot}.arbitrator.json"


def shipped_robots() -> list[str]:
    """The robots a controller (arbitrator and repertoire) ships for, e.g. 4ws-5 and hexapod."""
    return sorted(
        p.name.removesuffix(".arbitrator.json") for p in DATA_DIR.glob("*.arbitrator.json")
    )


def no_shipped_controller(robot: str) -> str:
    """One phrase: no controller ships for ``robot``, and the commands that make one."""
    return (
        f"no controller ships for robot {robot} (only for {' and '.join(shipped_robots())}); "
        f"make one with 'evorbc-evolve repertoire --robot {robot} --seed 1 --out r.json' and "
        "'evorbc-evolve arbitrator --repertoire r.json --seed 1 --out a.json'"
    )
