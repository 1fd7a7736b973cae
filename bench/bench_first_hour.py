"""Benchmark: what a new user waits for, from a fresh clone (README, "How long things take").

Clones this repository's committed HEAD into a temporary folder and times, there:

  * creating ``.venv`` and installing everything (``make .venv/.evorbc-installed``), with an
    empty pip cache, so downloads are included as on a new machine;
  * ``make demo`` twice: the first run includes numba compiling what it uses (compiled
    code is cached next to the sources, so a fresh clone has none);
  * ``make demo-repertoire`` twice (the first compiles MAP-Elites' kernel);
  * with ``--hexapod``, ``--evolve``, ``--test``: ``make demo-hexapod``, ``make
    demo-evolve`` and ``make test``;

and prints each time with the load average before and after it (other jobs on the machine
slow every figure), the size of ``.venv`` and the machine. The clone is deleted afterwards.

Run it with the system Python; it makes its own venv:
``python3 bench/bench_first_hour.py [--hexapod] [--evolve] [--test] [--ros-prefix CMD]``.
``--ros-prefix "ip netns exec NS"`` runs the steps that start ROS 2 nodes inside a network
namespace, so their DDS traffic stays apart from other graphs on the machine; the install
runs without it, since it needs the network.
"""

from __future__ import annotations

import argparse
import os
import platform
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def load() -> str:
    """The 1, 5 and 15 minute load averages."""
    return " ".join(f"{v:.1f}" for v in os.getloadavg())


def folder_size(path: Path) -> int:
    """Bytes of the regular files under ``path`` (links not followed)."""
    total = 0
    for dirpath, _, files in os.walk(path):
        for name in files:
            p = Path(dirpath, name)
            if not p.is_symlink():
                total += p.stat().st_size
    return total


def machine() -> str:
    cpu = platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            names = [line.split(":", 1)[1].strip() for line in f if line.startswith("model name")]
        cpu = names[0] if names else cpu
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}"


def step(name: str, command: list[str], cwd: Path, env: dict, log: Path) -> None:
    """Run ``command`` in ``cwd`` with its output in ``log``; print its time and the load."""
    before = load()
    start = time.perf_counter()
    with open(log, "w") as out:
        rc = subprocess.run(command, cwd=cwd, env=env, stdout=out, stderr=subprocess.STDOUT)
    seconds = time.perf_counter() - start
    status = "" if rc.returncode == 0 else f"  FAILED (status {rc.returncode}, see {log})"
    print(f"{name:<34} {seconds:8.1f} s   load {before} -> {load()}{status}", flush=True)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--hexapod", action="store_true", help="also time make demo-hexapod")
    p.add_argument("--evolve", action="store_true", help="also time make demo-evolve")
    p.add_argument("--test", action="store_true", help="also time make test")
    p.add_argument("--ros-prefix", default="", help="prefix for steps that start ROS nodes")
    p.add_argument(
        "--logs",
        default="",
        help="keep the steps' output in this folder (default: deleted with the clone)",
    )
    args = p.parse_args()
    ros = shlex.split(args.ros_prefix)
    print(f"machine: {machine()}")
    head = subprocess.check_output(["git", "rev-parse", "HEAD"], cwd=ROOT, text=True).strip()
    print(f"commit:  {head} (uncommitted changes are not measured)")
    with tempfile.TemporaryDirectory(prefix="evorbc-first-hour-") as tmp:
        clone = Path(tmp) / "evorbc"
        logs = Path(args.logs) if args.logs else Path(tmp) / "logs"
        logs.mkdir(parents=True, exist_ok=True)
        subprocess.run(["git", "clone", "--quiet", str(ROOT), str(clone)], check=True)
        env = dict(os.environ, PIP_CACHE_DIR=str(Path(tmp) / "pip-cache"))
        steps = [("install (.venv, downloads)", ["make", ".venv/.evorbc-installed"])]
        steps += [(f"make demo ({k})", [*ros, "make", "demo"]) for k in ("first", "again")]
        steps += [
            (f"make demo-repertoire ({k})", ["make", "demo-repertoire"]) for k in ("first", "again")
        ]
        if args.hexapod:
            steps.append(("make demo-hexapod", [*ros, "make", "demo-hexapod"]))
        if args.evolve:
            steps.append(("make demo-evolve", ["make", "demo-evolve"]))
        if args.test:
            steps.append(("make test", [*ros, "make", "test"]))
        for k, (name, command) in enumerate(steps):
            step(name, command, clone, env, logs / f"{k}-{Path(command[-1]).name}.log")
            if k == 0:
                size = folder_size(clone / ".venv")
                print(f"{'.venv size':<34} {size / 1e9:8.2f} GB", flush=True)
        shutil.rmtree(clone, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
