"""Cost per run of every setting of the 4WS studies (issue: no setting is pathologically slow).

For each setting of the bin-size x evaluation-time grid (and, with ``--all``, the metrics
and mappings studies), on one numba thread:

* the repertoire at the Table I budget (10k + 1000 x 1000 evaluations): wall seconds,
  evaluations per second and the repertoire's size;
* arbitrator evolution with that repertoire: seconds per generation, measured over
  ``--generations`` generations after the first (which loads the compiled kernels), and
  the projected cost of the study's 1000-generation run.

Every setting runs the same work per evaluation apart from T (an evaluation simulates T s
of the kinematic model) and the archive (its cells grow as 1 / bin^2), so a setting whose
cost per run stands out of line with T is what to profile.

    python bench/bench_study_settings.py [--generations 5] [--all] [--only 0.01]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numba
from bench_repertoire import machine

from evorbc_ros.config import config_dir
from offline_evolution.arbitrator.evolve import EvolutionSettings, evolve, file_sha256
from offline_evolution.maze_task.task import MazeTaskSettings
from offline_evolution.repertoire.map_elites import generate_repertoire
from offline_evolution.repertoire.settings import load_settings
from offline_evolution.study.spec import load_study


def arbitrator_cost(repertoire, mapping: str, generations: int) -> float:
    """Seconds per generation of EvoRBC evolution (generation 0 left out)."""
    neat_file = config_dir() / "neat" / "4ws.ini"
    settings = EvolutionSettings(
        kind="evorbc",
        robot=repertoire.robot,
        generations=generations + 1,
        seed=1,
        neat_file=str(neat_file),
        neat_sha256=file_sha256(neat_file),
        task=MazeTaskSettings.load(config_dir() / "tasks" / "maze-4ws.yaml").as_dict(),
        mapping=mapping,
        repertoire_fingerprint=repertoire.fingerprint(),
    )
    result = evolve(settings, repertoire)
    return statistics.mean(h.seconds for h in result.history[1:])


def settings_of(study_names: list[str], only: str | None) -> list[dict]:
    """Distinct EvoRBC settings (values) of the studies, in file order."""
    seen, out = set(), []
    for name in study_names:
        for run in load_study(name).runs(seeds=1):
            if run.approach != "evorbc":
                continue
            values = {k: v for k, v in run.values.items() if k not in ("generations",)}
            key = tuple(sorted(values.items()))
            if key in seen or (only and only not in str(values.get("bin_size"))):
                continue
            seen.add(key)
            out.append(values)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--generations", type=int, default=5)
    parser.add_argument("--all", action="store_true", help="metrics and mappings too")
    parser.add_argument("--only", help="bin sizes whose text contains this (e.g. 0.01)")
    args = parser.parse_args()
    numba.set_num_threads(1)
    print(f"machine: {machine()}, load {os.getloadavg()[0]:.1f}; one numba thread")
    studies = ["bin-time", *(["metrics", "mappings"] if args.all else [])]
    print(
        "| setting | repertoire s | evaluations/s | primitives | s/generation "
        "| projected run (1000 gen.) |"
    )
    print("|---|---|---|---|---|---|")
    for values in settings_of(studies, args.only):
        keys = ("metric", "bin_size", "eval_time", "initial_batch", "batch_size", "iterations")
        overrides = {k: values[k] for k in keys if k in values}
        rep_settings = load_settings(robot=values.get("robot", "4ws-5"), seed=1, **overrides)
        start = time.perf_counter()
        repertoire = generate_repertoire(rep_settings)
        rep_s = time.perf_counter() - start
        evaluations = rep_settings.initial_batch + rep_settings.batch_size * rep_settings.iterations
        per_gen = arbitrator_cost(repertoire, values.get("mapping", "polar"), args.generations)
        label = ", ".join(f"{k}={v}" for k, v in values.items() if k not in ("robot", "approach"))
        print(
            f"| {label} | {rep_s:.1f} | {evaluations / rep_s:,.0f} | {len(repertoire)} "
            f"| {per_gen:.2f} | {(rep_s + 1000 * per_gen) / 60:.1f} min |",
            flush=True,
        )


if __name__ == "__main__":
    main()
