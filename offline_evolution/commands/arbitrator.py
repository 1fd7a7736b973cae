"""``evorbc-evolve arbitrator`` (EvoRBC) and ``standard`` (the standard-NEAT baseline)."""

from __future__ import annotations

import argparse
import statistics
import sys
from collections import deque
from pathlib import Path

from evorbc_ros.controller_kinds import EVORBC, STANDARD
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.registry import lookup
from offline_evolution import bounds
from offline_evolution.commands.common import (
    CliError,
    EpisodeProgress,
    add_resume_options,
    add_workers_option,
    check_distinct,
    check_outputs,
    checkpoint_option,
    default_checkpoint,
    exclusive_outputs,
    restart_from_scratch,
    running,
    write_then_discard,
)
from offline_evolution.reporters import Reporter
from sim_bridge.cli_options import add_repertoire, add_robot, add_seed, add_task
from sim_bridge.cli_support import check_output_file, integer_in


def _common_options(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--generations",
        type=integer_in(1, bounds.GENERATIONS),
        metavar="N",
        help="NEAT generations (default: the robot's run settings, Table I)",
    )
    p.add_argument(
        "--population",
        type=integer_in(2, bounds.POP_SIZE),
        metavar="N",
        help="NEAT population, in place of the NEAT file's pop_size (its species and "
        "elitism settings must fit it)",
    )
    p.add_argument(
        "--post-samples",
        type=integer_in(1, bounds.MAZES),
        metavar="N",
        help="random starts per maze of each hall-of-fame genome in the post-selection "
        "(default: the run settings'; fewer is quicker, less sure)",
    )
    add_seed(p, "random seed")
    p.add_argument("--out", required=True, metavar="FILE", help="arbitrator file to write (JSON)")
    p.add_argument(
        "--config",
        metavar="FILE.yaml",
        help="run settings (default: the robot's, e.g. config/arbitrator/4ws.yaml)",
    )
    p.add_argument("--neat-config", metavar="FILE.ini", help="NEAT settings (neat-python format)")
    add_task(p, "the one the run settings name")
    p.add_argument(
        "--plot", metavar="FILE.png", help="fitness-curve picture (default: OUT with .fitness.png)"
    )
    add_resume_options(p, ".checkpoint.json", "generations")
    p.add_argument(
        "--keep-checkpoint",
        action="store_true",
        help="keep the finished run's checkpoint, so that the same command with a larger "
        "--generations continues it (e.g. look at 300 generations, then go on to 1000)",
    )
    p.add_argument(
        "--quiet", action="store_true", help="no per-generation lines (a resume is still said)"
    )
    p.add_argument(
        "--init-from",
        metavar="FILE.json",
        help="start from this arbitrator file's network (and mutated copies of it) instead "
        "of random networks: carry a controller on to another task (its inputs are matched "
        "by name; docs/design.md section 8)",
    )
    add_workers_option(p)


def add_parsers(sub) -> None:
    """Register ``arbitrator`` and ``standard``."""
    from evorbc_ros.mapping import MAPPINGS

    arb = sub.add_parser(
        EVORBC.command,
        help="evolve an EvoRBC arbitrator for a repertoire (NEAT)",
        description="Evolve an arbitrator network with NEAT that maps sensor readings to a "
        "point of the repertoire's behaviour space (paper Sec. III-C).",
    )
    add_repertoire(arb)
    arb.add_argument("--mapping", choices=MAPPINGS, help="mapping function (default: polar)")
    _common_options(arb)
    arb.set_defaults(func=cmd_evolve, kind=EVORBC)

    std = sub.add_parser(
        STANDARD.command,
        help="evolve a standard-NEAT controller (the baseline)",
        description="Evolve a network whose outputs are the robot's locomotion parameters, "
        "applied every control cycle (paper Sec. IV-D).",
    )
    add_robot(std, "robot type", required=True)
    std.add_argument(
        "--equal-budget",
        action="store_true",
        help="add the generations that match EvoRBC's repertoire budget (the robot's: +25 "
        "for the 4WS robots, +455 for the hexapod)",
    )
    _common_options(std)
    std.set_defaults(func=cmd_evolve, kind=STANDARD)


class _GenerationPrinter(Reporter):
    """One line per generation on stderr, with an ETA once it means something.

    The first generation a process runs also compiles the simulation kernels (seconds
    where a generation then takes a fraction of one). The ETA is the median of the last
    ten generations times those left, shown from the third generation measured on: a
    median of three or more is not thrown by one such generation, nor by a slow one later
    (the machine busy, the run paused).
    """

    #: Generations measured before an ETA is shown.
    MIN_MEASURED = 3

    def __init__(self, quiet: bool, total: int) -> None:
        self.quiet = quiet
        self.total = total
        self.recent: deque[float] = deque(maxlen=10)  # s per generation

    def resumed(self, done: int) -> None:
        """Say that the run resumes; even with --quiet: a log (a study's run.log) keeps it."""
        print(
            f"resuming from the checkpoint: generations 1-{done} of {self.total} are done",
            file=sys.stderr,
        )

    def generation_end(self, stats, settings) -> None:
        """Print the generation's line."""
        if self.quiet:
            return
        self.recent.append(stats.seconds)
        print(
            f"generation {stats.generation + 1:>4}/{self.total}  best {stats.best:6.3f}  "
            f"mean {stats.mean:6.3f}  best so far {stats.best_so_far:6.3f}  "
            f"species {stats.species:>2}  reached {stats.best_reached}  "
            f"{stats.seconds:5.2f} s/gen  {self.eta(stats.generation + 1)}",
            file=sys.stderr,
        )

    def eta(self, done: int) -> str:
        """``eta N.N min`` for the generations left, or ``eta --`` until it is meaningful."""
        if done >= self.total:
            return "done"
        if len(self.recent) < self.MIN_MEASURED:
            return "eta   --"
        remaining = (self.total - done) * statistics.median(self.recent)
        return f"eta {remaining / 60:5.1f} min"


class _PostEvaluationPrinter(Reporter):
    """The post-evaluation's episodes as lines on stderr, round by round (``EpisodeProgress``)."""

    def __init__(self) -> None:
        self.rounds = {
            False: EpisodeProgress("post-evaluation"),
            True: EpisodeProgress("post-evaluation, finalists"),
        }

    def post_evaluation(self, done: int, total: int, finalists: bool) -> None:
        """Pass the count to that round's lines."""
        self.rounds[finalists](done, total)


def _run(args, settings, every: int, repertoire, checkpoint: Path, initial_network=None):
    """Evolve (resuming from ``checkpoint``); the :class:`EvolutionResult`."""
    from offline_evolution.arbitrator.evolve import CHECKPOINT_KIND, evolve

    if args.restart:
        restart_from_scratch(checkpoint, CHECKPOINT_KIND, "NEAT evolution checkpoint")
    printer = _GenerationPrinter(args.quiet, settings.generations)
    # After the last generation the run stops between batches of its post-evaluation.
    with running("generation (or post-evaluation batch)", "generation") as stop:
        return evolve(
            settings,
            repertoire,
            checkpoint=checkpoint,
            checkpoint_every=every,
            reporters=[printer] if args.quiet else [printer, _PostEvaluationPrinter()],
            should_stop=stop,
            workers=args.workers or None,
            repertoire_source=args.repertoire if repertoire else "the repertoire",
            keep_checkpoint=True,  # deleted only once the files are written
            initial_network=initial_network,
        )


def cmd_evolve(args: argparse.Namespace) -> int:
    """Evolve an arbitrator or a standard-NEAT controller and write its file and curve."""
    from evorbc_ros.config import ConfigError, config_dir
    from evorbc_ros.sensors import SensorLayout
    from offline_evolution.arbitrator.evolve import (
        EvolutionSettings,
        arbitrator_file,
        file_sha256,
    )
    from offline_evolution.arbitrator.neat_config import load_neat_config
    from offline_evolution.arbitrator.settings import load_run_settings
    from offline_evolution.arbitrator.warm_start import load_initial_network, network_fingerprint
    from offline_evolution.maze_task.base import fit_task_mazes
    from offline_evolution.maze_task.task import MazeTaskSettings, make_task
    from offline_evolution.maze_task.training import check_training
    from offline_evolution.memory import check_evolution_memory

    # Every output is checked before any work, so that a typo costs nothing.
    check_output_file(args.out, "--out")
    out = Path(args.out)
    plot = Path(args.plot) if args.plot is not None else out.with_name(out.stem + ".fitness.png")
    checkpoint = default_checkpoint(out, args.checkpoint, ".checkpoint.json")
    written = {
        "--out": out,
        "--plot" if args.plot is not None else "the default --plot": plot,
        checkpoint_option(args.checkpoint): checkpoint,
    }
    check_outputs(written)
    repertoire = None
    if args.kind.uses_repertoire:
        repertoire = Repertoire.load(args.repertoire)
        robot = repertoire.robot
    else:
        robot = args.robot
    run = load_run_settings(args.config, robot)
    generations = args.generations if args.generations is not None else run.generations
    if not args.kind.uses_repertoire and args.equal_budget:
        generations += lookup(robot).equal_budget_generations
    neat_file = Path(args.neat_config) if args.neat_config else run.neat_path()
    task_settings = MazeTaskSettings.load(args.task or run.task_path())
    # A maze the robot does not fit is scaled to fit it (one warning line), and the scale
    # recorded with the task; a maze no scale fits is refused before any work.
    try:
        task_settings, task_mazes = fit_task_mazes(
            task_settings, lookup(robot).footprint_radius, robot
        )
    except ConfigError as e:
        raise CliError(f"{args.task or run.task_path()}: {e}") from None
    # Held-out mazes and seeds are refused before any work (docs/design.md section 22).
    check_training(task_mazes, task_settings.training, args.seed, str(args.task or run.task_path()))
    # The NEAT settings, the task's sensor layout and a network to start from, before any
    # work.
    layout = SensorLayout.load(config_dir() / task_settings.sensors)
    n_outputs = args.kind.n_outputs(lookup(robot).n_parameters)
    neat_config = load_neat_config(neat_file, layout.n_inputs, n_outputs, args.population)
    mapping = (args.mapping or run.mapping) if args.kind.uses_repertoire else None
    initial_network = None
    if args.init_from:
        initial_network = load_initial_network(
            args.init_from, robot, args.kind, mapping, layout, neat_config, str(neat_file)
        )
    selection = run.selection()
    if args.post_samples is not None:
        selection["post_samples"] = args.post_samples
    settings = EvolutionSettings(
        kind=args.kind,
        robot=robot,
        generations=generations,
        seed=args.seed,
        neat_file=str(neat_file),
        neat_sha256=file_sha256(neat_file),
        task=task_settings.as_dict(),
        mapping=mapping,
        repertoire_fingerprint=repertoire.fingerprint() if repertoire else None,
        **selection,
        initial_network=network_fingerprint(initial_network) if initial_network else None,
        initial_network_file=args.init_from,
        population=args.population,
    )
    check_distinct(
        {
            **written,
            "--repertoire": args.repertoire if repertoire else None,
            "--config": args.config,
            "--neat-config": args.neat_config,
            "--task": args.task,
            "--init-from": args.init_from,
        }
    )
    pop_size = neat_config.pop_size
    check_evolution_memory(
        task_settings,
        pop_size,
        robot,
        str(args.task or run.task_path()),
        3 * run.hall_of_fame + (generations // run.snapshot_every if run.snapshot_every else 0),
        selection["post_samples"],
        run.post_finalists,
        run.post_final_samples,
        neat_source=str(neat_file),
        run_source=str(args.config or lookup(robot).settings_file("arbitrator")),
    )
    every = args.checkpoint_every or run.checkpoint_every
    with exclusive_outputs(written):
        result = _run(args, settings, every, repertoire, checkpoint, initial_network)

        def write() -> None:
            task = make_task(task_settings, robot, workers=1)
            try:
                arb = arbitrator_file(
                    result, task, repertoire, args.repertoire if repertoire else None
                )
                arb.save(out)
            finally:
                task.close()
            from offline_evolution.plots.fitness import plot_fitness_history

            plot_fitness_history(
                result.history,
                plot,
                title=f"{args.kind.label}, {robot}, seed {args.seed}",
            )

        write_then_discard(checkpoint, write, discard=not args.keep_checkpoint)
    post = result.post_evaluation
    episodes = f"{post.episodes} post-evaluation episodes"
    if post.finalists:  # its figures are over both rounds (docs/design.md section 8)
        episodes = (
            f"{post.final_episodes} post-evaluation episodes (one of {post.finalists} "
            f"finalists of {post.candidates} candidates)"
        )
    print(
        f"{robot} {args.kind.noun}: best fitness {result.best_fitness:.3f} (generation "
        f"{result.best_generation + 1}); the controller written scores {post.fitness:.3f} and "
        f"reaches the target in {post.reached:.0%} of {episodes}; "
        f"{generations} generations in {result.seconds / 60:.1f} min "
        f"(seed {args.seed}) -> {out}, curve {plot}"
    )
    return 0
