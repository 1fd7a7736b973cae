"""Benchmark: a profile's wall time per stage, from a URDF or a robot file to a controller.

Runs ``evorbc-evolve from-robot SOURCE --out DIR --profile PROFILE`` (resuming what DIR
holds), then prints each stage's wall and CPU time from ``DIR/recipe-times.json`` (summed
over the runs that resumed it), the repertoire's evaluations per second, and the load
average before and after: other jobs on the machine slow every figure. Then, unless
``--no-evaluate``, the controller's reach rate on random starts in its own maze and on
held-out generated mazes (``evorbc-evolve evaluate``; docs/your-robot.md, "The quick
path", records the figures).

    python bench/bench_profiles.py pybullet_data:a1/a1.urdf --out runs/a1-quick
        [--profile quick|full] [--starts 20] [--held-out 10] [--held-out-starts 5]
        [--budget full|small] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

from offline_evolution.recipes.profiles import is_urdf

EVOLVE = [sys.executable, "-P", "-m", "offline_evolution.cli"]


def stage_times(out: Path) -> dict:
    """{step: {"wall_s", "cpu_s", "runs"}} of the run in ``out`` (recipe-times.json)."""
    path = out / "recipe-times.json"
    return json.loads(path.read_text()) if path.is_file() else {}


def repertoire_figures(out: Path) -> dict:
    """The repertoire the run wrote: evaluations, primitives, and how far its primitives
    go in the evaluation time T (m: median and 90th percentile of the displacement, the
    largest forward one), which bounds how fast an arbitrator can cross a maze."""
    for path in sorted(out.glob("*.repertoire.json")):
        data = json.loads(path.read_text())
        behaviour = data["primitives"]["behaviour"]
        reach = sorted(math.hypot(x, y) for x, y in behaviour)
        return {
            "evaluations": data["algorithm"].get("evaluations"),
            "primitives": len(reach),
            "eval_time_s": data["eval_time"],
            "displacement_p50_m": round(reach[len(reach) // 2], 3),
            "displacement_p90_m": round(reach[int(0.9 * (len(reach) - 1))], 3),
            "forward_max_m": round(max(x for x, _ in behaviour), 3),
        }
    return {}


def reach(arbitrator: Path, robot_path: str, extra: list[str]) -> dict:
    """``evaluate --json`` of ``arbitrator`` with ``extra`` options: its overall figures
    (episodes, reached, reach rate and its 95 % interval, falls, stalls)."""
    env = {**os.environ, "EVORBC_ROBOT_PATH": robot_path}
    cmd = [*EVOLVE, "evaluate", "--arbitrator", str(arbitrator), "--json", *extra]
    done = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if done.returncode:
        raise SystemExit(f"evaluate failed: {done.stderr.strip()}")
    overall = json.loads(done.stdout)["overall"]
    keys = ("episodes", "reached", "reach_rate", "reach_interval", "falls", "stalls")
    return {k: overall[k] for k in keys}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("source", help="a URDF (or pybullet_data:PATH) or a robot settings file")
    p.add_argument("--out", required=True, type=Path, help="the run's folder (resumed)")
    p.add_argument("--profile", choices=("quick", "full"), default="quick")
    p.add_argument("--starts", type=int, default=20, help="random starts in its own maze")
    p.add_argument("--held-out", type=int, default=10, help="held-out generated mazes")
    p.add_argument("--held-out-starts", type=int, default=5, help="starts per held-out maze")
    p.add_argument("--budget", choices=("full", "small"), default="full", help="small: a check")
    p.add_argument("--no-evaluate", action="store_true")
    p.add_argument("--json", type=Path, help="also write the figures here")
    args = p.parse_args(argv)

    load0 = os.getloadavg()
    started = time.perf_counter()
    cmd = [*EVOLVE, "from-robot", args.source, "--out", str(args.out), "--profile", args.profile]
    subprocess.run([*cmd, "--quiet", "--budget", args.budget], check=True)
    figures = {
        "source": args.source,
        "profile": args.profile,
        "machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores",
        "load_before": load0,
        "load_after": os.getloadavg(),
        "this_run_wall_s": round(time.perf_counter() - started, 1),
        "stages": stage_times(args.out),
        "repertoire": repertoire_figures(args.out),
    }
    rep, made = figures["stages"].get("repertoire"), figures["repertoire"]
    if rep and made.get("evaluations"):
        figures["evaluations_per_s"] = round(made["evaluations"] / rep["wall_s"], 1)
    print(f"{args.source} at the {args.profile} profile ({figures['machine']})")
    total = 0.0
    for step, t in figures["stages"].items():
        total += t["wall_s"]
        print(f"  {step:12s} {t['wall_s'] / 60:7.1f} min wall {t['cpu_s'] / 60:7.1f} min CPU")
    load = f"load {load0[0]:.1f} -> {os.getloadavg()[0]:.1f}"
    print(f"  {'total':12s} {total / 60:7.1f} min wall; {load}")
    if not args.no_evaluate:
        arbitrator = next(args.out.glob("*.arbitrator.json"))
        # Where the robot is declared: made from a URDF, or the robot file's folder.
        urdf = is_urdf(args.source)
        robots = str(args.out / "robots" if urdf else Path(args.source).resolve().parent)
        own = ["--starts", str(args.starts), "--mazes", "paper"]
        held = ["--generated", str(args.held_out), "--starts", str(args.held_out_starts)]
        figures["own_maze"] = reach(arbitrator, robots, own)
        figures["held_out"] = reach(arbitrator, robots, held)
        print(f"  own maze: {figures['own_maze']}; held out: {figures['held_out']}")
    if args.json:
        args.json.write_text(json.dumps(figures, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
