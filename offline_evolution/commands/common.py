"""Option helpers shared by the subcommands: argument types, resume and worker options."""

from __future__ import annotations

import argparse
import math

from offline_evolution import bounds
from sim_bridge.cli_support import integer_in

#: ``integer >= low`` argument types (kept under this name for the subcommands).
at_least = integer_in


def count(text: str) -> int:
    """Argparse type: an integer >= 0."""
    return integer_in(0)(text)


def positive_float(text: str) -> float:
    """Argparse type: a finite number > 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not (value > 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text!r}")
    return value


def add_resume_options(
    parser: argparse.ArgumentParser, suffix: str, unit: str, every: int | None = None
) -> None:
    """``--checkpoint``, ``--checkpoint-every`` and ``--restart`` of a resumable run.

    Args:
        suffix: the default checkpoint's, after OUT (``.checkpoint.json``).
        unit: what a run counts between checkpoints (``generations``).
        every: the default of ``--checkpoint-every`` (None: the run settings').
    """
    parser.add_argument(
        "--checkpoint",
        metavar="FILE",
        help=f"resume checkpoint (default: OUT{suffix}); a run resumes from it automatically",
    )
    parser.add_argument(
        "--checkpoint-every",
        type=at_least(1),
        default=every,
        metavar="N",
        help=f"{unit} between checkpoints" + (f" (default: {every})" if every else ""),
    )
    parser.add_argument(
        "--restart",
        action="store_true",
        help="discard an existing checkpoint and start from scratch",
    )


def add_workers_option(parser: argparse.ArgumentParser) -> None:
    """``--workers N``: processes for PyBullet simulations (results do not depend on it)."""
    parser.add_argument(
        "--workers",
        type=integer_in(1, bounds.WORKERS),
        metavar="N",
        help="worker processes for robots simulated in PyBullet (default: one per core; "
        "with --cluster, one per cluster CPU); results are the same for any number",
    )
    parser.add_argument(
        "--cluster",
        metavar="ADDRESS",
        help="spread PyBullet simulations over the Ray cluster at ADDRESS (host:port, "
        "auto or ray://...; default: $EVORBC_CLUSTER, else this machine's cores)",
    )
