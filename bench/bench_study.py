"""Throughput of the same small study: serial, local processes, and Ray clusters on localhost.

    python bench/bench_study.py [--runs 6] [--generations 20]

Runs one small study (2ws-2 EvoRBC runs with a small repertoire budget) four ways, each into
a fresh results folder, and prints runs per hour and the wall time:

* serial: ``evorbc-study run --jobs 1``;
* local: ``--jobs 2`` (the embedded default on a 2-core machine: one run per core);
* Ray, one node with 2 CPUs: ``--address``;
* Ray, two nodes with 1 CPU each (a head and a worker on localhost).

All four give identical results (checked); on one 2-core machine the Ray clusters can only
show their overhead against the local runner, not more throughput.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import platform
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

RAY = str(Path(sys.executable).with_name("ray"))
STUDY = """
study: bench
seeds: {runs}
grid:
  approach: [evorbc]
fixed:
  robot: 2ws-2
  initial_batch: 2000
  batch_size: 200
  iterations: 50
  generations: {generations}
"""


def _port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_cluster(cpus_per_node: list[int]) -> tuple[str, list[int], Path]:
    """Start a head (and workers) on localhost; returns the address, process groups, temp."""
    temp = Path(tempfile.mkdtemp(prefix="raybn", dir="/tmp"))
    port = _port()
    env = dict(os.environ, RAY_USAGE_STATS_ENABLED="0")
    groups = []
    for k, cpus in enumerate(cpus_per_node):
        args = [f"--num-cpus={cpus}", "--object-store-memory=100000000"]
        if k == 0:
            args += ["--head", f"--port={port}", "--include-dashboard=false", f"--temp-dir={temp}"]
        else:
            args += [f"--address=127.0.0.1:{port}"]
        proc = subprocess.Popen(
            [RAY, "start", *args],
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        proc.wait(timeout=120)
        groups.append(proc.pid)
    return f"127.0.0.1:{port}", groups, temp


def stop_cluster(groups: list[int], temp: Path) -> None:
    for g in groups:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(g, signal.SIGKILL)
    shutil.rmtree(temp, ignore_errors=True)


def run(study: Path, results: Path, *options: str) -> float:
    """Wall seconds of one ``evorbc-study run``."""
    t0 = time.perf_counter()
    subprocess.run(
        [
            sys.executable,
            "-m",
            "offline_evolution.study.cli",
            "run",
            str(study),
            "--results",
            str(results),
            *options,
        ],
        check=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env=dict(os.environ, RAY_USAGE_STATS_ENABLED="0"),
    )
    return time.perf_counter() - t0


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=6)
    p.add_argument("--generations", type=int, default=20)
    args = p.parse_args()
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from study_helpers import results_contents

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        study = tmp / "bench.yaml"
        study.write_text(STUDY.format(runs=args.runs, generations=args.generations))
        times = {}
        times["serial (--jobs 1)"] = run(study, tmp / "serial", "--jobs", "1")
        times["local processes (--jobs 2)"] = run(study, tmp / "local", "--jobs", "2")
        for label, nodes in (("Ray, 1 node x 2 CPUs", [2]), ("Ray, 2 nodes x 1 CPU", [1, 1])):
            address, groups, temp = start_cluster(nodes)
            try:
                times[label] = run(study, tmp / label.replace(" ", "_"), "--address", address)
            finally:
                stop_cluster(groups, temp)
        reference = results_contents(tmp / "serial")
        same = all(
            results_contents(tmp / name) == reference
            for name in ["local", *(lbl.replace(" ", "_") for lbl in list(times)[2:])]
        )
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} cores, Python "
        f"{platform.python_version()}; {args.runs} runs of {args.generations} generations"
    )
    print(f"{'runner':28s} {'wall s':>8s} {'runs/hour':>10s}")
    for label, seconds in times.items():
        print(f"{label:28s} {seconds:8.1f} {args.runs * 3600 / seconds:10.0f}")
    print(f"results identical to the serial run: {same}")


if __name__ == "__main__":
    main()
