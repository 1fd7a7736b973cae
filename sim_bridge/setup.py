"""The ``sim_bridge`` ROS 2 package for colcon (ament_python); pip uses ../pyproject.toml.

Name, version and licence come from package.xml; the bridge node, the recorder,
``evorbc-sim`` and ``evorbc-play`` are installed to ``lib/sim_bridge`` for ``ros2 run``
(setup.cfg; docs/design.md section 10).
"""

import re
from pathlib import Path

from setuptools import find_packages, setup

PACKAGE = "sim_bridge"
manifest = (Path(__file__).parent / "package.xml").read_text(encoding="utf-8")

setup(
    name=PACKAGE,
    version=re.search(r"<version>(.*?)</version>", manifest).group(1),
    license=re.search(r"<license>(.*?)</license>", manifest).group(1),
    packages=find_packages(include=[PACKAGE, f"{PACKAGE}.*"]),
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
    ],
    zip_safe=False,
    entry_points={
        "console_scripts": [
            f"{PACKAGE} = {PACKAGE}.bridge_node:main",
            f"recorder = {PACKAGE}.recorder:main",
            f"evorbc-sim = {PACKAGE}.bringup:main",
            f"evorbc-play = {PACKAGE}.player:main",
        ],
    },
)
