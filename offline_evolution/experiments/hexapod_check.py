"""Check the hexapod experiment against the paper (Sec. V-B and V-C).

:mod:`offline_evolution.experiments.legged_check` for the hexapod: EvoRBC arbitrators for
seeds 1..N (Table I: 200 generations, polar mapping) and standard NEAT for seeds 1..M with
the equal-budget generations (200 + 455), reported next to the paper's values
(docs/paper-check.md).

Run: ``python -m offline_evolution.experiments.hexapod_check --repertoire REP.json
--out DIR [--seeds 3] [--standard-seeds 1] [--summarise-only]``
"""

from __future__ import annotations

from pathlib import Path

from offline_evolution.experiments import legged_check


def summarise(repertoire: Path, out: Path, seeds: list[int], standard_seeds: list[int]) -> str:
    """The hexapod's table (``OUT/hexapod-check.md``) and curves (``.png``)."""
    return legged_check.summarise(repertoire, out, seeds, standard_seeds, "hexapod")


def main() -> None:
    """Command-line entry point."""
    legged_check.main("hexapod", "hexapod_check")


if __name__ == "__main__":
    main()
