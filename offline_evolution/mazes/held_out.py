"""The held-out generated mazes: kept for evaluation, never trained on (docs/design.md section 21).

The held-out set is the generator's mazes of seed :data:`HELD_OUT_SEED` (``evorbc-evolve
evaluate --generated N`` uses mazes ``0 .. N-1`` of it). A generated maze is named
``<prefix><seed>-<index>`` (:func:`~offline_evolution.mazes.generator.generate_maze`), so a
maze file saved from the held-out set is known by its name.
"""

from __future__ import annotations

import re

#: Generator seed of the held-out mazes.
HELD_OUT_SEED = 21021

_HELD_OUT_NAME = re.compile(rf"^[A-Za-z_]*{HELD_OUT_SEED}-\d+$")


def is_held_out(name: str) -> bool:
    """True if ``name`` is a held-out generated maze's name (``gen21021-007``)."""
    return bool(_HELD_OUT_NAME.match(name))
