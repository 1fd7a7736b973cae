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
