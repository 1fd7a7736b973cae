"""Resume checkpoints: numpy arrays plus a JSON header, in one ``.npz`` file.

Checkpoints are loaded with ``allow_pickle=False``: a checkpoint is data, never code, so a
file from elsewhere cannot run anything. They are written atomically, so an interruption
while saving leaves the previous checkpoint intact. NEAT runs keep theirs as plain JSON
(:func:`load_json_checkpoint`). Any file may be given as a checkpoint by mistake, so
``--restart`` deletes only one that declares the run's kind (:func:`discard_checkpoint`).
"""

from __future__ import annotations

import io
import json
import math
import os
import zipfile
from pathlib import Path

import numpy as np

from evorbc_ros.atomic_io import atomic_write
from evorbc_ros.input_files import DATA_LIMIT, is_regular, read_regular
from evorbc_ros.json_files import first_difference, parse_json
from evorbc_ros.limits import CHECKPOINT_ARRAY_BYTES
from evorbc_ros.repertoire_checks import version_problem

_HEADER = "__header__"
#: The checkpoint format version written from 2026-11-28 on; a checkpoint without one is
#: of the same layout (written before the key existed).
VERSION = 1


class CheckpointError(ValueError):
    """A checkpoint cannot be used; the message names the file and the reason.

    ``discardable`` is False when the file is not recognisably a checkpoint of the run's
    kind (another file given as ``--checkpoint`` by mistake): it must not be deleted.
    """

    def __init__(self, message: str, discardable: bool = True) -> None:
        super().__init__(message)
        self.discardable = discardable


class Interrupted(Exception):
    """A run was asked to stop; finished work is in the checkpoint."""

    def __init__(self, iteration: int, checkpoint: str | None, during: str | None = None) -> None:
        super().__init__(f"stopped after iteration {iteration}")
        self.iteration = iteration
        self.checkpoint = checkpoint
        # What was running past the last iteration when the run stopped (a NEAT run's
        # post-evaluation), or None between iterations.
        self.during = during


def save_checkpoint(path: str | os.PathLike, header: dict, arrays: dict[str, np.ndarray]):
    """Write ``header`` (JSON-safe) and ``arrays`` to ``path`` atomically."""
    buf = io.BytesIO()
    header = {"version": VERSION, **header}
    np.savez(buf, **{_HEADER: np.array(json.dumps(header))}, **arrays)
    atomic_write(path, lambda f: f.write(buf.getvalue()), binary=True)


#: What reading a damaged or foreign ``.npz`` can raise.
_READ_ERRORS = (OSError, ValueError, KeyError, zipfile.BadZipFile, EOFError)


def _reason(e: Exception) -> str:
    # numpy's advice about allow_pickle would invite loading the pickle: never do that.
    return "it holds pickled objects" if "pickle" in str(e) else str(e)


def _header(data, source: str) -> dict:
    """The JSON header of an open ``.npz``; CheckpointError (not discardable) if none."""
    if _HEADER not in data.files:
        raise CheckpointError(f"{source}: not a checkpoint (no header)", discardable=False)
    try:
        text = str(data[_HEADER])
    except _READ_ERRORS as e:
        raise CheckpointError(
            f"{source}: not a checkpoint ({_reason(e)})", discardable=False
        ) from None
    try:
        header = parse_json(text, f"{source}: header", "checkpoint", _NotJson, _bad)
    except _NotJson:
        raise CheckpointError(
            f"{source}: not a checkpoint (its header is not JSON)", discardable=False
        ) from None
    if not isinstance(header, dict):
        raise CheckpointError(f"{source}: not a checkpoint (bad header)", discardable=False)
    return header


class _NotJson(ValueError):
    """The text is not JSON (the caller says what that makes the file)."""


def _bad(message: str) -> CheckpointError:
    """A checkpoint that holds a value no run writes (a number beyond float range)."""
    return CheckpointError(message)


def _not_ours(message: str) -> CheckpointError:
    """The error for a file that is not recognisably a checkpoint: never to be deleted."""
    return CheckpointError(message, discardable=False)


def _read(path: str | os.PathLike) -> bytes:
    """The bytes of a checkpoint file: a regular file of a sane size, else CheckpointError."""
    return read_regular(path, "checkpoint", _not_ours, DATA_LIMIT)


def _open(path: str | os.PathLike):
    """``np.load`` of a file that is an ``.npz`` archive, else CheckpointError."""
    source = str(path)
    data = io.BytesIO(_read(path))
    # Checked first: numpy reads any other file as a pickle and then complains about
    # allow_pickle, which says nothing useful about a JSON or text file.
    if not zipfile.is_zipfile(data):
        raise CheckpointError(
            f"{source}: not a checkpoint (not an .npz archive)", discardable=False
        )
    try:
        check_npz_sizes(data, source)
        return np.load(data, allow_pickle=False)
    except CheckpointError:
        raise
    except _READ_ERRORS as e:
        raise CheckpointError(
            f"{source}: not a checkpoint ({_reason(e)})", discardable=False
        ) from None


def check_npz_sizes(data: io.BytesIO, source: str) -> None:
    """Refuse an ``.npz`` whose arrays would inflate to too much, before inflating any.

    Each member's ``.npy`` header (a few hundred bytes at its start) gives the array's
    shape and dtype; shape x itemsize must be what the member's declared size leaves after
    the header (zipfile never inflates past the declared size), and the arrays together
    must stay within :data:`~evorbc_ros.limits.CHECKPOINT_ARRAY_BYTES`. A zip bomb of a
    few MB that would inflate to 16 GiB is refused here rather than ending in MemoryError.

    Raises:
        CheckpointError: naming the member and what is wrong (not ``discardable`` if the
            file is no ``.npz`` of arrays at all).
    """
    total = 0
    with zipfile.ZipFile(data) as archive:
        for info in archive.infolist():
            name = info.filename
            with archive.open(info) as member:
                try:
                    version = np.lib.format.read_magic(member)
                    read = (
                        np.lib.format.read_array_header_1_0
                        if version == (1, 0)
                        else np.lib.format.read_array_header_2_0
                    )
                    shape, _, dtype = read(member)
                    header_size = member.tell()
                except ValueError as e:
                    raise CheckpointError(
                        f"{source}: not a checkpoint ({name} is not a numpy array: {e})",
                        discardable=False,
                    ) from None
            size = math.prod(shape) * dtype.itemsize
            if dtype.hasobject:  # a pickle: never loaded (allow_pickle=False names it)
                size = info.file_size
            elif size != info.file_size - header_size:
                raise CheckpointError(
                    f"{source}: not a usable checkpoint ({name} declares shape {shape} of "
                    f"{dtype}, {size:,} bytes, but holds {info.file_size - header_size:,})"
                )
            total += size
            problem = CHECKPOINT_ARRAY_BYTES.problem(total, "once inflated")
            if problem:
                raise CheckpointError(f"{source}: not a usable checkpoint ({problem})")
    data.seek(0)


def load_checkpoint(path: str | os.PathLike) -> tuple[dict, dict[str, np.ndarray]]:
    """Read a checkpoint written by :func:`save_checkpoint`.

    Raises:
        CheckpointError: the file is missing or not a checkpoint (then not
            ``discardable``: it may be someone's file given by mistake), or a checkpoint
            whose arrays cannot be read.

    """
    with _open(path) as data:
        header = _header(data, str(path))
        check_version(header, str(path))
        try:
            arrays = {k: data[k] for k in data.files if k != _HEADER}
        except _READ_ERRORS as e:
            raise CheckpointError(f"{path}: not a usable checkpoint ({_reason(e)})") from None
    return header, arrays


def load_json_checkpoint(path: str | os.PathLike) -> dict:
    """Read a JSON checkpoint (NEAT runs write one: genomes are nested records, not arrays).

    Raises:
        CheckpointError: unreadable, not JSON or not a JSON object (not ``discardable``).

    """
    try:
        data = parse_json(_read(path).decode("utf-8"), str(path), "checkpoint", _NotJson, _bad)
    except (UnicodeDecodeError, _NotJson):
        raise CheckpointError(f"{path}: not a checkpoint (not JSON)", discardable=False) from None
    if not isinstance(data, dict):
        raise CheckpointError(f"{path}: not a checkpoint (not a JSON object)", discardable=False)
    return data


def check_version(header: dict, source: str) -> None:
    """Refuse a checkpoint whose ``version`` is not this format's (an int; absent is 1).

    Called once the file is known to be a checkpoint (``--restart`` may then discard it).

    Raises:
        CheckpointError: naming the file and the version found.
    """
    if "version" not in header:
        return
    problem = version_problem(header["version"], "checkpoint", VERSION)
    if problem:
        raise CheckpointError(f"{source}: {problem}")


def checkpoint_kind(path: str | os.PathLike) -> str | None:
    """The ``kind`` a checkpoint (``.npz`` or JSON) declares; None for any other file."""
    if not is_regular(path):
        return None  # a folder, FIFO or device: opening it could block or never end
    try:
        if zipfile.is_zipfile(path):
            with _open(path) as data:
                header = _header(data, str(path))  # the arrays may be damaged
        else:
            header = load_json_checkpoint(path)
    except CheckpointError:
        return None
    kind = header.get("kind")
    return kind if isinstance(kind, str) else None


def discard_checkpoint(path: str | os.PathLike, kind: str, what: str) -> None:
    """Delete the checkpoint at ``path`` (``--restart``) if it is recognisably one.

    Args:
        kind: the ``kind`` the run's checkpoints declare; any other file is left alone.
        what: what such a checkpoint is called in the message ("MAP-Elites checkpoint").

    Raises:
        CheckpointError: ``path`` holds something else, which is left as it is.

    """
    path = Path(path)
    if not path.exists():
        return
    if path.is_dir() or checkpoint_kind(path) != kind:
        raise CheckpointError(f"{path}: not a {what}", discardable=False)
    path.unlink()


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
