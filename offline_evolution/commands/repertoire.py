"""``evorbc-evolve repertoire`` and ``export-csv``."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.registry import lookup
from offline_evolution.commands.common import (
    CliError,
    add_resume_options,
    add_workers_option,
    check_distinct,
    check_outputs,
    checkpoint_option,
    count,
    default_checkpoint,
    exclusive_outputs,
    positive_float,
    restart_from_scratch,
    running,
    write_then_discard,
)
from sim_bridge.cli_options import add_robot
from sim_bridge.cli_support import check_output_file


def add_parsers(sub) -> None:
    """Register ``repertoire`` and ``export-csv``."""
    from offline_evolution.quality import METRICS
    from offline_evolution.repertoire.settings import ARCHIVES, VARIATIONS

    rep = sub.add_parser(
        "repertoire",
        help="generate a MAP-Elites repertoire of locomotion primitives",
        description="Generate a repertoire with batch MAP-Elites (paper Algorithm 1). "
        "Settings come from the robot's settings file (config/repertoire/4ws.yaml or "
        "hexapod.yaml: paper Table I) or --config; options given here override them.",
    )
    add_robot(rep, "robot type (default: from config)")
    rep.add_argument("--metric", choices=tuple(METRICS), help="quality metric")
    rep.add_argument(
        "--bin-size",
        type=positive_float,
        metavar="M",
        help="side of a square archive cell in metres",
    )
    rep.add_argument(
        "--eval-time",
        type=positive_float,
        metavar="S",
        help="primitive evaluation time T in seconds",
    )
    rep.add_argument(
        "--initial-batch", type=count, metavar="N", help="random solutions in the first batch (S_G)"
    )
    rep.add_argument("--batch-size", type=count, metavar="N", help="mutants per iteration (S_B)")
    rep.add_argument(
        "--iterations", type=count, metavar="N", help="iterations after the initial batch (I)"
    )
    rep.add_argument("--seed", type=count, metavar="N", help="random seed")
    rep.add_argument(
        "--archive", choices=ARCHIVES, help="grid (the paper's) or cvt (Voronoi cells)"
    )
    rep.add_argument(
        "--variation",
        choices=VARIATIONS,
        help="paper (Gaussian mutation) or iso_line_dd (Iso+LineDD of two elites)",
    )
    rep.add_argument("--config", metavar="FILE.yaml", help="settings file (YAML)")
    rep.add_argument("--out", required=True, metavar="FILE", help="repertoire file to write (JSON)")
    rep.add_argument("--plot", metavar="FILE.png", help="also draw the repertoire (Fig. 8 style)")
    rep.add_argument("--csv", metavar="FILE.csv", help="also export the primitives as CSV")
    add_resume_options(rep, ".checkpoint.npz", "iterations", every=100)
    rep.add_argument("--quiet", action="store_true", help="no progress lines")
    add_workers_option(rep)
    rep.set_defaults(func=cmd_repertoire)

    csv = sub.add_parser("export-csv", help="convert a repertoire file to CSV")
    csv.add_argument("repertoire", metavar="REPERTOIRE", help="repertoire file (JSON)")
    csv.add_argument("--out", metavar="FILE.csv", help="CSV file (default: next to the input)")
    csv.set_defaults(func=cmd_export_csv)


class _ProgressPrinter:
    """Prints a progress line to stderr at most every ``interval`` seconds, and the last.

    The rate and ETA leave out the first batch a process runs, which also compiles the
    simulation kernels (or starts the workers): they come from the batches after it, and
    the ETA is shown once those have run for :attr:`MIN_SECONDS` (``eta --`` before).
    """

    #: Seconds of batches after the first before the ETA is shown.
    MIN_SECONDS = 2.0

    def __init__(self, quiet: bool, interval: float = 1.0) -> None:
        self.quiet = quiet
        self.interval = interval
        self.last = -float("inf")
        self.announced = False
        self.after_first: tuple[float, int] | None = None  # (s, evaluations) after batch 1

    def __call__(self, p) -> None:
        if self.quiet:
            return
        if p.resumed_from is not None and not self.announced:
            print(f"resuming from the checkpoint at iteration {p.resumed_from}", file=sys.stderr)
        self.announced = True
        if self.after_first is None:
            self.after_first = (p.elapsed, p.evaluations)
        now = time.perf_counter()
        if now - self.last < self.interval and p.iteration < p.iterations:
            return
        self.last = now
        rate, eta = self.rate_and_eta(p)
        speed = f"{rate / 1e3:7.0f}k eval/s" if rate >= 1e4 else f"{rate:7.1f} eval/s"
        print(
            f"iteration {p.iteration:>5}/{p.iterations}  evaluations {p.evaluations:>9,}  "
            f"primitives {p.cells:>5}  mean quality {p.mean_quality:.3f}  "
            f"QD-score {p.qd_score:8.1f}  {speed}{eta}",
            file=sys.stderr,
        )

    def rate_and_eta(self, p) -> tuple[float, str]:
        """Evaluations/s and the ETA text (empty for fast runs, done in moments).

        The rate is measured after the first batch (this process's overall rate until
        then); the ETA waits for :attr:`MIN_SECONDS` of such batches.
        """
        t0, e0 = self.after_first
        seconds, done = p.elapsed - t0, p.evaluations - e0
        rate = done / seconds if seconds > 0 and done > 0 else p.rate
        if rate >= 1e4 or p.evaluations >= p.total_evaluations:
            return rate, ""
        if seconds < self.MIN_SECONDS or done <= 0:
            return rate, "  eta   --"
        return rate, f"  eta {(p.total_evaluations - p.evaluations) / rate / 60:6.1f} min"


#: Setting key -> the option that overrides it.
OPTIONS = {
    "robot": "--robot",
    "metric": "--metric",
    "bin_size": "--bin-size",
    "eval_time": "--eval-time",
    "initial_batch": "--initial-batch",
    "batch_size": "--batch-size",
    "iterations": "--iterations",
    "seed": "--seed",
    "archive": "--archive",
    "variation": "--variation",
}


def cmd_repertoire(args: argparse.Namespace) -> int:
    """Generate a repertoire, write it (and optionally a plot and CSV), print a summary."""
    from offline_evolution.memory import check_repertoire_memory
    from offline_evolution.repertoire.settings import check_budget, load_settings, settings_path

    # Every output is checked before any work, so that a typo costs nothing.
    check_output_file(args.out, "--out")
    out = Path(args.out)
    checkpoint = default_checkpoint(out, args.checkpoint, ".checkpoint.npz")
    written = {
        "--out": out,
        "--plot": args.plot,
        "--csv": args.csv,
        checkpoint_option(args.checkpoint): checkpoint,
    }
    check_distinct({**written, "--config": args.config})
    check_outputs(written)
    given = {key: option for key, option in OPTIONS.items() if getattr(args, key) is not None}
    config = settings_path(args.config, args.robot)
    settings = load_settings(config, options=given, **{k: getattr(args, k) for k in OPTIONS})

    check_repertoire_memory(
        settings,
        lookup(settings.robot).n_parameters,
        lambda key: given.get(key) or f"{config}: {key}",
    )
    check_budget(settings, config, given)
    with exclusive_outputs(written):
        repertoire, elapsed = _run(args, settings, config, given, checkpoint)
        write_then_discard(checkpoint, lambda: _write(repertoire, out, args.plot, args.csv))
    s = repertoire.summary()
    print(
        f"{repertoire.robot} repertoire: {s['count']} primitives, mean quality "
        f"{s['mean_quality']:.3f}, QD-score {s['qd_score']:.1f}, "
        f"{repertoire.algorithm['evaluations']:,} evaluations in {elapsed:.1f} s "
        f"(seed {settings.seed}) -> {out}"
    )
    return 0


def _run(args, settings, config, given: dict, checkpoint: Path) -> tuple[Repertoire, float]:
    """Run MAP-Elites (resuming from ``checkpoint``); the repertoire and the seconds taken."""
    from offline_evolution.repertoire.map_elites import CHECKPOINT_KIND, generate_repertoire
    from offline_evolution.repertoire.settings import SettingError, blame

    if args.restart:
        restart_from_scratch(checkpoint, CHECKPOINT_KIND, "MAP-Elites checkpoint")
    start = time.perf_counter()
    with running("batch", "iteration") as stop:
        try:
            repertoire = generate_repertoire(
                settings,
                checkpoint=checkpoint,
                checkpoint_every=args.checkpoint_every,
                progress=_ProgressPrinter(args.quiet),
                should_stop=stop,
                workers=args.workers or None,
                keep_checkpoint=True,
            )
        except SettingError as e:
            raise blame(e, config, given) from None
    elapsed = time.perf_counter() - start
    out = args.out
    if len(repertoire) == 0:
        # A repertoire without primitives could drive nothing (and would not load).
        checkpoint.unlink(missing_ok=True)
        raise CliError(
            f"no primitive was kept after {repertoire.algorithm['evaluations']:,} evaluations "
            "(each one left the archive's range or was discarded); nothing written to "
            f"{out}; try a larger budget or another --metric"
        )
    return repertoire, elapsed


def _write(repertoire: Repertoire, out: Path, plot: str | None, csv: str | None) -> None:
    """Write the repertoire file and the plot and CSV asked for."""
    repertoire.save(out)
    if plot:
        from offline_evolution.plots.repertoire import plot_repertoire

        plot_repertoire(repertoire, plot)
    if csv:
        repertoire.to_csv(csv)


def cmd_export_csv(args: argparse.Namespace) -> int:
    """Convert a repertoire file to CSV."""
    repertoire = Repertoire.load(args.repertoire)
    if args.out is not None:
        out_option, out = "--out", args.out
    else:
        out_option, out = "the default --out", str(Path(args.repertoire).with_suffix(".csv"))
    check_output_file(out, out_option)
    check_distinct({"REPERTOIRE": args.repertoire, out_option: out})
    repertoire.to_csv(out)
    print(f"{len(repertoire)} primitives -> {out}")
    return 0
