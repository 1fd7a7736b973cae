"""The simulated world: robot motion models, mazes, sensors and the PyBullet bridge.

``import sim_bridge`` is light: each name below imports its module (and with it numba)
when first used (docs/design.md section 19).

The public API (``n`` primitives; lengths in m, angles in rad):

* :class:`SimulatedRobot`: the protocol of a robot the offline search drives: its
  ``parameter_specs``, ``max_reach(eval_time)`` m and ``evaluate_primitives(genes (n,
  d), eval_time) ->`` :class:`PrimitiveOutcome`.
* :class:`PrimitiveOutcome`: ``x, y (n,)`` m and ``heading (n,)`` rad after T seconds
  from rest (start frame: x forward, y left), ``path (n,)`` m, and ``max_tilt (n,)`` rad
  for legged robots; what the quality metrics score.
* :class:`Maze` and :func:`load_named_maze`: a maze (walls, start region, target) from
  ``config/mazes/`` or a file.
"""

import evorbc_ros
from evorbc_ros.lazy_exports import lazy_exports
from evorbc_ros.numba_caches import drop_stale_caches

_EXPORTS = {
    "Maze": "sim_bridge.maze",
    "PrimitiveOutcome": "sim_bridge.robots.base",
    "SimulatedRobot": "sim_bridge.robots.base",
    "load_named_maze": "sim_bridge.maze",
}
__all__ = sorted(_EXPORTS)
# Caches left by an earlier version whose modules have moved break numba (see numba_caches).
drop_stale_caches(__path__[0], evorbc_ros.__path__[0])
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
