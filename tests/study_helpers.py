"""A tiny study for the study-runner tests, and how to compare two results folders."""

import json
import lzma
import subprocess
import sys
import time
from pathlib import Path

#: Two EvoRBC runs of the 2ws-2 robot with a small repertoire budget and 20 generations
#: (a NEAT checkpoint is written after generation 10 and stays until the run ends, a
#: window long enough to find both runs between their checkpoint and their end).
TINY_STUDY = """
study: tiny
seeds: 2
grid:
  approach: [evorbc]
fixed:
  robot: 2ws-2
  initial_batch: 500
  batch_size: 100
  iterations: 20
  generations: 20
"""

#: Keys that hold measured times, which differ between any two runs.
TIMING_KEYS = {"seconds", "evaluation_seconds", "cpu_seconds", "finished", "host", "threads"}


def write_tiny_study(folder: Path) -> Path:
    path = folder / "tiny.yaml"
    path.write_text(TINY_STUDY)
    return path


def study_command(*args) -> list[str]:
    return [sys.executable, "-m", "offline_evolution.study.cli", *map(str, args)]


def run_study(*args, timeout=600) -> subprocess.CompletedProcess:
    return subprocess.run(study_command(*args), capture_output=True, text=True, timeout=timeout)


def _strip(value):
    if isinstance(value, dict):
        return {k: _strip(v) for k, v in value.items() if k not in TIMING_KEYS}
    if isinstance(value, list):
        return [_strip(v) for v in value]
    return value


def results_contents(folder: Path) -> dict:
    """Every finished run's files, parsed, without measured times (path -> data)."""
    out = {}
    for path in sorted(folder.rglob("*")):
        if path.name.endswith(".json.xz"):
            out[str(path.relative_to(folder))] = _strip(
                json.loads(lzma.decompress(path.read_bytes()))
            )
        elif path.name == "run.json":
            out[str(path.relative_to(folder))] = _strip(json.loads(path.read_text()))
    return out


def wait_for(condition, timeout: float, what: str):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        found = condition()
        if found:
            return found
        time.sleep(0.2)
    raise AssertionError(f"timed out waiting for {what}")


def first_checkpoint(results: Path):
    return next(results.rglob("arbitrator.json.checkpoint.json"), None)


def checkpoints(results: Path) -> int:
    """How many runs are between their first NEAT checkpoint and their end."""
    return len(list(results.rglob("arbitrator.json.checkpoint.json")))
