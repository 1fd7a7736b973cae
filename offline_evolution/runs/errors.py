"""The one error a run tells its user: a bad input, or a run stopped, in one line."""

from __future__ import annotations

#: Exit status of a failed command, and of one stopped by Ctrl-C/SIGTERM (128 + SIGINT).
EXIT_ERROR = 1
EXIT_INTERRUPTED = 130


class UserError(Exception):
    """A user-facing error: printed as one line, exit status ``code``.

    Raised by the runs (:mod:`offline_evolution.runs`) for what the user can act on: a bad
    option, file or combination, a locked output, an interrupted run.
    """

    def __init__(self, message: str, code: int = EXIT_ERROR) -> None:
        super().__init__(message)
        self.code = code
