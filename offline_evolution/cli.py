"""``evorbc-evolve``: the offline evolution command line.

Subcommands:
    repertoire   generate a MAP-Elites repertoire of locomotion primitives
    export-csv   convert a repertoire file to CSV

Bad arguments or files end the program with a one-line message and a non-zero status,
never a traceback (set ``EVORBC_DEBUG=1`` to see one for an unexpected failure).
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import time
from collections.abc import Sequence
from pathlib import Path

from evorbc_ros.config import ConfigError
from evorbc_ros.repertoire import Repertoire, RepertoireError
from offline_evolution.checkpoint import CheckpointError

EXIT_ERROR = 1
EXIT_USAGE = 2
EXIT_INTERRUPTED = 130


class CliError(Exception):
    """A user-facing error: printed as one line, exit status ``code``."""

    def __init__(self, message: str, code: int = EXIT_ERROR) -> None:
        super().__init__(message)
        self.code = code


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not value > 0 or value != value or value == float("inf"):
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text!r}")
    return value


def _count(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a non-negative integer, got {text!r}")
    return value


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``evorbc-evolve``."""
    from offline_evolution.quality import METRICS
    from sim_bridge.robots import ROBOT_NAMES

    parser = argparse.ArgumentParser(
        prog="evorbc-evolve",
        description="Offline evolution for EvoRBC: repertoires of locomotion primitives "
        "(MAP-Elites) and arbitrators (NEAT).",
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    rep = sub.add_parser(
        "repertoire",
        help="generate a MAP-Elites repertoire of locomotion primitives",
        description="Generate a repertoire with batch MAP-Elites (paper Algorithm 1). "
        "Settings come from config/repertoire/<family>.yaml (paper Table I) or "
        "--config; options given here override them.",
    )
    rep.add_argument("--robot", choices=ROBOT_NAMES, help="robot type (default: from config)")
    rep.add_argument("--metric", choices=tuple(METRICS), help="quality metric")
    rep.add_argument(
        "--bin-size",
        type=_positive_float,
        metavar="M",
        help="side of a square archive cell in metres",
    )
    rep.add_argument(
        "--eval-time",
        type=_positive_float,
        metavar="S",
        help="primitive evaluation time T in seconds",
    )
    rep.add_argument(
        "--initial-batch",
        type=_count,
        metavar="N",
        help="random solutions in the first batch (S_G)",
    )
    rep.add_argument("--batch-size", type=_count, metavar="N", help="mutants per iteration (S_B)")
    rep.add_argument(
        "--iterations", type=_count, metavar="N", help="iterations after the initial batch (I)"
    )
    rep.add_argument("--seed", type=_count, metavar="N", help="random seed")
    rep.add_argument("--config", metavar="FILE.yaml", help="settings file (YAML)")
    rep.add_argument("--out", required=True, metavar="FILE", help="repertoire file to write (JSON)")
    rep.add_argument("--plot", metavar="FILE.png", help="also draw the repertoire (Fig. 8 style)")
    rep.add_argument("--csv", metavar="FILE.csv", help="also export the primitives as CSV")
    rep.add_argument(
        "--checkpoint",
        metavar="FILE",
        help="resume checkpoint (default: OUT.checkpoint.npz); a run resumes from it automatically",
    )
    rep.add_argument(
        "--checkpoint-every",
        type=_count,
        default=100,
        metavar="N",
        help="iterations between checkpoints (default: 100)",
    )
    rep.add_argument(
        "--restart",
        action="store_true",
        help="discard an existing checkpoint and start from scratch",
    )
    rep.add_argument("--quiet", action="store_true", help="no progress lines")
    rep.set_defaults(func=cmd_repertoire)

    csv = sub.add_parser("export-csv", help="convert a repertoire file to CSV")
    csv.add_argument("repertoire", metavar="REPERTOIRE", help="repertoire file (JSON)")
    csv.add_argument("--out", metavar="FILE.csv", help="CSV file (default: next to the input)")
    csv.set_defaults(func=cmd_export_csv)
    return parser


class _ProgressPrinter:
    """Prints a progress line to stderr at most every ``interval`` seconds, and the last."""

    def __init__(self, quiet: bool, interval: float = 1.0) -> None:
        self.quiet = quiet
        self.interval = interval
        self.last = -float("inf")
        self.announced = False

    def __call__(self, p) -> None:
        if self.quiet:
            return
        if p.resumed_from is not None and not self.announced:
            print(f"resuming from the checkpoint at iteration {p.resumed_from}", file=sys.stderr)
        self.announced = True
        now = time.perf_counter()
        if now - self.last < self.interval and p.iteration < p.iterations:
            return
        self.last = now
        rate = p.evaluations / p.elapsed if p.elapsed > 0 else 0.0
        print(
            f"iteration {p.iteration:>5}/{p.iterations}  evaluations {p.evaluations:>9,}  "
            f"primitives {p.cells:>5}  mean quality {p.mean_quality:.3f}  "
            f"QD-score {p.qd_score:8.1f}  {rate / 1e3:7.0f}k eval/s",
            file=sys.stderr,
        )


class _StopOnSignal:
    """First Ctrl-C/SIGTERM: finish the current batch, checkpoint, exit. Second: abort."""

    def __init__(self) -> None:
        self.requested = False

    def __call__(self) -> bool:
        return self.requested

    def install(self) -> dict:
        """Install the handlers; return the previous ones for :meth:`restore`."""

        def handler(signum, frame):
            if self.requested:
                raise KeyboardInterrupt
            self.requested = True
            print(
                "\nstopping after this batch (Ctrl-C again to abort without saving)",
                file=sys.stderr,
            )

        return {sig: signal.signal(sig, handler) for sig in (signal.SIGINT, signal.SIGTERM)}

    @staticmethod
    def restore(previous: dict) -> None:
        """Put back the handlers :meth:`install` replaced."""
        for sig, old in previous.items():
            signal.signal(sig, old)


def cmd_repertoire(args: argparse.Namespace) -> int:
    """Generate a repertoire, write it (and optionally a plot and CSV), print a summary."""
    from offline_evolution.repertoire.map_elites import Interrupted, generate_repertoire
    from offline_evolution.repertoire.settings import load_settings

    settings = load_settings(
        args.config,
        robot=args.robot,
        metric=args.metric,
        bin_size=args.bin_size,
        eval_time=args.eval_time,
        initial_batch=args.initial_batch,
        batch_size=args.batch_size,
        iterations=args.iterations,
        seed=args.seed,
    )
    if settings.initial_batch < 1 or settings.batch_size < 1:
        raise CliError("--initial-batch and --batch-size must be at least 1", EXIT_USAGE)
    out = Path(args.out)
    checkpoint = (
        Path(args.checkpoint) if args.checkpoint else out.with_name(out.name + ".checkpoint.npz")
    )
    if args.restart and checkpoint.exists():
        checkpoint.unlink()
    _check_writable(out, args.plot, args.csv)
    stop = _StopOnSignal()
    previous_handlers = stop.install()
    start = time.perf_counter()
    try:
        repertoire = generate_repertoire(
            settings,
            checkpoint=checkpoint,
            checkpoint_every=args.checkpoint_every,
            progress=_ProgressPrinter(args.quiet),
            should_stop=stop,
        )
    except CheckpointError as e:
        raise CliError(f"{e}; use --restart to discard it") from None
    except Interrupted as e:
        raise CliError(
            f"interrupted after iteration {e.iteration}; finished work is saved in "
            f"{e.checkpoint}; run the same command again to resume",
            EXIT_INTERRUPTED,
        ) from None
    finally:
        stop.restore(previous_handlers)
    elapsed = time.perf_counter() - start
    repertoire.save(out)
    if args.plot:
        from offline_evolution.plots.repertoire import plot_repertoire

        plot_repertoire(repertoire, args.plot)
    if args.csv:
        repertoire.to_csv(args.csv)
    s = repertoire.summary()
    print(
        f"{repertoire.robot} repertoire: {s['count']} primitives, mean quality "
        f"{s['mean_quality']:.3f}, QD-score {s['qd_score']:.1f}, "
        f"{repertoire.algorithm['evaluations']:,} evaluations in {elapsed:.1f} s "
        f"(seed {settings.seed}) -> {out}"
    )
    return 0


def cmd_export_csv(args: argparse.Namespace) -> int:
    """Convert a repertoire file to CSV."""
    repertoire = Repertoire.load(args.repertoire)
    out = Path(args.out) if args.out else Path(args.repertoire).with_suffix(".csv")
    _check_writable(out)
    repertoire.to_csv(out)
    print(f"{len(repertoire)} primitives -> {out}")
    return 0


def _check_writable(*paths) -> None:
    """Fail early (before a long run) if an output folder cannot be created or written."""
    for p in paths:
        if p is None:
            continue
        folder = Path(p).resolve().parent
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise CliError(f"{p}: cannot create folder {folder} ({e.strerror})") from None
        if not os.access(folder, os.W_OK):
            raise CliError(f"{p}: folder {folder} is not writable")
        if Path(p).is_dir():
            raise CliError(f"{p}: is a folder, expected a file name")


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``evorbc-evolve``; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except CliError as e:
        print(f"evorbc-evolve: error: {e}", file=sys.stderr)
        return e.code
    except (ConfigError, RepertoireError, CheckpointError) as e:
        print(f"evorbc-evolve: error: {e}", file=sys.stderr)
        return EXIT_ERROR
    except KeyboardInterrupt:
        print("evorbc-evolve: aborted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except OSError as e:
        where = f"{e.filename}: " if e.filename else ""
        print(f"evorbc-evolve: error: {where}{e.strerror or e}", file=sys.stderr)
        return EXIT_ERROR
    except Exception as e:
        if os.environ.get("EVORBC_DEBUG"):
            raise
        print(
            f"evorbc-evolve: internal error: {type(e).__name__}: {e} "
            "(set EVORBC_DEBUG=1 for a traceback)",
            file=sys.stderr,
        )
        return EXIT_ERROR


if __name__ == "__main__":
    sys.exit(main())
