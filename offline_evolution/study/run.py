"""One run of a study: the ordinary repertoire and arbitrator runs in the run's own folder.

A run folder (``RESULTS/<setting>/seed-NNN/``) holds, when the run is finished:

* ``repertoire.json.xz`` (EvoRBC runs): the ``evorbc-evolve repertoire`` file;
* ``arbitrator.json.xz``: the ``evorbc-evolve arbitrator`` or ``standard`` file, with the
  per-generation fitness history;
* ``run.json``: the run's settings and seed, the equivalent ``evorbc-evolve`` commands,
  the measured cost (wall and CPU seconds, host, threads) and a summary. It is written
  last, atomically: a run is finished exactly when it exists, and the folder is the
  single record of the run.

Each step runs the run API (:mod:`offline_evolution.runs`) in a worker process of its own
(:mod:`offline_evolution.runs.worker`), so that it can be stopped, killed or lost alone
and its CPU time counted. While a run is under way the folder holds the steps' checkpoints
(``*.checkpoint.*``); running the same run again resumes from them, so a run killed at any
point loses at most the work since its last checkpoint and then gives the same files as a
run that was never interrupted (the commands are seeded and resume bit for bit).
Finished files are compressed with xz (a 4ws-5 arbitrator file of 300 generations
shrinks from 84 kB to about 12 kB), so that finished studies stay small enough to keep in
the repository.
"""

from __future__ import annotations

import contextlib
import ctypes
import json
import lzma
import os
import platform
import shutil
import signal
import subprocess
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path

from evorbc_ros.atomic_io import atomic_write, special_file_kind
from offline_evolution.runs.errors import EXIT_INTERRUPTED
from offline_evolution.runs.worker import spec
from offline_evolution.study.spec import REPERTOIRE_KEYS, Run
from sim_bridge.cluster_pool import CLUSTER_VARIABLE

RUN_FILE = "run.json"
FORMAT = "evorbc-study-run"
VERSION = 1
#: The worker process of a step; -P: never import the checkout's ROS package folders
#: from the current folder (docs/design.md section 10).
WORKER = (sys.executable, "-P", "-m", "offline_evolution.runs.worker")


class RunError(Exception):
    """A run failed; the message names the run and the command's last output line."""


class RunInterrupted(Exception):
    """A run was stopped by a signal; its checkpoint holds the finished work."""


@dataclass(frozen=True)
class RunRecord:
    """What a finished run's ``run.json`` says (the parts the runner uses)."""

    path: Path
    settings: dict
    seconds: float  # wall time of this run's commands, summed over resumes
    cpu_seconds: float
    summary: dict

    @classmethod
    def load(cls, folder: Path) -> RunRecord:
        """Read ``folder/run.json``."""
        data = json.loads((folder / RUN_FILE).read_text(encoding="utf-8"))
        if data.get("format") != FORMAT:
            raise RunError(f"{folder / RUN_FILE}: not a study run file")
        return cls(folder, data["settings"], data["seconds"], data["cpu_seconds"], data["summary"])


def is_finished(folder: Path) -> bool:
    """True when the run in ``folder`` has its ``run.json``."""
    return (folder / RUN_FILE).is_file()


def check_settings(run: Run, folder: Path) -> None:
    """Refuse a finished run made with other settings (another protocol, an edited file).

    Raises:
        RunError: naming the folder and the first setting that differs.
    """
    record = RunRecord.load(folder)
    wanted = run.recorded_settings()
    if record.settings != wanted:
        key = next(
            k
            for k in sorted(set(record.settings) | set(wanted))
            if record.settings.get(k) != wanted.get(k)
        )
        raise RunError(
            f"{folder}: was run with {key} = {record.settings.get(key)!r}, not "
            f"{wanted.get(key)!r}; use another results folder for another protocol"
        )


def steps(run: Run) -> list:
    """The runs (``RepertoireRun``, ``ArbitratorRun``) of ``run``, in order.

    Only the keys the setting names are given; everything else comes from the robot's
    shipped settings files (Table I), as for any run started by hand. Outputs are
    relative to the run's folder; the fitness curve goes to a scratch name that is
    removed once the run is finished (the study report draws its own figures from the
    histories).
    """
    from evorbc_ros.controller_kinds import EVORBC, STANDARD
    from offline_evolution.runs.arbitrator import ArbitratorRun
    from offline_evolution.runs.repertoire import RepertoireRun

    v = run.values
    given = {k: _TYPES[k](v[k]) for k in _TYPES if k in v}
    plot = "fitness-curve.png"
    if run.approach != "evorbc":
        return [
            ArbitratorRun(
                kind=STANDARD,
                robot=v["robot"],
                seed=run.seed,
                equal_budget=bool(v.get("equal_budget")),
                generations=given.get("generations"),
                out="arbitrator.json",
                plot=plot,
            )
        ]
    repertoire = RepertoireRun(
        robot=v["robot"],
        seed=run.seed,
        out="repertoire.json",
        **{k: given[k] for k in REPERTOIRE_KEYS if k in given},
    )
    arbitrator = ArbitratorRun(
        kind=EVORBC,
        repertoire="repertoire.json",
        seed=run.seed,
        mapping=given.get("mapping"),
        generations=given.get("generations"),
        out="arbitrator.json",
        plot=plot,
    )
    return [repertoire, arbitrator]


#: Setting key -> its type in the run settings (the study file holds checked values).
_TYPES = {
    "metric": str,
    "bin_size": float,
    "eval_time": float,
    "initial_batch": int,
    "batch_size": int,
    "iterations": int,
    "archive": str,
    "variation": str,
    "mapping": str,
    "generations": int,
}


def commands(run: Run, workers: int | None = None) -> list[list[str]]:
    """The ``evorbc-evolve`` arguments equivalent to the steps of ``run`` (its record).

    ``workers`` caps a PyBullet robot's simulation processes (``--workers``; the 4WS
    kernels ignore it), so a run takes the CPUs it was given and no more.
    """
    from offline_evolution.runs.command_line import command_line

    tail = ["--quiet"] + (["--workers", str(workers)] if workers else [])
    return [[*command_line(step), *tail] for step in steps(run)]


#: Every file a run writes in its folder (the commands' outputs, checkpoints and log).
RUN_FILES = (
    "run.log",
    "repertoire.json",
    "repertoire.json.xz",
    "repertoire.json.checkpoint.npz",
    "arbitrator.json",
    "arbitrator.json.xz",
    "arbitrator.json.checkpoint.json",
    "fitness-curve.png",
)


def check_run_files(folder: Path) -> None:
    """Refuse a run folder where a file the run writes is a device, a pipe or a folder.

    Checked before the run starts (a named pipe as ``run.log`` would block it for good;
    a device would be replaced by the first write: docs/design.md section 12).

    Raises:
        RunError: naming the file and what it is.
    """
    for name in (*RUN_FILES, RUN_FILE, SPENT_FILE):
        kind = special_file_kind(folder / name)
        if kind:
            raise RunError(
                f"{folder / name}: is {kind}, not a regular file; remove it and run the study again"
            )


def _die_with_parent() -> None:
    """Child pre-exec hook: get SIGKILL when the runner dies (Linux prctl).

    A run lost with its runner (a killed worker, a lost cluster node) must not keep
    writing its checkpoint while the retried run resumes from it.
    """
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG


def _xz(src: Path) -> Path:
    """Compress ``src`` to ``src.xz`` atomically and remove ``src``."""
    dest = src.with_name(src.name + ".xz")
    data = lzma.compress(src.read_bytes(), preset=9 | lzma.PRESET_EXTREME)
    atomic_write(dest, lambda f: f.write(data), binary=True)
    src.unlink()
    return dest


def read_json_xz(path: Path) -> dict:
    """A compressed (``.xz``) or plain JSON file."""
    raw = path.read_bytes()
    if path.suffix == ".xz":
        raw = lzma.decompress(raw)
    return json.loads(raw)


def _summary(folder: Path) -> dict:
    arb = read_json_xz(folder / "arbitrator.json.xz")
    evo = arb.get("evolution", {})
    out = {
        "best_fitness": evo.get("best_fitness"),
        "best_generation": evo.get("best_generation"),
        "generations": len(evo.get("history", [])),
    }
    post = evo.get("post_evaluation") or {}
    if post:
        out["post_fitness"] = post.get("fitness")
        out["post_reached"] = post.get("reached")
    rep_file = folder / "repertoire.json.xz"
    if rep_file.exists():
        rep = read_json_xz(rep_file)
        out["repertoire"] = rep.get("summary", {})
    return out


#: Commands running now (all threads), so that a stop request reaches every one.
_LIVE: set[subprocess.Popen] = set()
_LIVE_LOCK = threading.Lock()


def interrupt_all() -> None:
    """Ask every running command to checkpoint and stop (SIGINT, as Ctrl-C would)."""
    with _LIVE_LOCK:
        for proc in _LIVE:
            _ask_to_stop(proc)


def _ask_to_stop(proc: subprocess.Popen) -> None:
    """Send ``proc`` SIGINT, and remember it: its end is then an interruption."""
    proc.asked_to_stop = True
    with contextlib.suppress(ProcessLookupError):
        proc.send_signal(signal.SIGINT)


def died_of_signal(status: int) -> str:
    """``SIGSEGV (Segmentation fault)`` for the exit status ``-11`` of a killed command."""
    try:
        sig = signal.Signals(-status)
    except ValueError:
        return f"signal {-status}"
    return f"{sig.name} ({signal.strsignal(sig) or 'unknown'})"


def execute(run: Run, results: Path, threads: int = 1, cluster: str | None = None) -> RunRecord:
    """Run (or resume, or finish) ``run`` in its folder under ``results``.

    The commands' output goes to ``run.log`` in the run's folder.

    Args:
        threads: numba threads per command (``NUMBA_NUM_THREADS``), and a PyBullet
            robot's simulation processes; results do not depend on it.
        cluster: a Ray cluster address: a PyBullet robot's simulations go there
            (``EVORBC_CLUSTER``, one CPU per chunk in flight) instead of ``threads``
            local processes.

    Raises:
        RunInterrupted: a command was stopped by a signal (its checkpoint is kept).
        RunError: a command failed.
    """
    folder = results / run.path
    if is_finished(folder):
        check_settings(run, folder)
        return RunRecord.load(folder)
    folder.mkdir(parents=True, exist_ok=True)
    check_run_files(folder)
    env = dict(os.environ, NUMBA_NUM_THREADS=str(threads), PYTHONUNBUFFERED="1")
    env.pop(CLUSTER_VARIABLE, None)
    if cluster:
        env[CLUSTER_VARIABLE] = cluster
    workers = None if cluster else threads
    with open(folder / "run.log", "a", encoding="utf-8") as log:
        for step, cmd in zip(steps(run), commands(run, workers), strict=True):
            target = folder / step.out
            if target.exists() or target.with_name(target.name + ".xz").exists():
                continue  # finished by an earlier attempt
            log.write(f"$ evorbc-evolve {' '.join(cmd)}\n")
            log.flush()
            status, asked = _run_step([*WORKER, spec(step, workers, quiet=True)], folder, env, log)
            if status < 0 and not asked:
                # A crash (SIGSEGV), the OOM killer (SIGKILL) or someone's kill: a failed
                # run, not a stop the study asked for (docs/design.md section 15).
                raise RunError(
                    f"run {run.path}: {cmd[0]} died of signal {died_of_signal(status)}; "
                    f"its checkpoint, if any, is kept; see {folder / 'run.log'}"
                )
            if status == EXIT_INTERRUPTED or status < 0:
                raise RunInterrupted(str(run.path))
            if status != 0:
                raise RunError(f"{run.path}: {cmd[0]} failed (status {status}): {_tail(folder)}")
    for name in ("repertoire.json", "arbitrator.json"):
        if (folder / name).exists():
            _xz(folder / name)
    (folder / "fitness-curve.png").unlink(missing_ok=True)
    wall, cpu = _spent(folder)
    record = {
        "format": FORMAT,
        "version": VERSION,
        "settings": run.recorded_settings(),
        "commands": [" ".join(["evorbc-evolve", *c]) for c in commands(run)],
        "seconds": round(wall, 3),
        "cpu_seconds": round(cpu, 3),
        "threads": threads,
        "host": platform.node(),
        "machine": f"{platform.machine()}, {os.cpu_count()} cores",
        "finished": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "summary": _summary(folder),
    }
    text = json.dumps(record, indent=1, sort_keys=True) + "\n"
    atomic_write(folder / RUN_FILE, lambda f: f.write(text))
    (folder / SPENT_FILE).unlink(missing_ok=True)
    return RunRecord.load(folder)


def _run_step(cmd: list[str], folder: Path, env: dict, log) -> tuple[int, bool]:
    """Run one step's worker process to its end; add its wall and CPU time to the tally.

    Returns:
        The exit status (negative: killed by that signal), and whether the runner asked
        the command to stop (:func:`interrupt_all`, a cancelled Ray task).
    """
    start = time.monotonic()
    proc = subprocess.Popen(
        cmd,
        cwd=folder,
        env=env,
        stdout=log,
        stderr=subprocess.STDOUT,
        preexec_fn=_die_with_parent,
        # Its own session: a terminal's Ctrl-C reaches only the runner, which forwards one
        # SIGINT (a second one would make the command abort without saving).
        start_new_session=True,
    )
    with _LIVE_LOCK:
        _LIVE.add(proc)
    try:
        while True:
            try:
                # wait4 gives this child's own CPU time (RUSAGE_CHILDREN would mix the
                # runs of other threads).
                _, status, usage = os.wait4(proc.pid, 0)
                break
            except KeyboardInterrupt:
                # Stopped in this thread (a cancelled Ray task): ask the command to save
                # its checkpoint, and wait for it.
                _ask_to_stop(proc)
        proc.returncode = os.waitstatus_to_exitcode(status)
    finally:
        with _LIVE_LOCK:
            _LIVE.discard(proc)
    wall, cpu = _spent(folder)
    wall += time.monotonic() - start
    cpu += usage.ru_utime + usage.ru_stime
    text = json.dumps({"seconds": wall, "cpu_seconds": cpu})
    atomic_write(folder / SPENT_FILE, lambda f: f.write(text))
    return proc.returncode, getattr(proc, "asked_to_stop", False)


#: Wall and CPU seconds of an unfinished run's earlier attempts.
SPENT_FILE = ".spent.json"


def _spent(folder: Path) -> tuple[float, float]:
    """Wall and CPU seconds spent on the run so far (``.spent.json``)."""
    try:
        data = json.loads((folder / SPENT_FILE).read_text())
        return float(data["seconds"]), float(data["cpu_seconds"])
    except (OSError, ValueError, KeyError, TypeError):
        return 0.0, 0.0


def _tail(folder: Path) -> str:
    try:
        lines = (folder / "run.log").read_text(encoding="utf-8").strip().splitlines()
    except OSError:
        return "see run.log"
    return lines[-1] if lines else "no output"


def remove_partial(folder: Path) -> None:
    """Delete an unfinished run's folder (``--restart`` of a study run)."""
    if folder.exists() and not is_finished(folder):
        shutil.rmtree(folder)
