"""Benchmark: the generic loaders on big inputs (issue 39, docs/performance.md).

Prints three tables:
  * maze files of 1,000 to 20,000 walls (the shipped obstacle maze plus short posts): load
    and check with ``yaml.safe_load`` (the loader before) and with ``load_maze`` (now);
    time per wall should stay flat (linear); and the time to build the task's wall grid
    for the 4ws-5 sensors (each wall indexes only the cells near it: linear too);
  * one big YAML file (a 20,000-wall maze): ``yaml.safe_load``, pyyaml's C loader, and the
    strict loader (:func:`evorbc_ros.yaml_files.parse_yaml`);
  * a synthetic 200,000-primitive repertoire (18 genes, as the hexapod's): ``json.loads``
    with the number hook alone (the parser before), with the duplicate-key hook, the
    nesting walk alone, and :func:`evorbc_ros.json_files.parse_json` with every check.

Medians of ``--repeats``, in CPU seconds.
Run: ``.venv/bin/python -P bench/bench_hostile_inputs.py``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))  # run with -P: its siblings
from bench_repertoire import machine

from evorbc_ros.config import config_dir
from evorbc_ros.json_files import duplicate_key_hook, nesting_depth, parse_json
from evorbc_ros.yaml_files import parse_yaml
from sim_bridge.maze import load_maze, maze_from_dict

OBSTACLE = yaml.safe_load((config_dir() / "mazes" / "obstacle.yaml").read_text())


def timed(f, repeats: int) -> float:
    """Median CPU seconds of ``f()`` over ``repeats`` calls.

    CPU time, not wall time: the loaders run on one thread, and on a shared machine CPU
    time varies far less than wall time.
    """
    times = []
    for _ in range(repeats):
        start = time.process_time()
        f()
        times.append(time.process_time() - start)
    return statistics.median(times)


def maze_text(n: int) -> str:
    """The obstacle maze with ``n`` 5 cm posts added along its floor (a valid maze)."""
    x = np.linspace(-5.0, 5.0, n)
    posts = np.column_stack([x, np.full(n, -0.60), x, np.full(n, -0.55)]).round(6).tolist()
    return yaml.safe_dump({**OBSTACLE, "walls": OBSTACLE["walls"] + posts}, sort_keys=False)


def repertoire_text(n: int, genes: int = 18, seed: int = 0) -> str:
    """A repertoire-shaped JSON text of ``n`` primitives (columns, as the files have)."""
    rng = np.random.default_rng(seed)
    columns = {
        "genes": rng.uniform(-1, 1, (n, genes)).tolist(),
        "behaviour": rng.uniform(-0.4, 0.4, (n, 2)).tolist(),
        "heading": rng.uniform(-3, 3, n).tolist(),
        "quality": rng.uniform(0, 1, n).tolist(),
    }
    meta = {"format": "evorbc-repertoire", "version": 1, "archive": {"kind": "grid"}}
    return json.dumps({**meta, "primitives": columns})


#: The 4ws-5 task's grid reach (m): its sensors' reach plus a step and a margin.
GRID_REACH = 1.1


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=3)
    args = p.parse_args()
    r = args.repeats
    print(machine())

    print(
        "\n| walls | safe_load + checks (s) | load_maze (s) | load_maze per 1,000 walls (ms) "
        "| wall grid (s) |"
    )
    print("|---:|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        for n in (1_000, 2_500, 5_000, 10_000, 20_000):
            text = maze_text(n)
            path = Path(tmp) / f"m{n}.yaml"
            path.write_text(text)
            before = timed(lambda t=text: maze_from_dict(yaml.safe_load(t), "m.yaml"), r)
            after = timed(lambda p=path: load_maze(p), r)
            maze = load_maze(path)
            maze.wall_grid(GRID_REACH)  # compile the grid kernels before timing
            grid = timed(lambda m=maze: m.wall_grid(GRID_REACH), r)
            per = 1000 * after / n * 1000
            print(f"| {n:,} | {before:.2f} | {after:.3f} | {per:.1f} | {grid:.3f} |")

    text = maze_text(20_000)
    print(f"\nYAML, one file of {len(text) / 1e6:.1f} MB (a 20,000-wall maze)\n")
    print("| loader | seconds |")
    print("|---|---:|")
    for name, load in (
        ("yaml.safe_load (before)", yaml.safe_load),
        ("yaml.CSafeLoader (no checks)", lambda t: yaml.load(t, Loader=yaml.CSafeLoader)),
        ("parse_yaml (now: the checks)", lambda t: parse_yaml(t, "m.yaml", ValueError)),
    ):
        print(f"| {name} | {timed(lambda load=load: load(text), r):.2f} |")

    text = repertoire_text(200_000)
    hook = {"parse_int": lambda digits: int(digits)}  # a Python call, as parse_json's
    data = json.loads(text)
    print(f"\nJSON, a 200,000-primitive repertoire of {len(text) / 1e6:.0f} MB\n")
    print("| parse | seconds |")
    print("|---|---:|")
    for name, f in (
        ("json.loads + number hook (before)", lambda: json.loads(text, **hook)),
        (
            "+ duplicate-key hook",
            lambda: json.loads(text, **hook, object_pairs_hook=duplicate_key_hook([])),
        ),
        ("nesting walk alone", lambda: nesting_depth(data)),
        ("parse_json (now: every check)", lambda: parse_json(text, "r.json", "r", ValueError)),
    ):
        print(f"| {name} | {timed(f, r):.2f} |")


if __name__ == "__main__":
    main()
