"""Installed with pip, the package registers itself in the ament index (docs/design.md section 10).

``ros2 run evorbc_ros <node>`` looks up ``share/ament_index/resource_index/packages/
evorbc_ros`` under ``AMENT_PREFIX_PATH`` and runs ``<prefix>/lib/evorbc_ros/<node>``. This
builds the wheel, installs it into a fresh prefix and checks both the index and the
executables, without the ros2 CLI; with it, ``ros2 run`` itself is tried too.
"""

import os
import py_compile
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EVORBC_NODES = ["laser_sensor", "radar_sensor", "arbitrator", "primitive_executor"]


@pytest.fixture(scope="module")
def prefix(tmp_path_factory):
    """The project installed (no dependencies) into an empty prefix."""
    out = tmp_path_factory.mktemp("prefix")
    wheels = tmp_path_factory.mktemp("wheel")
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", str(ROOT), "-w", str(wheels)],
        check=True,
        timeout=300,
        capture_output=True,
    )
    wheel = next(wheels.glob("evorbc-*.whl"))
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "install",
            "-q",
            "--no-deps",
            "--ignore-installed",  # never touch the test environment's own install
            "--prefix",
            str(out),
            str(wheel),
        ],
        check=True,
        timeout=300,
        capture_output=True,
    )
    return out


def assert_startup_error(stderr: str, node: str, message: str) -> None:
    """The node's last line is its logger's one-line start-up error, and no traceback."""
    assert "Traceback" not in stderr
    last = stderr.strip().splitlines()[-1]
    pattern = rf"\[FATAL\] \[[0-9.]+\] \[{node}\]: cannot start: {re.escape(message)}"
    assert re.fullmatch(pattern, last), last


def site_packages(prefix: Path) -> Path:
    return next(prefix.glob("lib/python3*/site-packages"))


def installed_env(prefix: Path) -> dict:
    """The installed copy first on the path, the test venv's interpreter as python3."""
    return dict(
        os.environ,
        AMENT_PREFIX_PATH=str(prefix),
        PYTHONPATH=str(site_packages(prefix)),
        PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}",
        ROS_AUTOMATIC_DISCOVERY_RANGE="OFF",
    )


@pytest.mark.slow
def test_the_ament_index_finds_both_packages(prefix, tmp_path):
    script = (
        "from ament_index_python.packages import get_package_prefix, "
        "get_package_share_directory as share\n"
        "print(get_package_prefix('evorbc_ros')); print(share('evorbc_ros')); "
        "print(share('sim_bridge'))"
    )
    out = subprocess.run(
        [sys.executable, "-c", script],
        env=installed_env(prefix),
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
        cwd=tmp_path,
    ).stdout.split()
    assert out == [
        str(prefix),
        str(prefix / "share" / "evorbc_ros"),
        str(prefix / "share" / "sim_bridge"),
    ]
    share = prefix / "share" / "evorbc_ros"
    assert (share / "package.xml").read_text().count("<name>evorbc_ros</name>") == 1
    assert (share / "launch" / "sim.launch.py").exists()
    for rel in (
        "config/ros/evorbc_nodes.yaml",
        "config/sensors/4ws.yaml",
        "config/mazes/obstacle.yaml",
        "config/neat/4ws.ini",
    ):
        assert (share / rel).exists(), rel


@pytest.mark.parametrize("node", EVORBC_NODES)
def test_every_node_is_an_executable_in_lib(prefix, node):
    exe = prefix / "lib" / "evorbc_ros" / node
    assert exe.is_file() and os.access(exe, os.X_OK)


def test_an_installed_node_starts_and_reports_bad_files(prefix, tmp_path):
    exe = prefix / "lib" / "evorbc_ros" / "arbitrator"
    missing = tmp_path / "missing.json"
    done = subprocess.run(
        [str(exe), "--ros-args", "-p", f"arbitrator:={missing}"],
        env=installed_env(prefix),
        capture_output=True,
        text=True,
        timeout=120,
        cwd=tmp_path,
    )
    assert done.returncode == 2, done.stderr
    assert_startup_error(done.stderr, "arbitrator", f"{missing}: no such arbitrator file")
    # It ran the installed copy, whose settings come from the prefix's share folder.
    script = "from evorbc_ros.config import config_dir; print(config_dir())"
    where = subprocess.run(
        [sys.executable, "-c", script],
        env=installed_env(prefix),
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
        cwd=tmp_path,
    ).stdout
    assert where.strip() == str(prefix / "share" / "evorbc_ros" / "config")


def test_sim_bridge_is_registered_too(prefix):
    exe = prefix / "lib" / "sim_bridge" / "sim_bridge"
    assert exe.is_file() and os.access(exe, os.X_OK)


def test_the_launch_file_is_valid_python():
    py_compile.compile(str(ROOT / "launch" / "sim.launch.py"), doraise=True)


needs_ros2 = pytest.mark.skipif(
    shutil.which("ros2") is None, reason="needs the ros2 CLI (full ROS 2)"
)


@needs_ros2
def test_ros2_run_finds_the_arbitrator(prefix, tmp_path):
    missing = tmp_path / "missing.json"
    done = subprocess.run(
        ["ros2", "run", "evorbc_ros", "arbitrator", "--ros-args", "-p", f"arbitrator:={missing}"],
        env=installed_env(prefix),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert "no such arbitrator file" in done.stderr


@needs_ros2
def test_the_launch_file_builds_a_description(prefix):
    script = (
        "import runpy; d = runpy.run_path('launch/sim.launch.py')"
        "['generate_launch_description'](); print(len(d.entities))"
    )
    done = subprocess.run(
        [sys.executable, "-c", script],
        cwd=ROOT,
        env=installed_env(prefix),
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0 and int(done.stdout) == 10


def graph_env(prefix: Path, domain: int) -> dict:
    """The installed copy, with discovery on this machine (the nodes must find each other)."""
    return {
        **installed_env(prefix),
        "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
        "ROS_DOMAIN_ID": str(domain),
        "PYTHONUNBUFFERED": "1",
    }


def ros2_launch(prefix, domain, *args, timeout=300) -> str:
    """``ros2 launch evorbc_ros sim.launch.py ARGS``: its whole output, once it ended itself."""
    done = subprocess.run(
        ["ros2", "launch", "evorbc_ros", "sim.launch.py", *args],
        env=graph_env(prefix, domain),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        timeout=timeout,
    )
    assert done.returncode == 0, done.stdout
    assert "Traceback" not in done.stdout
    return done.stdout


@needs_ros2
def test_ros2_launch_shows_every_argument_with_its_description(prefix):
    from sim_bridge.graph import ARGUMENTS

    out = ros2_launch(prefix, 170, "--show-args", timeout=60)
    for a in ARGUMENTS:
        assert f"'{a.name}':\n        {a.description}\n        (default: '{a.default}')" in out


@needs_ros2
def test_ros2_launch_runs_an_episode_in_a_namespace_and_then_shuts_the_graph_down(prefix):
    out = ros2_launch(prefix, 171, "maze:=zigzag", "namespace:=robot1", "paper:=true")
    # The paper-protocol controller, as offline (evorbc_ros/data/README.md: zigzag 86.0 s, 1.283).
    assert "[robot1.sim_bridge]: reached the target in 86.0 s; fitness 1.283" in out
    assert re.search(r"process\[sim_bridge-\d\] was required: shutting down", out)
    assert out.count("process has finished cleanly") == 5


@needs_ros2
def test_ros2_launch_refuses_a_controller_for_another_robot_and_ends(prefix):
    arb = site_packages(prefix) / "evorbc_ros" / "data" / "4ws-5.arbitrator.json"
    out = ros2_launch(prefix, 172, "robot:=4ws-3", f"arbitrator:={arb}", timeout=120)
    assert (
        f"[arbitrator]: cannot start: {arb}: is a controller for robot 4ws-5, "
        "but parameter robot is 4ws-3"
    ) in out
    assert "sim_bridge]: t =" not in out  # the graph shut down before any episode ran


@needs_ros2
def test_ros2_param_set_refuses_read_only_and_ros2_topic_pub_goals_arrive(prefix):
    env = graph_env(prefix, 173)
    node = subprocess.Popen(
        ["ros2", "run", "evorbc_ros", "radar_sensor"],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,  # its own group: Ctrl-C reaches ros2 run and the node
    )
    try:

        def ros2(*args):
            cmd = ["ros2", *args]
            return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=60)

        cli = ("--no-daemon", "--spin-time", "2")
        deadline = time.monotonic() + 60
        done = ros2("param", "set", *cli, "/radar_sensor", "goal_type", "pose")
        while "Node not found" in done.stderr and time.monotonic() < deadline:  # starting
            done = ros2("param", "set", *cli, "/radar_sensor", "goal_type", "pose")
        assert done.stderr.strip() == (
            "Setting parameter failed: Trying to set a read-only parameter: goal_type."
        )
        done = ros2("param", "get", *cli, "/radar_sensor", "goal_type")
        assert done.stdout.strip() == "String value is: point"
        goal = "{header: {frame_id: odom}, point: {x: 1.5, y: -0.5}}"
        done = ros2(
            "topic", "pub", "--once", "-w", "1", "goal", "geometry_msgs/msg/PointStamped", goal
        )
        assert done.returncode == 0, done.stderr
        time.sleep(1.0)
    finally:
        for _ in range(2):  # Ctrl-C twice, as ros2 launch run from a script does
            os.killpg(node.pid, signal.SIGINT)
            time.sleep(0.05)
        out = node.communicate(timeout=30)[0]
    assert node.returncode == 0, out
    assert "goal (1.500, -0.500) in frame 'odom'" in out
    assert "Traceback" not in out and "incompatible QoS" not in out
