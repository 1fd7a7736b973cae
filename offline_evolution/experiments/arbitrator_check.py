"""Check arbitrator evolution against the paper (Sec. IV-D, Fig. 9): EvoRBC vs standard NEAT.

For each robot and seed: a Table I repertoire (seeded like the run), an EvoRBC arbitrator
(polar mapping, circular metric, 4 cm bins, T = 2 s) and a standard-NEAT controller with the
equal-budget extra generations. Reports per robot and method the best training fitness
(mean +- sd over seeds), how many runs' best genome reached the target in every maze, the
post-evaluated controller's reach, and a two-sided Mann-Whitney U test of EvoRBC against
standard NEAT; draws Fig. 9-style fitness curves.

Runs are files in ``OUT/runs``: a finished run is skipped, an interrupted one resumes from
its checkpoint, so the whole experiment can be stopped and restarted.

Run: ``python -m offline_evolution.experiments.arbitrator_check --seeds 5 --out docs``
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
from scipy.stats import mannwhitneyu

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.atomic_io import atomic_write_text
from evorbc_ros.controller_kinds import EVORBC, KINDS, STANDARD, ControllerKind
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.registry import lookup
from offline_evolution.arbitrator.evolve import (
    EvolutionSettings,
    arbitrator_file,
    evolve,
    file_sha256,
)
from offline_evolution.arbitrator.settings import load_run_settings
from offline_evolution.maze_task.task import MazeTask, MazeTaskSettings
from offline_evolution.repertoire.map_elites import generate_repertoire
from offline_evolution.repertoire.settings import load_settings

METHODS = tuple(KINDS.values())

#: Random starts per maze, and their seed, for the per-maze robustness table.
ROBUST_EPISODES = 20
ROBUST_SEED = 100


def run_one(robot: str, kind: ControllerKind, seed: int, generations: int, runs: Path) -> dict:
    """One evolution run (or its saved result)."""
    out = runs / f"{robot}-{kind.name}-seed{seed}.json"
    if out.exists():
        return json.loads(out.read_text())["evolution"]
    run = load_run_settings(robot=robot)
    task_settings = MazeTaskSettings.load(run.task_path())
    repertoire = None
    if kind.uses_repertoire:
        rep_path = runs / f"{robot}-repertoire-seed{seed}.json"
        if rep_path.exists():
            repertoire = Repertoire.load(rep_path)
        else:
            repertoire = generate_repertoire(load_settings(robot=robot, seed=seed))
            repertoire.save(rep_path)
    else:
        generations += lookup(robot).equal_budget_generations
    neat_file = run.neat_path()
    settings = EvolutionSettings(
        kind=kind,
        robot=robot,
        generations=generations,
        seed=seed,
        neat_file=str(neat_file),
        neat_sha256=file_sha256(neat_file),
        task=task_settings.as_dict(),
        mapping=run.mapping if kind.uses_repertoire else None,
        repertoire_fingerprint=repertoire.fingerprint() if repertoire else None,
        **run.selection(),
    )
    start = time.perf_counter()
    result = evolve(
        settings,
        repertoire,
        checkpoint=out.with_suffix(".checkpoint.json"),
        checkpoint_every=run.checkpoint_every,
    )
    task = MazeTask(task_settings, robot)
    arbitrator_file(
        result,
        task,
        repertoire,
        str(runs / f"{robot}-repertoire-seed{seed}.json") if repertoire else None,
    ).save(out)
    print(
        f"{robot} {kind.name} seed {seed}: best fitness {result.best_fitness:.3f}, reached "
        f"{result.best_reached}/{task.n_mazes}, post {result.post_evaluation.fitness:.3f}, "
        f"{(time.perf_counter() - start) / 60:.1f} min",
        flush=True,
    )
    return json.loads(out.read_text())["evolution"]


def finished_seeds(robots, seeds, runs: Path) -> list[int]:
    """The seeds whose runs (every robot, both methods) are all done."""
    return [
        s
        for s in seeds
        if all((runs / f"{r}-{m.name}-seed{s}.json").exists() for r in robots for m in METHODS)
    ]


def summarise(robots, seeds, generations, runs: Path, out: Path) -> str:
    """Aggregate the runs into a Markdown table and a fitness-curve picture per robot."""
    from offline_evolution.plots.fitness import plot_fitness_comparison

    extra = " or ".join(sorted({str(lookup(r).equal_budget_generations) for r in robots}))
    lines = [
        f"Generations: {generations} for EvoRBC, {generations} + "
        f"{extra} for standard NEAT (equal budget); seeds "
        f"{', '.join(map(str, seeds))}.",
        "",
        "| robot | method | best fitness (mean ± sd) | runs whose best genome reached all 5 "
        "mazes | post-evaluated controller: fitness / reach | Mann-Whitney U p (two-sided) |",
        "|---|---|---|---|---|---|",
    ]
    for robot in robots:
        evo = {m: [run_one(robot, m, s, generations, runs) for s in seeds] for m in METHODS}
        best = {m: np.array([e["best_fitness"] for e in evo[m]]) for m in METHODS}
        p = mannwhitneyu(best[EVORBC], best[STANDARD], alternative="two-sided").pvalue
        for m in METHODS:
            n_mazes = len(evo[m][0]["task"]["mazes"])
            all_reached = sum(e["best_reached"] == n_mazes for e in evo[m])
            post_fit = np.mean([e["post_evaluation"]["fitness"] for e in evo[m]])
            post_reach = np.mean([e["post_evaluation"]["reached"] for e in evo[m]])
            lines.append(
                f"| {robot} | {m.label} | {best[m].mean():.3f} ± {best[m].std(ddof=1):.3f} | "
                f"{all_reached} of {len(seeds)} | {post_fit:.3f} / {post_reach:.0%} | "
                f"{p:.4f} |"
            )
        plot_fitness_comparison(
            {m.label: [[h["best"] for h in e["history"]] for e in evo[m]] for m in METHODS},
            out / f"arbitrator-check-{robot}.png",
            title=f"{robot}: highest fitness so far",
        )
    lines += ["", *per_maze_table(robots, seeds, runs)]
    text = "\n".join(lines) + "\n"
    atomic_write_text(out / "arbitrator-check.md", text)
    return text


def per_maze_table(robots, seeds, runs: Path) -> list[str]:
    """Markdown: each run's selected controller over random starts, per maze.

    Every controller runs from ``ROBUST_EPISODES`` random starts per maze (seed
    ``ROBUST_SEED``, apart from training and post-evaluation); a cell is the mean eq. 5
    fitness over the seeds' controllers and, in brackets, the share of episodes that
    reached the target.
    """
    from offline_evolution.maze_task.replay import replay, summarise_outcomes

    header = None
    rows = []
    for robot in robots:
        task_settings = MazeTaskSettings.load(load_run_settings(robot=robot).task_path())
        task = MazeTask(task_settings, robot)
        rng = np.random.default_rng(ROBUST_SEED)
        starts = np.concatenate([task.sample_starts(rng) for _ in range(ROBUST_EPISODES)])
        names = [m.name for m in task.mazes]
        header = header or names
        for kind in METHODS:
            fitness = np.zeros((len(seeds), len(names)))
            reached = np.zeros_like(fitness)
            for i, seed in enumerate(seeds):
                arb = ArbitratorFile.load(runs / f"{robot}-{kind.name}-seed{seed}.json")
                rep = (
                    Repertoire.load(runs / f"{robot}-repertoire-seed{seed}.json")
                    if kind.uses_repertoire
                    else None
                )
                outcomes, _ = replay(arb, task, starts, rep)
                per_maze = {row["maze"]: row for row in summarise_outcomes(outcomes)}
                for k, name in enumerate(names):
                    row = per_maze[name]
                    fitness[i, k] = row["mean_fitness"]
                    reached[i, k] = row["reached"] / row["episodes"]
            means = zip(fitness.mean(0), reached.mean(0), strict=True)
            cells = [f"{f:.2f} ({r:.0%})" for f, r in means]
            rows.append(
                f"| {robot} | {kind.label} | {' | '.join(cells)} | "
                f"{fitness.mean():.2f} ({reached.mean():.0%}) |"
            )
    return [
        f"Selected controllers from {ROBUST_EPISODES} random starts per maze (seed "
        f"{ROBUST_SEED}): mean fitness over the seeds (share of episodes that reached the "
        "target).",
        "",
        f"| robot | method | {' | '.join(header)} | all |",
        "|---|---|" + "---|" * (len(header) + 1),
        *rows,
    ]


def main() -> None:
    """Command-line entry point."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--robots", nargs="+", default=["4ws-5", "2ws-2"])
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument(
        "--generations",
        type=int,
        default=None,
        help="default: Table I (config/arbitrator/4ws.yaml)",
    )
    parser.add_argument("--out", type=Path, default=Path("docs"))
    parser.add_argument(
        "--summarise-only",
        action="store_true",
        help="only tabulate the seeds whose runs are all done",
    )
    args = parser.parse_args()
    generations = args.generations or load_run_settings(robot=args.robots[0]).generations
    runs = args.out / "runs"
    runs.mkdir(parents=True, exist_ok=True)
    seeds = list(range(1, args.seeds + 1))
    if args.summarise_only:
        seeds = finished_seeds(args.robots, seeds, runs)
        if len(seeds) < 2:
            raise SystemExit(f"{runs}: fewer than two seeds are finished")
    for seed in seeds:  # seed-major, so every method has results early
        for robot in args.robots:
            for kind in METHODS:
                run_one(robot, kind, seed, generations, runs)
    print(summarise(args.robots, seeds, generations, runs, args.out))


if __name__ == "__main__":
    main()
