"""Benchmark: MAP-Elites repertoire generation for the kinematic robots (Table I budget).

Prints, for this machine and ``--robot`` (4ws-5, or any compiled-path robot such as
turtlebot3-burger, the differential-drive robot from config/robots/):
  * the full Table I run (10k + 1000 x 1000 = 1.01M evaluations of 2 s):
    wall time, evaluations per second and peak memory (max RSS of the process);
  * where the time goes (evaluation, archive insertion, mutation, metric);
  * how the throughput grows with the batch size and the run time with the number of
    evaluations.

Run: ``.venv/bin/python bench/bench_repertoire.py`` (``--quick`` for a short version,
``--robot turtlebot3-burger`` for the differential-drive robot).
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import subprocess
import sys
import time

import numba

from offline_evolution.repertoire.map_elites import MapElites, generate_repertoire
from offline_evolution.repertoire.settings import load_settings


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            names = [line.split(":", 1)[1].strip() for line in f if line.startswith("model name")]
        cpu = names[0] if names else cpu
    except OSError:
        pass
    return (
        f"{cpu}, {os.cpu_count()} cores, numba {numba.__version__} "
        f"({numba.get_num_threads()} threads), Python {platform.python_version()}"
    )


#: The robot measured (``--robot``).
ROBOT = "4ws-5"


def timed_run(**overrides) -> tuple[float, object]:
    settings = load_settings(robot=overrides.pop("robot", ROBOT), **overrides)
    start = time.perf_counter()
    rep = generate_repertoire(settings)
    return time.perf_counter() - start, rep


def breakdown(settings) -> dict[str, float]:
    """Seconds spent in each part of the loop over one full run."""
    run = MapElites(settings)
    parts = {
        "mutation (ask)": 0.0,
        "evaluation (motion model)": 0.0,
        "quality metric": 0.0,
        "archive insertion (pyribs) and bounds": 0.0,
    }
    while not run.finished:
        t0 = time.perf_counter()
        genes = run.emitter.ask()
        t1 = time.perf_counter()
        outcome = run.robot.evaluate_primitives(genes, settings.eval_time)
        t2 = time.perf_counter()
        run.metric(outcome)  # timed alone; tell() scores the batch again
        t3 = time.perf_counter()
        run.tell(genes, outcome)
        t4 = time.perf_counter() - (t3 - t2)  # tell() scores again: count that once
        for key, dt in zip(parts, (t1 - t0, t2 - t1, t3 - t2, t4 - t3), strict=True):
            parts[key] += dt
    return parts


def cold_cli_run() -> float:
    """Wall time of the whole CLI command in a fresh process (imports and JIT cache load)."""
    out = "/tmp/evorbc-bench-repertoire.json"
    start = time.perf_counter()
    subprocess.run(
        [
            sys.executable,
            "-m",
            "offline_evolution.cli",
            "repertoire",
            "--robot",
            ROBOT,
            "--seed",
            "1",
            "--out",
            out,
            "--quiet",
        ],
        check=True,
        stdout=subprocess.DEVNULL,
    )
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="skip the scaling sweeps")
    parser.add_argument("--robot", default="4ws-5", help="robot measured (default: 4ws-5)")
    args = parser.parse_args()
    global ROBOT
    ROBOT = args.robot
    print(f"machine: {machine()}")
    timed_run(iterations=2)  # compile / load the JIT cache outside the measurements

    full = load_settings(robot=ROBOT, seed=1)
    wall, rep = timed_run(seed=1)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    s = rep.summary()
    print(
        f"\nfull Table I run, {ROBOT}: {full.evaluations:,} evaluations of {full.eval_time:g} s "
        f"in {wall:.2f} s = {full.evaluations / wall / 1e3:.0f}k evaluations/s "
        f"({full.evaluations * full.eval_time / 0.1 / wall / 1e6:.1f}M robot steps/s); "
        f"{s['count']} primitives, mean quality {s['mean_quality']:.3f}"
    )
    print(f"peak memory (max RSS of this process, imports included): {rss:.0f} MiB")
    print(f"whole CLI command in a fresh process: {cold_cli_run():.2f} s")

    parts = breakdown(full)
    total = sum(parts.values())
    print("\nwhere the time goes (one full run):")
    for key, dt in parts.items():
        print(f"  {key:<28} {dt:6.2f} s  {100 * dt / total:5.1f} %")

    if args.quick:
        return
    print("\nthroughput against batch size (about 400k evaluations each):")
    for batch in (100, 300, 1000, 3000, 10000):
        iterations = max(1, 400_000 // batch)
        wall, _ = timed_run(seed=1, batch_size=batch, iterations=iterations)
        n = 10_000 + batch * iterations
        print(f"  batch {batch:>6}: {n / wall / 1e3:6.0f}k evaluations/s")
    print("\nwall time against evaluations (batch 1000):")
    for iterations in (250, 500, 1000, 2000):
        wall, _ = timed_run(seed=1, iterations=iterations)
        n = 10_000 + 1000 * iterations
        print(f"  {n:>9,} evaluations: {wall:6.2f} s ({n / wall / 1e3:.0f}k/s)")
    threads = numba.get_num_threads()
    print("\nthreads (full run):")
    for t in sorted({1, threads}):
        numba.set_num_threads(t)
        wall, _ = timed_run(seed=1)
        print(f"  {t} thread(s): {wall:.2f} s")
    numba.set_num_threads(threads)


if __name__ == "__main__":
    main()
