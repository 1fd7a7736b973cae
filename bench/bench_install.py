"""Benchmark: from nothing to the first wheel command, as a wheel and as a colcon workspace.

Wheel (a new user's ``pip install``): build the wheel, make a fresh venv, ``pip install
evorbc-*.whl[ros,sim]`` with pip's cache off (what a fresh machine downloads), then start
the five nodes the way ``ros2 run`` does (``<prefix>/lib/<package>/<node>``, found in the
ament index) and time the first command on ``wheel_velocity_controller/commands``.

colcon: copy the repository into ``src/`` of a new workspace, ``colcon build`` (and, in a
second workspace, ``--symlink-install``), then the same start-up from the workspace.

Run: ``.venv/bin/python bench/bench_install.py``.
"""

from __future__ import annotations

import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Float64MultiArray

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT / "tests"))
from install_helpers import clean_env  # noqa: E402
from test_install_colcon import checkout  # noqa: E402

NODES = [
    ("evorbc_ros", "laser_sensor"),
    ("evorbc_ros", "radar_sensor"),
    ("evorbc_ros", "arbitrator"),
    ("evorbc_ros", "primitive_executor"),
    ("sim_bridge", "sim_bridge"),
]


def timed(cmd, env, cwd) -> float:
    """Wall seconds of a command that must succeed."""
    t0 = time.monotonic()
    subprocess.run(cmd, env=env, cwd=cwd, check=True, capture_output=True, timeout=1800)
    return time.monotonic() - t0


def first_command(prefix_of, env, cwd, domain: int) -> float:
    """s from starting the five node executables to the first wheel command."""
    context = Context()
    rclpy.init(context=context, domain_id=domain)
    probe = Node("bench_probe", context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(probe)
    got = []
    probe.create_subscription(
        Float64MultiArray, "wheel_velocity_controller/commands", got.append, 10
    )
    env = {**env, "ROS_DOMAIN_ID": str(domain)}
    t0 = time.monotonic()
    procs = [
        subprocess.Popen(
            [f"{prefix_of(pkg)}/lib/{pkg}/{exe}", "--ros-args", "-p", "use_sim_time:=true"]
            if pkg == "evorbc_ros"
            else [f"{prefix_of(pkg)}/lib/{pkg}/{exe}"],
            env=env,
            cwd=cwd,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        for pkg, exe in NODES
    ]
    try:
        while not got and time.monotonic() - t0 < 300:
            executor.spin_once(timeout_sec=0.01)
        return time.monotonic() - t0
    finally:
        for p in procs:
            p.send_signal(2)
        for p in procs:
            p.wait(30)
        context.try_shutdown()


def wheel(tmp: Path) -> None:
    """Build, install into a fresh venv without pip's cache, run."""
    env = clean_env(0)
    dist = tmp / "dist"
    t_wheel = timed(
        [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", ROOT, "-w", dist], env, tmp
    )
    venv = tmp / "venv"
    t_venv = timed([sys.executable, "-m", "venv", venv], env, tmp)
    whl = next(dist.glob("evorbc-*.whl"))
    pip = [venv / "bin" / "python", "-m", "pip", "install", "-q", "--no-cache-dir"]
    t_install = timed([*pip, f"{whl}[ros,sim]"], env, tmp)
    run_env = {**env, "AMENT_PREFIX_PATH": str(venv), "PATH": f"{venv}/bin:{env['PATH']}"}
    t_first = first_command(lambda pkg: str(venv), run_env, tmp, 160)
    print(
        f"wheel: build {t_wheel:.1f} s, venv {t_venv:.1f} s, pip install [ros,sim] "
        f"(no cache) {t_install:.1f} s; start-up to the first command {t_first:.1f} s; "
        f"total {t_wheel + t_venv + t_install + t_first:.1f} s"
    )


def colcon(tmp: Path, symlink: bool, domain: int) -> None:
    """Build a workspace with colcon, run from it."""
    ws = tmp / ("ws-symlink" if symlink else "ws")
    checkout(ws / "src" / "evorbc")
    colcon_exe = str(Path(sys.executable).parent / "colcon")
    extra = ["--symlink-install"] if symlink else []
    t_build = timed([colcon_exe, "build", *extra], clean_env(0), ws)
    setup = ws / "install" / "setup.bash"
    dump = subprocess.run(
        ["bash", "-c", f"source {shlex.quote(str(setup))} && env -0"],
        env=clean_env(0),
        capture_output=True,
        check=True,
    ).stdout.split(b"\0")
    env = dict(kv.decode().split("=", 1) for kv in dump if b"=" in kv)
    env["PATH"] = f"{Path(sys.executable).parent}:{env['PATH']}"
    t_first = first_command(lambda pkg: str(ws / "install" / pkg), env, tmp, domain)
    kind = "colcon build --symlink-install" if symlink else "colcon build"
    print(f"{kind}: {t_build:.1f} s; start-up to the first command {t_first:.1f} s")


def main() -> None:
    sys.path.insert(0, str(HERE))
    from bench_repertoire import machine

    print(f"machine: {machine()}")
    with tempfile.TemporaryDirectory() as tmp:
        wheel(Path(tmp))
        colcon(Path(tmp), False, 161)
        colcon(Path(tmp), True, 162)
    shutil.rmtree(ROOT / "build", ignore_errors=True)  # pip wheel's in-tree build folder


if __name__ == "__main__":
    main()
