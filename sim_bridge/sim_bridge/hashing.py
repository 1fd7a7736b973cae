"""A counter-based uniform number: noise that depends only on its key and counters.

The 4WS episode kernel's rangefinder noise and dropouts (docs/design.md section 21) and a
slipping wheel's traction (:mod:`sim_bridge.four_ws.damaged`) draw from it, so an episode's
noise does not depend on threads, workers or other episodes, and the bridge reproduces it.
"""

from __future__ import annotations

import numba as nb
import numpy as np


@nb.njit(cache=True)
def hash_uniform(key, cycle, index, salt):
    """A uniform number in [0, 1) from ``(key, cycle, index, salt)`` (splitmix64's mixer)."""
    z = np.uint64(key) + np.uint64(cycle * 1024 + index * 4 + salt + 1) * np.uint64(
        0x9E3779B97F4A7C15
    )
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    z = z ^ (z >> np.uint64(31))
    return float(z >> np.uint64(11)) * (1.0 / 9007199254740992.0)
