"""EvoRBC against standard NEAT for a legged robot; for the hexapod, against the paper.

The paper's hexapod experiment (Sec. V-B and V-C), and the same comparison for any legged
robot of the registry (the A1: docs/a1.md). Given one repertoire of the robot (made by
``evorbc-evolve repertoire --robot ROBOT``), runs through the CLI, so every run is a
command a user can repeat:

* EvoRBC arbitrators for seeds 1..N (the robot's run settings, or ``--config``; the
  hexapod's are Table I: 200 generations, polar mapping);
* standard NEAT for seed 1..M with as many generations more as ``--standard-extra`` says
  (default: the robot's equal budget, 200 + 455 for the hexapod).

Then reports, next to the paper's values where the paper has any: the repertoire's size,
quality and left/right symmetry; EvoRBC's best fitness (mean +- sd), how many runs reached
the goal and the first generation that did; how far standard NEAT got (eq. 5 fitness, 1 -
d_final/d_initial when it does not arrive, also at EvoRBC's budget of generations, and how
far along the maze its controller walks); how often the selected arbitrator switches
primitive; and how large the written networks are. The fitness curves of the finished runs
(paper Fig. 17) go beside the table as a picture (``OUT/ROBOT-check.md`` and ``.png``).

Every run checkpoints as it goes and resumes when the experiment is started again;
finished runs are skipped. A standard run that has not finished (655 generations outlast
a working session) is reported from its checkpoint: how far it has got and its best
fitness so far, also at EvoRBC's budget of generations.

Run: ``python -m offline_evolution.experiments.legged_check --robot ROBOT --repertoire
REP.json --out DIR [--seeds 3] [--standard-seeds 1] [--config RUN.yaml] [--standard-extra
N] [--summarise-only]`` (``offline_evolution.experiments.hexapod_check`` is this for the
hexapod).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np

from evorbc_ros.arbitrator import ArbitratorError, ArbitratorFile
from evorbc_ros.atomic_io import atomic_write_text
from evorbc_ros.config import ConfigError, build_settings
from evorbc_ros.controller_kinds import EVORBC, STANDARD
from evorbc_ros.repertoire import Repertoire, RepertoireError
from evorbc_ros.robots.registry import lookup
from offline_evolution.arbitrator.settings import load_run_settings
from offline_evolution.checkpoint import CheckpointError, load_json_checkpoint
from offline_evolution.repertoire.stats import repertoire_stats

# What the paper reports, by robot: only the hexapod ran in the paper.
PAPERS = {
  "hexapod": {
    "count": 336,
    "quality": "1.69 ± 0.24",
    "evorbc": "1.28 ± 0.02, goal reached in 5 of 5 runs, about 25 generations to first reach",
    "standard": "about the middle of the maze",
    "switch": "about every 1.9 cycles",
    # Appendix E: mean over the best controllers, output and hidden neurons plus synapses
    "size": "EvoRBC 37.6, standard NEAT 277.6",
  },
}  # fmt: skip
NOT_REPORTED = dict.fromkeys(PAPERS["hexapod"], "")


def cli(*args: str) -> None:
    """Run ``evorbc-evolve`` with ``args`` (it resumes from its own checkpoint).

    Raises:
        SystemExit: the command failed (its own one-line error is above).

    """
    cmd = [sys.executable, "-P", "-m", "offline_evolution.cli", *args]  # -P: design.md s. 10
    print("$ evorbc-evolve " + " ".join(args), flush=True)
    code = subprocess.run(cmd, check=False).returncode
    if code != 0:
        raise SystemExit(
            f"legged_check: error: evorbc-evolve {args[0]} exited with status {code}; "
            "finished runs are kept and the same command resumes"
        )


def run_all(
    robot: str,
    repertoire: Path,
    out: Path,
    seeds: list[int],
    standard_seeds: list[int],
    config: Path | None = None,
    standard_extra: int | None = None,
    workers: int | None = None,
) -> None:
    """Every run that is not finished yet: EvoRBC and standard NEAT seed by seed.

    Args:
        config: run settings for both approaches (default: the robot's).
        standard_extra: standard NEAT's generations beyond EvoRBC's (default: the
            robot's equal budget, ``--equal-budget``).
        workers: PyBullet worker processes per run (default: every core).
    """
    common = [*(["--config", str(config)] if config else []),
              *(["--workers", str(workers)] if workers else [])]  # fmt: skip
    if standard_extra is None:
        budget = ["--equal-budget"]
    else:
        evorbc_generations = run_generations(robot, config)
        budget = ["--generations", str(evorbc_generations + standard_extra)]
    for seed in sorted(set(seeds) | set(standard_seeds)):
        path = out / f"evorbc-seed{seed}.json"
        if seed in seeds and not path.exists():
            cli(EVORBC.command, "--repertoire", str(repertoire), "--seed", str(seed),
                "--out", str(path), *common)  # fmt: skip
        path = out / f"standard-seed{seed}.json"
        if seed in standard_seeds and not path.exists():
            cli(STANDARD.command, "--robot", robot, *budget, "--seed", str(seed),
                "--out", str(path), *common)  # fmt: skip


def run_generations(robot: str, config: Path | None) -> int:
    """EvoRBC's generations: ``config``'s, else the robot's run settings'."""
    return load_run_settings(config, robot).generations


def replay_nominal(arbitrator: Path, repertoire: Path | None) -> dict:
    """Replay a controller from the maze's nominal start.

    Returns:
        ``switches_per_cycle``, ``reached``, ``fitness``, and ``progress``: the share of
        the start-to-goal span along the maze's length (x) that the robot covered.

    """
    from offline_evolution.maze_task.replay import replay
    from offline_evolution.maze_task.task import MazeTaskSettings, make_task

    arb = ArbitratorFile.load(arbitrator)
    rep = Repertoire.load(repertoire) if arb.kind.uses_repertoire else None
    settings = build_settings(MazeTaskSettings, arb.evolution["task"], f"{arbitrator}: task")
    task = make_task(settings, arb.robot, workers=1)
    try:
        starts = task.nominal_starts()
        outcomes, result = replay(arb, task, starts, rep)
        target_x = task.mazes[0].target[0]
    finally:
        task.close()
    o = outcomes[0]
    final_x = result.pose[0, int(result.cycles[0]), 0]
    start_x = starts[0, 1]
    return {
        "switches_per_cycle": o.switches_per_cycle,
        "reached": o.reached,
        "fitness": o.fitness,
        "progress": (final_x - start_x) / (target_x - start_x),
    }


def summarise(
    repertoire: Path,
    out: Path,
    seeds: list[int],
    standard_seeds: list[int],
    robot: str = "hexapod",
    standard_extra: int | None = None,
) -> str:
    """The Markdown comparison (with the paper's values, for the hexapod).

    Written to ``OUT/ROBOT-check.md``; the fitness curves of the finished runs (paper Fig.
    17) go to ``OUT/ROBOT-check.png``. ``standard_extra``: standard NEAT's generations
    beyond EvoRBC's (default: the robot's equal budget).
    """
    paper = PAPERS.get(robot, NOT_REPORTED)
    extra = lookup(robot).equal_budget_generations if standard_extra is None else standard_extra
    evo = [_evolution(out / f"evorbc-seed{k}.json") for k in seeds]
    evo = [e for e in evo if e is not None]
    std = [_evolution(out / f"standard-seed{k}.json") for k in standard_seeds]
    std = [e for e in std if e is not None]
    lines = [
        "| figure | here | paper |",
        "|---|---|---|",
        *_repertoire_rows(Repertoire.load(repertoire), paper),
        *(_evorbc_rows(evo, out, repertoire, paper) if evo else []),
        *(_standard_rows(std, out, standard_seeds, extra, paper) if std else []),
        *_running_rows(out, seeds, standard_seeds, extra, paper),
        *_size_rows(out, seeds, standard_seeds, paper),
    ]
    if evo or std:
        from offline_evolution.plots.fitness import plot_fitness_comparison

        # the paper's Fig. 17: highest fitness so far, mean over runs with the min-max band
        groups = {"EvoRBC": evo, "standard NEAT": std}
        plot_fitness_comparison(
            {k: [[h["best"] for h in e["history"]] for e in v] for k, v in groups.items() if v},
            out / f"{robot}-check.png",
            title=f"{robot}: highest fitness so far",
        )
    if robot not in PAPERS:  # nothing to compare with: drop the paper column
        lines = [line[: line[:-1].rfind("|") + 1] for line in lines]
        lines[1] = "|---|---|"
    text = "\n".join(lines) + "\n"
    atomic_write_text(out / f"{robot}-check.md", text)
    return text


def _repertoire_rows(rep: Repertoire, paper: dict) -> list[str]:
    """The repertoire's size, quality and left/right symmetry."""
    s = repertoire_stats(rep)
    return [
        f"| repertoire size | {s['count']} primitives ({rep.algorithm.get('evaluations', 0):,} "
        f"evaluations, {rep.algorithm.get('variation', 'paper')} operator) | {paper['count']} |",
        f"| repertoire quality | {s['mean_quality']:.2f} ± {s['sd_quality']:.2f} | "
        f"{paper['quality']} |",
        f"| left/right symmetry (off-axis cells with a filled mirror cell) | "
        f"{100 * s['mirrored']:.0f} %, left/right {s['left']}/{s['right']} | "
        "asymmetric (Fig. 16) |",
    ]


def _evorbc_rows(evo: list[dict], out: Path, repertoire: Path, paper: dict) -> list[str]:
    """EvoRBC's training fitness, its written controllers' results and their switching."""
    best = np.array([e["best_fitness"] for e in evo])
    reached = sum(e["best_reached"] >= 1 for e in evo)
    firsts = [
        # 1-based, as the CLI's progress lines count generations
        next((h["generation"] + 1 for h in e["history"] if h["best_reached"] >= 1), None)
        for e in evo
    ]
    first_text = ", ".join("never" if f is None else str(f) for f in firsts)
    sd = f" ± {best.std(ddof=1):.2f}" if len(best) > 1 else ""
    lines = [
        f"| EvoRBC best fitness, {len(evo)} run(s) of {evo[0]['generations']} generations "
        f"| {best.mean():.2f}{sd}; goal reached in {reached} of {len(evo)}; first reached "
        f"at generation {first_text} | {paper['evorbc']} |"
    ]
    nominal = [replay_nominal(out / f"evorbc-seed{e['seed']}.json", repertoire) for e in evo]
    # The paper reports training fitness only; how the written controllers do over
    # many starts, and from the nominal start where the demo puts the robot, is what a
    # user gets, so it goes next to it.
    posts = "; ".join(
        f"seed {e['seed']} (rule {e['post_evaluation'].get('rule', 'mean')}): "
        f"{e['post_evaluation']['fitness']:.2f}, reached "
        f"{100 * e['post_evaluation']['reached']:.0f} % of "
        f"{_post_episodes(e['post_evaluation'])}, "
        f"{'reaches' if w['reached'] else 'misses'} from the nominal start"
        for e, w in zip(evo, nominal, strict=True)
    )
    lines.append(
        "| selected EvoRBC controllers over the nominal start and random starts "
        f"(mean fitness, goal reached) | {posts} | not reported |"
    )
    rate = np.mean([w["switches_per_cycle"] for w in nominal])
    lines.append(
        f"| primitive switches of the selected arbitrators (nominal start) | "
        f"{rate:.2f} per cycle, about every {1 / rate:.1f} cycles | {paper['switch']} |"
        if rate > 0
        else "| primitive switches | never switched | " + paper["switch"] + " |"
    )
    return lines


def _standard_rows(
    std: list[dict], out: Path, standard_seeds: list[int], extra: int, paper: dict
) -> list[str]:
    """Standard NEAT's training fitness, also at EvoRBC's budget, and how far it walks."""
    best = np.array([e["best_fitness"] for e in std])
    walks = [
        replay_nominal(out / f"standard-seed{k}.json", None)
        for k in standard_seeds
        if (out / f"standard-seed{k}.json").exists()
    ]
    how_far = ", ".join(
        "reached the goal" if w["reached"] else f"{100 * w['progress']:.0f} % of the way"
        for w in walks
    )
    base = std[0]["generations"] - extra
    at_base = (
        # what standard NEAT had after as many generations as EvoRBC ran
        f" ({np.mean([e['history'][base - 1]['best_so_far'] for e in std]):.2f} at "
        f"generation {base}, EvoRBC's budget)"
        if 0 < base <= min(len(e["history"]) for e in std)
        else ""
    )
    return [
        f"| standard NEAT, {len(std)} run(s) of {std[0]['generations']} generations | "
        f"best fitness {best.mean():.2f}{at_base}, goal reached in "
        f"{sum(e['best_reached'] >= 1 for e in std)} of {len(std)} in training; the "
        f"selected controller from the nominal start: {how_far} along the maze | "
        f"{paper['standard']} |"
    ]


def _running_rows(
    out: Path, seeds: list[int], standard_seeds: list[int], extra: int, paper: dict
) -> list[str]:
    """What the checkpoints of runs still going hold so far."""
    lines = []
    running = [(k, _progress(out / f"evorbc-seed{k}.json", 0)) for k in seeds]
    running = [(k, p) for k, p in running if p is not None]
    if running:
        parts = "; ".join(f"seed {k}: {p}" for k, p in running)
        lines.append(f"| EvoRBC still running (its checkpoint) | {parts} | |")
    running = [(k, _progress(out / f"standard-seed{k}.json", extra)) for k in standard_seeds]
    running = [(k, p) for k, p in running if p is not None]
    if running:
        # A 655-generation run outlasts a working session; what its checkpoint holds so
        # far is worth reporting, as at EvoRBC's own budget of generations.
        parts = "; ".join(f"seed {k}: {p}" for k, p in running)
        lines.append(
            f"| standard NEAT still running (its checkpoint) | {parts} | {paper['standard']} |"
        )
    return lines


def _size_rows(out: Path, seeds: list[int], standard_seeds: list[int], paper: dict) -> list[str]:
    """The written controllers' mean network size, per kind."""
    sizes = {
        kind: [network_size(out / f"{kind.name}-seed{k}.json") for k in ks]
        for kind, ks in ((EVORBC, seeds), (STANDARD, standard_seeds))
    }
    sizes = {kind: [s for s in v if s is not None] for kind, v in sizes.items()}
    if not any(sizes.values()):
        return []
    parts = [
        f"{kind.label} {np.mean(sizes[kind]):.1f} ({len(sizes[kind])} run(s))"
        for kind in (EVORBC, STANDARD)
        if sizes[kind]
    ]
    return [
        "| network size of the written controllers (output and hidden neurons plus "
        f"enabled synapses) | {', '.join(parts)} | {paper['size']} |"
    ]


def network_size(path: Path) -> int | None:
    """Neurons (output and hidden) plus enabled synapses of a run file's network.

    neat-python's ``DefaultGenome.size()`` counts the same two things, which is how the
    paper's Appendix E reports network sizes. None if the run has not finished.
    """
    if not path.exists():
        return None
    net = ArbitratorFile.load(path).network
    return len(net.nodes) + sum(c.enabled for c in net.connections)


def _progress(path: Path, extra: int) -> str | None:
    """How far an unfinished run has got, from its checkpoint next to ``path``.

    None if the run has finished or has no checkpoint.

    Raises:
        CheckpointError: the checkpoint is unreadable or lacks its generation history.

    """
    ckpt = path.with_name(path.name + ".checkpoint.json")
    if path.exists() or not ckpt.exists():
        return None
    data = load_json_checkpoint(ckpt)
    try:
        total = int(data["settings"]["generations"])
        best = [float(h["best_so_far"]) for h in data["history"]]
        reached = any(h["best_reached"] >= 1 for h in data["history"])
    except (KeyError, TypeError, ValueError):
        raise CheckpointError(f"{ckpt}: not a NEAT checkpoint with a generation history") from None
    if not best:
        return f"generation 0 of {total}"
    # 1-based generations, as the CLI's progress lines count them
    text = (
        f"generation {len(best)} of {total}, best fitness so far {best[-1]:.2f} "
        f"(generation {int(np.argmax(best)) + 1}), goal {'reached' if reached else 'not reached'}"
    )
    base = total - extra
    if 0 < base <= len(best):
        text += f"; {best[base - 1]:.2f} at generation {base} (EvoRBC's budget)"
    return text


def _evolution(path: Path) -> dict | None:
    """The ``evolution`` record of a finished run's file, or None if not run yet."""
    return ArbitratorFile.load(path).evolution if path.exists() else None


def main(robot: str | None = None, name: str = "legged_check") -> None:
    """Command-line entry point.

    Args:
        robot: fixed by a robot's own check (``hexapod_check``), else ``--robot``.
        name: the program's name in error messages.
    """
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    if robot is None:
        parser.add_argument("--robot", required=True, help="a legged robot of the registry")
    parser.add_argument("--repertoire", type=Path, required=True)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--seeds", type=int, default=3, help="EvoRBC runs (seeds 1..N)")
    parser.add_argument("--standard-seeds", type=int, default=1, help="standard-NEAT runs")
    parser.add_argument("--config", type=Path, help="run settings for both approaches")
    parser.add_argument(
        "--standard-extra", type=int, metavar="N",
        help="standard NEAT's generations beyond EvoRBC's (default: the robot's equal budget)",
    )  # fmt: skip
    parser.add_argument("--workers", type=int, help="PyBullet workers per run")
    parser.add_argument("--summarise-only", action="store_true")
    args = parser.parse_args()
    robot = robot or args.robot
    try:
        lookup(robot)
        rep = Repertoire.load(args.repertoire)
        if rep.robot != robot:
            raise RepertoireError(f"{args.repertoire}: is for robot {rep.robot}, not {robot}")
        args.out.mkdir(parents=True, exist_ok=True)
        seeds = list(range(1, args.seeds + 1))
        standard = list(range(1, args.standard_seeds + 1))
        if not args.summarise_only:
            run_all(robot, args.repertoire, args.out, seeds, standard, args.config,
                    args.standard_extra, args.workers)  # fmt: skip
        print(summarise(args.repertoire, args.out, seeds, standard, robot, args.standard_extra))
    except (RepertoireError, ArbitratorError, CheckpointError, ConfigError, OSError) as e:
        raise SystemExit(f"{name}: error: {e}") from None


if __name__ == "__main__":
    main()


def _post_episodes(post: dict) -> int:
    """Episodes a file's ``post_evaluation`` figures are over.

    A finalist's episodes when it had a second round (docs/design.md section 8).
    """
    return post.get("episodes_per_finalist", post["episodes_per_candidate"])
