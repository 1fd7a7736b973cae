"""The ``evorbc_ros`` ROS 2 package for colcon (ament_python); pip uses ../pyproject.toml.

Name, version and licence come from package.xml; the nodes are installed to
``lib/evorbc_ros`` for ``ros2 run`` (setup.cfg), the settings as package data
(docs/design.md section 10).
"""

import re
from pathlib import Path

from setuptools import find_packages, setup

PACKAGE = "evorbc_ros"
manifest = (Path(__file__).parent / "package.xml").read_text(encoding="utf-8")
NODES = ["laser_sensor", "radar_sensor", "arbitrator", "primitive_executor"]

setup(
    name=PACKAGE,
    version=re.search(r"<version>(.*?)</version>", manifest).group(1),
    license=re.search(r"<license>(.*?)</license>", manifest).group(1),
    packages=find_packages(include=[PACKAGE, f"{PACKAGE}.*"]),
    package_data={PACKAGE: ["data/*.json", "data/*.md", "settings/**/*"]},
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
    ],
    zip_safe=False,
    entry_points={
        "console_scripts": [f"{node} = {PACKAGE}.nodes.{node}:main" for node in NODES],
    },
)
