"""evorbc as pip installs it: a built wheel in a fresh venv, run from outside the checkout.

The wheel carries the settings and the shipped controllers as package data, registers its
three ROS packages in the ament index of the venv's prefix, and puts one executable per
node in ``<prefix>/lib/<package>`` (docs/design.md section 10). Every node, ``ros2 run``
and ``ros2 launch`` (with the ros2 CLI) and the console scripts must work with their
defaults; an sdist must build the same wheel. (``pip install .`` builds this same wheel
first and installs it.)
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import tarfile
import time
import zipfile
from pathlib import Path

import pytest
from install_helpers import (
    NODES,
    ROOT,
    assert_fatal_line,
    clean_env,
    reached,
    run,
    start_and_stop,
    wait_for_node,
)

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    """The wheel built from the checkout, as ``pip wheel .`` makes it."""
    out = tmp_path_factory.mktemp("dist")
    pip = [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-cache-dir"]
    run([*pip, ROOT, "-w", out], env=clean_env(0), cwd=out)
    return next(out.glob("evorbc-*.whl"))


@pytest.fixture(scope="module")
def venv(wheel, tmp_path_factory):
    """A fresh venv with the wheel and the extras a roboticist installs (pip's cache reused)."""
    where = tmp_path_factory.mktemp("venv") / "venv"
    run([sys.executable, "-m", "venv", where], env=clean_env(0), cwd=where.parent)
    pip = [where / "bin" / "python", "-m", "pip", "install", "-q", "--disable-pip-version-check"]
    run([*pip, f"{wheel}[ros,sim,evolution]"], env=clean_env(0), cwd=where.parent, timeout=900)
    ros2 = os.environ.get(ROS2_WHEELS)
    if ros2:  # the ros2 CLI and launch, built from their sources (not on PyPI; docs/ros.md)
        run([*pip, "-r", Path(ros2) / "requirements.txt"], clean_env(0), where.parent)
        run([*pip, "--no-deps", *Path(ros2).glob("*.whl")], clean_env(0), where.parent)
    return where


#: A folder of wheels of the ros2 CLI and launch (and a requirements.txt of what they
#: need), installed into the venv when set, for the tests that need them.
ROS2_WHEELS = "EVORBC_TEST_ROS2_WHEELS"


def venv_env(venv, domain: int) -> dict:
    """A shell that activated the venv and set AMENT_PREFIX_PATH to it (docs/ros.md)."""
    env = clean_env(domain, VIRTUAL_ENV=str(venv), AMENT_PREFIX_PATH=str(venv))
    env["PATH"] = f"{venv / 'bin'}:{env['PATH']}"
    return env


def executable(venv, package: str, name: str, tmp_path):
    """What ``ros2 run PACKAGE NAME`` runs: found through the venv's ament index."""
    script = (
        f"from ament_index_python.packages import get_package_prefix as p; print(p('{package}'))"
    )
    env = venv_env(venv, 0)
    prefix = run([venv / "bin" / "python", "-c", script], env=env, cwd=tmp_path).stdout.strip()
    return f"{prefix}/lib/{package}/{name}"


def test_the_wheel_holds_the_settings_controllers_and_ros_files(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    data = "evorbc-0.1.0.data/data/"
    for path in (
        "evorbc_ros/settings/robots/4ws.yaml",
        "evorbc_ros/settings/ros/arbitrator.yaml",
        "evorbc_ros/settings/mazes/obstacle.yaml",
        "evorbc_ros/settings/neat/4ws.ini",
        "evorbc_ros/data/4ws-5.arbitrator.json",
        f"{data}share/evorbc_bringup/launch/sim.launch.py",
        f"{data}lib/evorbc_ros/arbitrator",
        f"{data}share/ament_index/resource_index/packages/sim_bridge",
    ):
        assert path in names, path
    # The colcon-only files stay out of the Python packages.
    assert not {n for n in names if n.endswith(("setup.py", "setup.cfg", "package.xml"))} - {
        f"{data}share/{p}/package.xml" for p in ("evorbc_ros", "sim_bridge", "evorbc_bringup")
    }


def test_an_sdist_builds_the_same_wheel(wheel, tmp_path):
    run([sys.executable, "-m", "build", "--sdist", "-o", tmp_path, ROOT], clean_env(0), tmp_path)
    sdist = next(tmp_path.glob("evorbc-*.tar.gz"))
    with tarfile.open(sdist) as tar:
        assert any(n.endswith("evorbc_ros/settings/robots/4ws.yaml") for n in tar.getnames())
    out = tmp_path / "from-sdist"
    pip = [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-cache-dir"]
    run([*pip, sdist, "-w", out], clean_env(0), tmp_path)
    again = next(out.glob("evorbc-*.whl"))

    def listing(path):
        return {
            (i.filename, i.CRC)
            for i in zipfile.ZipFile(path).infolist()
            if ".dist-info/" not in i.filename
        }

    assert listing(again) == listing(wheel)


def test_the_ament_index_finds_the_three_packages(venv, tmp_path):
    script = (
        "from ament_index_python.packages import get_package_share_directory as s\n"
        "for p in ('evorbc_ros', 'sim_bridge', 'evorbc_bringup'): print(s(p))"
    )
    out = run([venv / "bin" / "python", "-c", script], venv_env(venv, 0), tmp_path).stdout
    assert out.split() == [
        str(venv / "share" / p) for p in ("evorbc_ros", "sim_bridge", "evorbc_bringup")
    ]


@pytest.mark.parametrize(("package", "name", "bad", "message"), NODES)
def test_every_node_starts_with_its_defaults_and_stops_on_ctrl_c(
    venv, package, name, bad, message, tmp_path
):
    domain = 190 + [n[1] for n in NODES].index(name)
    exe = executable(venv, package, name, tmp_path)
    start_and_stop([exe], name, domain, venv_env(venv, domain), tmp_path)


@pytest.mark.parametrize(("package", "name", "bad", "message"), NODES)
def test_every_node_refuses_a_bad_setting_in_one_fatal_line(
    venv, package, name, bad, message, tmp_path
):
    exe = executable(venv, package, name, tmp_path)
    env = venv_env(venv, 0) | {"ROS_AUTOMATIC_DISCOVERY_RANGE": "OFF"}
    done = run([exe, "--ros-args", "-p", bad], env, tmp_path, timeout=120, check=False)
    assert_fatal_line(done, name, message)


def test_the_recorder_records_only_what_it_is_told(venv, tmp_path):
    exe = executable(venv, "sim_bridge", "recorder", tmp_path)
    env = venv_env(venv, 0) | {"ROS_AUTOMATIC_DISCOVERY_RANGE": "OFF"}
    done = run([exe], env, tmp_path, timeout=120, check=False)
    assert_fatal_line(done, "recorder", "parameter bag must name the bag folder to create")


def test_the_console_scripts_work_with_their_defaults(venv, tmp_path):
    env = venv_env(venv, 0)
    rep = tmp_path / "r.json"
    small = ("--initial-batch", "200", "--batch-size", "50", "--iterations", "4")
    run(["evorbc-evolve", "repertoire", "--robot", "4ws-5", *small, "--out", rep], env, tmp_path)
    assert rep.is_file()
    shipped = next((venv / "lib").glob("python3*/site-packages/evorbc_ros/data"))
    arb = shipped / "4ws-5.arbitrator.json"
    out = run(["evorbc-evolve", "replay", "--arbitrator", arb, "--maze", "obstacle"], env, tmp_path)
    assert "obstacle" in out.stdout
    # The shipped 4ws-5 controller by default, from two seeded random starts.
    out = run(["evorbc-evolve", "evaluate", "--mazes", "gaps", "--starts", "2"], env, tmp_path)
    assert "gaps" in out.stdout


def test_evorbc_sim_drives_the_shipped_controller_to_the_target(venv, tmp_path):
    out = run(["evorbc-sim", "--maze", "gaps"], venv_env(venv, 195), tmp_path).stdout
    reached(out)


def needs_ros2(venv):
    if not (venv / "bin" / "ros2").exists():
        pytest.skip(f"needs the ros2 CLI and launch: set {ROS2_WHEELS}")


def test_ros2_run_and_ros2_launch_from_the_wheel(venv, tmp_path):
    needs_ros2(venv)
    env = venv_env(venv, 196)
    done = run(
        ["ros2", "run", "evorbc_ros", "arbitrator", "--ros-args", "-p", NODES[2][2]],
        env,
        tmp_path,
        check=False,
    )
    assert_fatal_line(done, "arbitrator", NODES[2][3])
    out = run(["ros2", "launch", "evorbc_bringup", "sim.launch.py", "maze:=gaps"], env, tmp_path)
    assert "reached the target" in out.stdout + out.stderr
    # A refused node fails the launch, naming why.
    shipped = next((venv / "lib").glob("python3*/site-packages/evorbc_ros/data"))
    other = f"arbitrator:={shipped / '4ws-5.arbitrator.json'}"
    done = run(
        ["ros2", "launch", "evorbc_bringup", "sim.launch.py", "robot:=4ws-3", other],
        env,
        tmp_path,
        check=False,
    )
    out = done.stdout + done.stderr
    assert done.returncode == 1, out
    assert "cannot configure: " in out and "but parameter robot is 4ws-3" in out
    assert "reached the target" not in out


def test_ros2_lifecycle_param_and_diagnostics_from_the_wheel(venv, tmp_path):
    needs_ros2(venv)
    env = venv_env(venv, 193)

    def ros2(*args):
        return run(["ros2", *args], env, tmp_path, timeout=120, check=False)

    def until(check, *args):
        """``ros2 ARGS`` until ``check(output)``: the CLI may not see a new node at once."""
        deadline = time.monotonic() + 60
        done = ros2(*args)
        while not check(done.stdout) and time.monotonic() < deadline:
            done = ros2(*args)
        assert check(done.stdout), done.stdout + done.stderr
        return done

    node = subprocess.Popen(
        ["ros2", "run", "evorbc_ros", "arbitrator"],
        env=env,
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
    )
    try:
        wait_for_node("arbitrator", 193, node)
        until(lambda out: out.strip() == "active [3]", "lifecycle", "get", "/arbitrator")
        described = until(
            lambda out: "Min value: 0.1" in out,
            "param",
            "describe",
            "/arbitrator",
            "diagnostics_period",
        ).stdout
        assert "Max value: 60.0" in described
        shipped = next((venv / "lib").glob("python3*/site-packages/evorbc_ros/settings"))
        loaded = ros2("param", "load", "/arbitrator", str(shipped / "ros" / "arbitrator.yaml"))
        assert loaded.returncode == 0 and "failed" not in loaded.stdout + loaded.stderr
        assert "Set parameter robot successful" in loaded.stdout
        assert ros2("lifecycle", "set", "/arbitrator", "deactivate").returncode == 0
        until(lambda out: out.strip() == "inactive [2]", "lifecycle", "get", "/arbitrator")
        echo = ros2("topic", "echo", "--once", "/diagnostics")
        assert "name: /arbitrator" in echo.stdout and "value: inactive" in echo.stdout
    finally:
        os.killpg(node.pid, signal.SIGINT)
        out = node.communicate(timeout=30)[0]
        ros2("daemon", "stop")  # the CLI started one for this domain
    assert node.returncode == 0 and "Traceback" not in out, out
