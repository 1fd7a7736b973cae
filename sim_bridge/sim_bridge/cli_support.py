"""What the command-line programs (``evorbc-evolve``, ``evorbc-sim``, ``evorbc-study``) share.

* Argument errors in one line and status 2 (:class:`OneLineParser`, :func:`integer_in`).
* The last-resort report: whatever no check caught ends as one line and status 1, never a
  traceback (``EVORBC_DEBUG=1`` shows one).
* Output paths checked before a run, so that a typo costs nothing rather than a whole run.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from evorbc_ros.atomic_io import special_file_kind
from evorbc_ros.config import ConfigError

#: Set (to anything) to get the traceback of an internal error instead of one line.
DEBUG_VARIABLE = "EVORBC_DEBUG"
#: Exit status of a bad option (argparse's).
EXIT_USAGE = 2


class OneLineParser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (no usage block) and status 2.

    Every bad option value ends the same way, whether the parser or a later check finds
    it: ``evorbc-evolve arbitrator: error: argument --generations: expected an integer
    >= 1, got '0' (see evorbc-evolve arbitrator --help)``.
    """

    def error(self, message: str):
        """Print one line and exit with the usage status."""
        text = " ".join(message.split())
        self.exit(EXIT_USAGE, f"{self.prog}: error: {text} (see {self.prog} --help)\n")


def integer_in(low: int, high: int | None = None):
    """Argparse type: an integer in ``[low, high]`` (no upper bound if ``high`` is None)."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
        if value < low or (high is not None and value > high):
            bounds = f"from {low} to {high}" if high is not None else f">= {low}"
            raise argparse.ArgumentTypeError(f"expected an integer {bounds}, got {text!r}")
        return value

    parse.__name__ = f"integer >= {low}" if high is None else f"integer {low}-{high}"
    return parse


def report_unexpected(prog: str, error: Exception) -> int:
    """Report a failure that no check caught as one line; return the exit status 1.

    An :class:`OSError` is the system's word on a file (disk full, permission denied) and
    is shown as an error about that file; anything else is a bug, shown as an internal
    error, or raised again when ``EVORBC_DEBUG`` is set.
    """
    if isinstance(error, OSError):
        where = f"{error.filename}: " if error.filename else ""
        print(f"{prog}: error: {where}{error.strerror or error}", file=sys.stderr)
        return 1
    if os.environ.get(DEBUG_VARIABLE):
        raise error
    text = " ".join(str(error).split())  # one line, whatever the message holds
    print(
        f"{prog}: internal error: {type(error).__name__}: {text} "
        f"(set {DEBUG_VARIABLE}=1 for a traceback)",
        file=sys.stderr,
    )
    return 1


def check_output_file(path: str, option: str, picture: bool = False) -> None:
    """Refuse an output ``path`` that could not be written, before the work that makes it.

    Missing folders are created (the writer would create them too). With ``picture``, the
    suffix must name a format matplotlib writes, since it picks the format from it. An
    existing path must be a regular file (or a link to one, written through): a device, a
    named pipe or a socket would be replaced by the write, not written to.

    Raises:
        ConfigError: one line naming ``option``, the path and the problem.

    """
    if not str(path):
        raise ConfigError(f"{option} '': an empty name, expected a file name")
    target = Path(path)
    kind = special_file_kind(target)
    if kind == "a folder":
        raise ConfigError(f"{option} {path}: is a folder, expected a file name")
    if kind:
        # Every write renames a new file over its path, so a device or a pipe would be
        # replaced, not written to (docs/design.md section 12, "Writing").
        raise ConfigError(
            f"{option} {path}: is {kind}, not a regular file; outputs are written as new "
            "files, so give a file name"
        )
    target = Path(os.path.realpath(target))  # a link is written through to its target
    if picture:
        from matplotlib.backend_bases import FigureCanvasBase

        formats = sorted(FigureCanvasBase.get_supported_filetypes())
        if target.suffix.lower().lstrip(".") not in formats:
            raise ConfigError(
                f"{option} {path}: not a picture format that can be written; "
                f"end the name in one of .{', .'.join(formats)}"
            )
    folder = target.absolute().parent
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise ConfigError(
            f"{option} {path}: cannot create folder {folder} ({e.strerror})"
        ) from None
    if not os.access(folder, os.W_OK | os.X_OK):
        raise ConfigError(f"{option} {path}: folder {folder} is not writable")
