"""evorbc in a colcon workspace: the repository under ``src/``, built by colcon from PyPI.

colcon finds the three ROS packages (evorbc_ros, sim_bridge, evorbc_bringup), orders them by
their manifests, and builds them with ``colcon build`` and with ``--symlink-install``.
After ``source install/setup.bash`` the installed copies are the ones imported, the
settings are found beside them as in any other install (docs/design.md section 10), and
the nodes, ``evorbc-sim`` and (with the ros2 CLI) ``ros2 run`` / ``ros2 launch`` work.
"""

from __future__ import annotations

import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from install_helpers import (
    NODES,
    ROOT,
    assert_fatal_line,
    clean_env,
    needs_ros2,
    reached,
    run,
)

pytestmark = pytest.mark.slow

ORDER = ["evorbc_ros", "sim_bridge", "evorbc_bringup"]


def checkout(where: Path) -> None:
    """Copy the repository's files (tracked, and new ones not ignored) as a clone has them."""
    names = subprocess.run(
        ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        cwd=ROOT,
        capture_output=True,
        check=True,
    ).stdout.split(b"\0")
    for name in filter(None, names):
        source, target = ROOT / name.decode(), where / name.decode()
        if not source.exists() and not source.is_symlink():
            continue  # deleted in the working tree
        target.parent.mkdir(parents=True, exist_ok=True)
        if source.is_symlink():
            target.symlink_to(source.readlink())
        else:
            shutil.copy2(source, target)


def colcon(*args) -> list[str]:
    """colcon, from the environment running the tests."""
    return [str(Path(sys.executable).parent / "colcon"), *args]


@pytest.fixture(scope="module")
def source_tree(tmp_path_factory):
    """A workspace folder with the repository in ``src/evorbc``."""
    ws = tmp_path_factory.mktemp("ws")
    checkout(ws / "src" / "evorbc")
    return ws


@pytest.fixture(scope="module", params=["copy", "symlink"])
def workspace(request, source_tree, tmp_path_factory):
    """The workspace built one way: ``colcon build`` or ``colcon build --symlink-install``."""
    ws = tmp_path_factory.mktemp(request.param)
    (ws / "src").symlink_to(source_tree / "src")
    extra = ["--symlink-install"] if request.param == "symlink" else []
    run(colcon("build", *extra), clean_env(0), ws, timeout=600)
    return ws


def in_workspace(ws: Path, command: str, domain: int = 0, check=True):
    """``source install/setup.bash`` and run ``command`` (bash) from outside the checkout.

    ``python3`` is the one with ROS 2 (rclpy, the messages), as on a robot's computer: the
    one running the tests.
    """
    env = clean_env(domain)
    env["PATH"] = f"{Path(sys.executable).parent}:{env['PATH']}"
    script = f"source {shlex.quote(str(ws / 'install' / 'setup.bash'))} && {command}"
    return run(script, env, ws.parent, timeout=300, check=check)


def test_colcon_lists_the_three_packages_in_dependency_order(source_tree):
    out = run(colcon("list", "--topological-order"), clean_env(0), source_tree).stdout
    rows = [line.split("\t") for line in out.strip().splitlines()]
    assert [r[0] for r in rows] == ORDER
    assert {r[2] for r in rows} == {"(ros.ament_python)"}
    assert [r[1] for r in rows] == [
        "src/evorbc/evorbc_ros",
        "src/evorbc/sim_bridge",
        "src/evorbc/launch",
    ]


def test_the_workspace_copies_are_imported_with_their_settings(workspace):
    script = (
        "import evorbc_ros, sim_bridge; from evorbc_ros.config import config_dir; "
        "print(evorbc_ros.__file__); print(sim_bridge.__file__); "
        "print((config_dir() / 'robots' / '4ws.yaml').is_file())"
    )
    out = in_workspace(workspace, f"python3 -c {shlex.quote(script)}").stdout.split()
    where = str(workspace) if workspace.name.startswith("copy") else str(workspace / "src")
    resolved = [str(Path(p).resolve()) for p in out[:2]]
    assert all(p.startswith(str(Path(where).resolve())) for p in resolved), out
    assert out[2] == "True"


def lib_executable(package: str, name: str) -> str:
    """``lib/PACKAGE/NAME`` under the package's prefix, as ``ros2 run PACKAGE NAME`` finds it."""
    find = f"from ament_index_python.packages import get_package_prefix as p; print(p('{package}'))"
    return f'"$(python3 -c {shlex.quote(find)})/lib/{package}/{name}"'


@pytest.mark.parametrize(("package", "name", "bad", "message"), NODES)
def test_each_node_runs_from_lib_and_refuses_a_bad_setting(workspace, package, name, bad, message):
    command = f"{lib_executable(package, name)} --ros-args -p {bad}"
    done = in_workspace(workspace, f"ROS_AUTOMATIC_DISCOVERY_RANGE=OFF {command}", check=False)
    assert_fatal_line(done, name, message)


def test_evorbc_sim_from_the_workspace_reaches_the_target(workspace):
    domain = 197 if workspace.name.startswith("copy") else 198
    out = in_workspace(
        workspace, f"{lib_executable('sim_bridge', 'evorbc-sim')} --maze gaps", domain
    )
    reached(out.stdout)


@needs_ros2
def test_ros2_run_and_ros2_launch_from_the_workspace(workspace):
    domain = 199
    done = in_workspace(
        workspace, f"ros2 run evorbc_ros arbitrator --ros-args -p {NODES[2][2]}", check=False
    )
    assert_fatal_line(done, "arbitrator", NODES[2][3])
    out = in_workspace(workspace, "ros2 launch evorbc_bringup sim.launch.py maze:=gaps", domain)
    assert "reached the target" in out.stdout + out.stderr
