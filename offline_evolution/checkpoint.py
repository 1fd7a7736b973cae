"""Resume checkpoints: numpy arrays plus a JSON header, in one ``.npz`` file.

Checkpoints are loaded with ``allow_pickle=False``: a checkpoint is data, never code, so a
file from elsewhere cannot run anything. They are written atomically, so an interruption
while saving leaves the previous checkpoint intact.
"""

from __future__ import annotations

import io
import json
import os
import zipfile
from pathlib import Path

import numpy as np

from evorbc_ros.atomic_io import atomic_write
from evorbc_ros.json_files import first_difference

_HEADER = "__header__"


class CheckpointError(ValueError):
    """A checkpoint cannot be used; the message names the file and the reason."""


class Interrupted(Exception):
    """A run was asked to stop; finished work is in the checkpoint."""

    def __init__(self, iteration: int, checkpoint: str | None) -> None:
        super().__init__(f"stopped after iteration {iteration}")
        self.iteration = iteration
        self.checkpoint = checkpoint


def save_checkpoint(path: str | os.PathLike, header: dict, arrays: dict[str, np.ndarray]):
    """Write ``header`` (JSON-safe) and ``arrays`` to ``path`` atomically."""
    buf = io.BytesIO()
    np.savez(buf, **{_HEADER: np.array(json.dumps(header))}, **arrays)
    atomic_write(path, lambda f: f.write(buf.getvalue()), binary=True)


def load_checkpoint(path: str | os.PathLike) -> tuple[dict, dict[str, np.ndarray]]:
    """Read a checkpoint written by :func:`save_checkpoint`.

    Raises:
        CheckpointError: the file is missing, truncated or not a checkpoint.

    """
    source = str(path)
    if not Path(path).exists():
        raise CheckpointError(f"{source}: no such checkpoint")
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
        header = json.loads(str(arrays.pop(_HEADER)))
    except (OSError, ValueError, KeyError, zipfile.BadZipFile, EOFError) as e:
        raise CheckpointError(f"{source}: not a usable checkpoint ({e})") from None
    if not isinstance(header, dict):
        raise CheckpointError(f"{source}: not a usable checkpoint (bad header)")
    return header, arrays


def settings_mismatch(saved: dict, current: dict, where: str = "the checkpoint") -> str | None:
    """Describe the first setting that differs between a saved run and this one.

    Nested dicts are compared key by key, so the message names the innermost setting
    (``geometry.max_joint_velocity is 10.0 in the checkpoint but 5.0 now``).
    """
    return first_difference(saved, current, where)


def check_same_robot(path: str | os.PathLike, saved: dict | None, current: dict | None) -> None:
    """Refuse a checkpoint written for another simulated robot (geometry, physics).

    Unlike a repertoire, a checkpoint that records none only matches a run that has none
    (the 4WS kinematics): checkpoints of the first hexapod design recorded nothing.

    Raises:
        CheckpointError: naming the file and the first setting that differs.

    """
    mismatch = settings_mismatch({"simulation": saved}, {"simulation": current})
    if mismatch:
        raise CheckpointError(f"{path}: was written for a different robot ({mismatch})")
