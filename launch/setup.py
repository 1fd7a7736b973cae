"""The ``evorbc_bringup`` ROS 2 package for colcon (ament_python): launch files only.

It depends on both ``evorbc_ros`` and ``sim_bridge``, so neither depends on the other's
launch file (as nav2_bringup does for nav2); pip installs the same files through
../pyproject.toml (docs/design.md section 10).
"""

import re
from pathlib import Path

from setuptools import setup

PACKAGE = "evorbc_bringup"
manifest = (Path(__file__).parent / "package.xml").read_text(encoding="utf-8")

setup(
    name=PACKAGE,
    version=re.search(r"<version>(.*?)</version>", manifest).group(1),
    license=re.search(r"<license>(.*?)</license>", manifest).group(1),
    packages=[],
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
        (f"share/{PACKAGE}/launch", ["sim.launch.py"]),
    ],
    zip_safe=False,
)
