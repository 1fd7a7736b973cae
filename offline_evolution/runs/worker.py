"""One step of a study's run in a process: ``python -P -m offline_evolution.runs.worker SPEC``.

A study runs each step (a repertoire, then an arbitrator) in a process of its own, so
that the study can stop it (SIGINT: it checkpoints), lose it to a kill or the OOM killer
without harm, and count its CPU time; the step is the run API called in that process,
not the command line. ``SPEC`` is JSON: ``{"run": "repertoire" | "arbitrator",
"settings": {...}, "workers": N | null, "quiet": bool}``, the settings as
:func:`~.command_line.as_dict` writes them. The process prints what ``evorbc-evolve``
would (the study keeps it in ``run.log``) and exits with its status: 0, 1 on an error,
130 when interrupted (docs/design.md section 18).
"""

from __future__ import annotations

import json
import sys
from collections.abc import Sequence

from offline_evolution.runs.frame import one_line_errors


def spec(run, workers: int | None, quiet: bool) -> str:
    """The ``SPEC`` of the settings ``run`` (``RepertoireRun`` or ``ArbitratorRun``)."""
    from offline_evolution.runs.arbitrator import ArbitratorRun
    from offline_evolution.runs.command_line import as_dict

    kind = "arbitrator" if isinstance(run, ArbitratorRun) else "repertoire"
    return json.dumps({"run": kind, "settings": as_dict(run), "workers": workers, "quiet": quiet})


def _step(text: str) -> int:
    """Run the step ``text`` (a ``SPEC``) as the terminal shows it."""
    from evorbc_ros.controller_kinds import controller_kind
    from offline_evolution.runs import terminal
    from offline_evolution.runs.arbitrator import ArbitratorRun
    from offline_evolution.runs.repertoire import RepertoireRun

    data = json.loads(text)
    settings, workers, quiet = data["settings"], data["workers"], data["quiet"]
    if data["run"] == "arbitrator":
        run = ArbitratorRun(**{**settings, "kind": controller_kind(settings["kind"])})
        return terminal.arbitrator(run, workers, quiet)
    return terminal.repertoire(RepertoireRun(**settings), workers, quiet)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point: the exit status of the step ``argv[0]``."""
    (text,) = sys.argv[1:] if argv is None else argv
    return one_line_errors("evorbc-evolve", lambda: _step(text))


if __name__ == "__main__":
    sys.exit(main())
