"""Each ROS package's manifest declares what its code imports, and no more (docs/design.md s. 10).

rosdep installs a package's dependencies from its ``package.xml``: an import that the
manifest leaves out fails only on a robot that lacks it, and a dependency in a circle stops
colcon. The imports are read from the source (``ast``), so a new import without its
manifest line fails here.
"""

import ast
import sys
import tomllib
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: The ROS packages: folder with package.xml -> the Python files that run as that package.
PACKAGES = {
    "evorbc_ros": ROOT / "evorbc_ros",
    "sim_bridge": ROOT / "sim_bridge",
    "evorbc_bringup": ROOT / "launch",
}
#: Python distributions -> their rosdep keys (ros/rosdistro rosdep/python.yaml).
ROSDEP = {
    "numpy": "python3-numpy",
    "scipy": "python3-scipy",
    "yaml": "python3-yaml",
    "matplotlib": "python3-matplotlib",
    "PIL": "python3-pil",
    "numba": "python3-numba",
    "pybullet": "python3-pybullet-pip",
    "pybullet_data": "python3-pybullet-pip",
    "rosbags": "python3-rosbags-pip",
}
#: Optional imports (pip extras that rosdep has no key for): they must sit in a
#: ``try``/``except ImportError`` that tells the user which extra to install.
OPTIONAL = {"ray": "cluster"}


def code_files(package: str) -> list[Path]:
    """The Python files installed as ``package``: its modules, or its launch files."""
    folder = PACKAGES[package]
    if package == "evorbc_bringup":
        return sorted(folder.glob("*.launch.py"))
    return sorted((folder / package).rglob("*.py"))


def imported(files: list[Path]) -> tuple[set[str], set[str]]:
    """Top-level names imported by ``files``: (required, optional behind ImportError)."""
    required, optional = set(), set()
    for path in files:
        tree = ast.parse(path.read_text(encoding="utf-8"))
        guarded = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.Try) and any(
                isinstance(h.type, ast.Name) and h.type.id in ("ImportError", "ModuleNotFoundError")
                for h in node.handlers
            ):
                guarded |= {id(n) for stmt in node.body for n in ast.walk(stmt)}
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                names = {a.name.split(".")[0] for a in node.names}
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = {node.module.split(".")[0]}
            else:
                continue
            (optional if id(node) in guarded else required).update(names)
    stdlib = sys.stdlib_module_names
    return {n for n in required if n not in stdlib}, {n for n in optional if n not in stdlib}


def declared(package: str) -> set[str]:
    manifest = ET.parse(PACKAGES[package] / "package.xml").getroot()
    assert manifest.findtext("name") == package
    return {e.text for tag in ("depend", "exec_depend") for e in manifest.iter(tag)}


def rosdep_keys(names: set[str], package: str) -> set[str]:
    """ROS packages (messages, rclpy, ours) are their own keys; Python ones map."""
    return {ROSDEP.get(n, n) for n in names if n != package}


@pytest.mark.parametrize("package", sorted(PACKAGES))
def test_the_manifest_declares_every_import(package):
    required, _ = imported(code_files(package))
    unmapped = {n for n in required if n.islower() and "_" not in n and n not in ROSDEP}
    # A Python distribution without a rosdep key here would pass as its own key; name it.
    assert unmapped <= {"rclpy", "launch"}, f"add a rosdep key for {unmapped}"
    assert rosdep_keys(required, package) <= declared(package)


@pytest.mark.parametrize("package", sorted(PACKAGES))
def test_the_manifest_declares_nothing_the_code_does_not_use(package):
    required, _ = imported(code_files(package))
    used = rosdep_keys(required, package)
    if package == "evorbc_bringup":
        # The launch file starts the nodes of the packages the graph names.
        from sim_bridge.graph import graph_from_arguments

        used |= {spec.package for spec in graph_from_arguments({}).nodes}
    if package == "sim_bridge":
        # The recorder imports the message types it records by name.
        from sim_bridge.graph import RECORDED

        used |= {t.split("/")[0] for t in RECORDED.values()}
    assert declared(package) <= used


def test_optional_imports_are_guarded_and_name_their_extra():
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
        "optional-dependencies"
    ]
    for package in PACKAGES:
        required, optional = imported(code_files(package))
        assert not required & set(OPTIONAL), f"{package} imports an optional module unguarded"
        for name in optional:
            assert name in OPTIONAL, f"{package}: {name} is guarded but not a known extra"
            assert any(d.startswith(name) for d in extras[OPTIONAL[name]])


def test_no_dependency_circle_between_the_ros_packages():
    ours = {p: declared(p) & set(PACKAGES) for p in PACKAGES}
    assert ours == {
        "evorbc_ros": set(),
        "sim_bridge": {"evorbc_ros"},
        "evorbc_bringup": {"evorbc_ros", "sim_bridge"},
    }


def test_every_manifest_has_the_project_version():
    version = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    for package in PACKAGES:
        manifest = ET.parse(PACKAGES[package] / "package.xml").getroot()
        assert manifest.findtext("version") == version, package
        assert manifest.find("export/build_type").text == "ament_python"


def test_the_onboard_package_imports_no_simulation_or_plotting():
    required, optional = imported(code_files("evorbc_ros"))
    assert not (required | optional) & {"sim_bridge", "offline_evolution", "matplotlib"}
    assert not (required | optional) & {"numba", "pybullet", "ray"}
