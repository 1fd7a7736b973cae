"""``evorbc-study``: run a study of the paper, locally or on a Ray cluster, and report it.

    evorbc-study list
    evorbc-study run robot-types --results results/robot-types [--seeds 10 --generations 300]
    evorbc-study run metrics --results DIR --address ray://head:10001   (or RAY_ADDRESS)
    evorbc-study status robot-types --results DIR
    evorbc-study report robot-types --results DIR --out docs/study
    evorbc-study compact robot-types --results DIR --out docs/study/robot-types.results.json
    evorbc-study report robot-types --results docs/study/robot-types.results.json

The results folder is the only record: each run's folder holds its files and ``run.json``.
``compact`` keeps of it what the report needs, in one file the report reads in its place.
A finished run is skipped, an unfinished one resumes from its checkpoint, so running the
same command again after any interruption finishes the study with the same results.
"""

from __future__ import annotations

import argparse
import fcntl
import os
import signal
import sys
from collections.abc import Sequence
from pathlib import Path

from evorbc_ros.config import ConfigError
from offline_evolution import bounds
from sim_bridge.cli_support import OneLineParser, integer_in, report_unexpected

EXIT_ERROR = 1
EXIT_INTERRUPTED = 130


class StudyError(Exception):
    """A user-facing error of ``evorbc-study``."""


def _only(text: str) -> tuple[str, str]:
    key, sep, value = text.partition("=")
    if not sep or not key:
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE, got {text!r}")
    return key, value


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``evorbc-study``."""
    p = OneLineParser(
        prog="evorbc-study",
        description="Run the paper's studies (a grid of settings x seeds of ordinary "
        "evorbc-evolve runs), locally or on a Ray cluster, and report them.",
    )
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    sub.add_parser("list", help="the shipped studies").set_defaults(func=cmd_list)
    for name, helptext, func in (
        ("run", "run (or resume) a study", cmd_run),
        ("status", "what is done, running and left", cmd_status),
    ):
        s = sub.add_parser(name, help=helptext)
        _study_options(s)
        s.set_defaults(func=func)
        if name == "run":
            s.add_argument(
                "--jobs",
                type=integer_in(1, bounds.WORKERS),
                help="runs at once on this machine (default: one per core)",
            )
            s.add_argument(
                "--threads",
                type=integer_in(1, bounds.THREADS),
                default=1,
                help="numba threads per run (default 1, at most "
                f"{bounds.THREADS}; results do not depend on it)",
            )
            s.add_argument(
                "--address",
                default=os.environ.get("RAY_ADDRESS", ""),
                help="Ray cluster to run on (default: $RAY_ADDRESS; none: this machine)",
            )
            s.add_argument(
                "--spread",
                type=integer_in(1, bounds.WORKERS),
                metavar="N",
                help="Ray: N runs at once, each spreading its PyBullet simulations over the "
                "whole cluster (for legged robots, whose runs are hours on one machine)",
            )
            s.add_argument(
                "--retries",
                type=integer_in(0, bounds.RETRIES),
                default=3,
                help="Ray: times a run lost with its node is retried from its checkpoint (3)",
            )
    rep = sub.add_parser("report", help="figures, statistics and verdicts as Markdown")
    _study_options(rep, protocol=False, table=True)
    rep.add_argument(
        "--out", metavar="DIR", help="folder for STUDY.md and its figures (default: docs/study)"
    )
    com = sub.add_parser(
        "compact", help="the study's result table: what the report needs, in one file"
    )
    _study_options(com, protocol=False)
    com.add_argument(
        "--out", metavar="FILE", help="the table (default: docs/study/STUDY.results.json)"
    )
    com.add_argument(
        "--source",
        default="",
        metavar="TEXT",
        help="where the raw run folders are kept, for the report "
        "(e.g. 'commit abc1234 under docs/study/runs')",
    )
    for parser, func in ((rep, cmd_report), (com, cmd_compact)):
        parser.add_argument(
            "--replay-runs",
            type=integer_in(1),
            metavar="N",
            help="replay at most N runs per setting for the selection heatmaps (default: all)",
        )
        parser.set_defaults(func=func)
    return p


def _study_options(p: argparse.ArgumentParser, protocol: bool = True, table=False) -> None:
    p.add_argument("study", help="a shipped study (evorbc-study list) or a study file (.yaml)")
    p.add_argument(
        "--results",
        required=True,
        metavar="DIR|TABLE" if table else "DIR",
        help="results folder: one folder per run, the single record of the study"
        + ("; or the study's result table (evorbc-study compact)" if table else ""),
    )
    if not protocol:
        return
    p.add_argument(
        "--seeds",
        type=integer_in(1, bounds.SEEDS),
        help="reduced protocol: seeds 1..N per setting (default: the study file's)",
    )
    p.add_argument(
        "--generations",
        type=integer_in(1, bounds.GENERATIONS),
        help="reduced protocol: NEAT generations of every run (default: the study file's)",
    )
    p.add_argument(
        "--only",
        type=_only,
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="only the settings with this value (repeatable), e.g. --only robot=4ws-5",
    )


def _selected_runs(args):
    from offline_evolution.study.spec import check_value, load_study

    study = load_study(args.study)
    only = {}
    for key, text in args.only:
        values = [v for vs in study.grid.values() for v in vs] + list(study.fixed.values())
        match = [v for v in values if str(v) == text]
        if not match:
            check_value(key, text, f"--only {key}")  # names the expected values
            raise ConfigError(f"--only {key}={text}: no setting of {study.name} has it")
        only[key] = match[0]
    runs = study.runs(args.seeds, args.generations, only)
    if not runs:
        raise ConfigError(f"--only: no setting of {study.name} matches")
    return study, runs


def cmd_list(args) -> int:
    """Print the shipped studies."""
    from offline_evolution.study.spec import load_study, study_names

    for name in study_names():
        s = load_study(name)
        n = len(s.settings())
        print(f"{name:12s} {s.paper:28s} {n} settings x {s.seeds} seeds  {s.title}")
    return 0


def cmd_status(args) -> int:
    """Print how many runs are finished, under way (checkpointed) and not started."""
    from offline_evolution.study.run import check_settings, is_finished

    study, runs = _selected_runs(args)
    results = results_folder(args.results)
    done = started = 0
    for run in runs:
        folder = results / run.path
        if is_finished(folder):
            check_settings(run, folder)
            done += 1
        elif folder.exists():
            started += 1
    print(
        f"study {study.name}: {done} finished, {started} started, "
        f"{len(runs) - done - started} not started, of {len(runs)} runs in {results}"
    )
    return 0


def results_folder(path: str) -> Path:
    """``--results``, refused in one line if it is empty or exists and is not a folder."""
    from evorbc_ros.atomic_io import special_file_kind

    if not path:
        raise StudyError("--results '': an empty name, expected a folder")
    kind = special_file_kind(path) or ("a file" if Path(path).is_file() else None)
    if kind and kind != "a folder":
        raise StudyError(f"--results {path}: is {kind}, expected a folder")
    return Path(path)


class ResultsLock:
    """An exclusive OS lock on the results folder: one runner per folder at a time.

    ``flock`` is released by the kernel when the holder dies, so a killed study never
    blocks the next one.
    """

    def __init__(self, results: Path):
        self.path = results / ".study.lock"

    def __enter__(self):
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.file = open(self.path, "a+")
        try:
            fcntl.flock(self.file, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            self.file.close()
            raise StudyError(
                f"{self.path.parent}: another evorbc-study is running on this results folder"
            ) from None
        return self

    def __exit__(self, *exc):
        self.file.close()


def cmd_run(args) -> int:
    """Run every unfinished run of the study."""
    from offline_evolution.study.local import StudyInterrupted, run_local
    from offline_evolution.study.progress import StudyProgress
    from offline_evolution.study.run import RunRecord, check_settings, is_finished

    study, runs = _selected_runs(args)
    results = results_folder(args.results)
    if args.spread and not args.address:
        raise StudyError("--spread needs a Ray cluster (--address or RAY_ADDRESS)")
    jobs = args.jobs or max(1, (os.cpu_count() or 1) // args.threads)
    with ResultsLock(results):
        progress = StudyProgress(study.name, runs, jobs)
        todo = []
        for run in runs:
            folder = results / run.path
            if is_finished(folder):
                check_settings(run, folder)
                progress.finished(run, RunRecord.load(folder).seconds, fresh=False)
            else:
                todo.append(run)
        where = f"Ray cluster {args.address}" if args.address else f"{jobs} at a time here"
        progress.print(f"{study.name}: {len(todo)} runs to go ({where})")
        # SIGTERM (a batch system, `kill`) stops the study like Ctrl-C: checkpoints kept.
        previous = signal.signal(signal.SIGTERM, signal.default_int_handler)
        try:
            if args.address:
                from offline_evolution.study.cluster import run_on_ray

                failed = run_on_ray(
                    todo, results, args.address, args.threads, args.retries, progress, args.spread
                )
            else:
                failed = run_local(todo, results, jobs, args.threads, progress)
        except StudyInterrupted:
            progress.print("interrupted; run the same command again to resume")
            return EXIT_INTERRUPTED
        finally:
            signal.signal(signal.SIGTERM, previous)
    progress.print("study finished" if not failed else f"{failed} runs failed (see run.log)")
    return EXIT_ERROR if failed else 0


def cmd_report(args) -> int:
    """Write the study's report from its results folder or its result table."""
    from offline_evolution.study.report import default_out, write_report
    from offline_evolution.study.spec import load_study

    study = load_study(args.study)
    results = Path(args.results)
    if not (results.is_dir() or results.is_file()):
        raise StudyError(f"--results {results}: no such folder or result table")
    out = Path(args.out) if args.out else default_out()
    try:
        md = write_report(study, results, out, args.replay_runs)
    except ValueError as e:
        raise StudyError(str(e)) from None
    print(f"{study.name}: report {md}")
    return 0


def cmd_compact(args) -> int:
    """Write the study's compact result table from its results folder."""
    from offline_evolution.study.report import default_out, read_results
    from offline_evolution.study.spec import load_study
    from offline_evolution.study.table import write_table

    study = load_study(args.study)
    results = Path(args.results)
    if not results.is_dir():
        raise StudyError(f"--results {results}: no such folder")
    out = Path(args.out) if args.out else default_out() / f"{study.name}.results.json"
    settings, _ = read_results(study, results, args.replay_runs)
    if not any(s.runs for s in settings):
        raise StudyError(f"{results}: no finished run of study {study.name}")
    write_table(study, settings, out, args.results, args.source, args.replay_runs)
    runs = sum(len(s.runs) for s in settings)
    print(f"{study.name}: {runs} runs of {len(settings)} settings in {out}")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``evorbc-study``; returns the exit status."""
    from evorbc_ros.arbitrator import ArbitratorError
    from evorbc_ros.repertoire import RepertoireError
    from offline_evolution.study.run import RunError

    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except (StudyError, ConfigError, RunError, ArbitratorError, RepertoireError) as e:
        print(f"evorbc-study: error: {e}", file=sys.stderr)
        return EXIT_ERROR
    except KeyboardInterrupt:
        print("evorbc-study: aborted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except Exception as e:
        return report_unexpected("evorbc-study", e)


if __name__ == "__main__":
    sys.exit(main())
