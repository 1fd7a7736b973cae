"""Offline evolution for EvoRBC: MAP-Elites repertoires, NEAT arbitrators, tasks and plots.

``import offline_evolution`` is light: each name below imports its module (and with it
numba, pyribs or neat-python) when first used (docs/design.md section 20).

The public API (shapes: ``n`` primitives, ``d`` locomotion parameters, ``E`` episodes;
lengths in m, angles in rad, times in s):

Repertoires (paper Sec. III-A, Algorithm 1):

* :class:`MapElites`: one run with an ask/tell loop on plain arrays. ``ask() -> genes
  (n, d)`` in [-1, 1]; ``tell(genes (n, d), quality (n,), behaviour (n, 2) m, heading
  (n,) rad)``; ``repertoire()``; ``save``/``restore`` checkpoints. Evaluate with your own
  simulator or robot (give ``parameters`` and ``max_reach``), or with a simulated robot
  of this project (``step()``).
* :class:`MapElitesSettings`: budget, archive, variation and seed;
  :func:`load_repertoire_settings` reads them from ``config/repertoire/*.yaml``.
* :func:`generate_repertoire`: a simulated robot's run to the end, with checkpoints and
  progress (:class:`Progress`), as ``evorbc-evolve repertoire`` runs it.
* :func:`quality_metric`: a quality metric by name (paper Sec. III-A), ``outcome ->
  quality (n,)``.

Arbitrators (paper Sec. III-C):

* :class:`ArbitratorTask`: the protocol a task implements to evolve arbitrators on it
  (sensor layout, control period ``dt`` s, controllers, start rows, ``evaluate(networks,
  controller, starts) ->`` :class:`EpisodeResult` of ``(E,)`` arrays, ``describe``,
  ``close``).
* :class:`MazeTask` (the 4WS robots, compiled) and :class:`HexapodMazeTask` (PyBullet):
  the maze tasks, set by :class:`MazeTaskSettings`; :func:`eq5_fitness`, the paper's
  eq. 5 per episode.
* :func:`evolve_arbitrator`: NEAT on any task, seeded and checkpointed, for
  :class:`EvolutionSettings`, returning an :class:`EvolutionResult`;
  :func:`arbitrator_file` turns that into an :class:`~evorbc_ros.ArbitratorFile`.
* :class:`Interrupted`, :class:`CheckpointError`: a run asked to stop; an unusable
  checkpoint.
"""

import evorbc_ros
import sim_bridge
from evorbc_ros.lazy_exports import lazy_exports
from evorbc_ros.numba_caches import drop_stale_caches

_EXPORTS = {
    "ArbitratorTask": "offline_evolution.task_protocol",
    "CheckpointError": "offline_evolution.checkpoint",
    "EpisodeResult": "offline_evolution.task_protocol",
    "EvolutionResult": "offline_evolution.arbitrator.evolve",
    "EvolutionSettings": "offline_evolution.arbitrator.evolve",
    "HexapodMazeTask": "offline_evolution.maze_task.hexapod_task",
    "Interrupted": "offline_evolution.checkpoint",
    "MapElites": "offline_evolution.repertoire.map_elites",
    "MapElitesSettings": "offline_evolution.repertoire.settings",
    "MazeTask": "offline_evolution.maze_task.task",
    "MazeTaskSettings": "offline_evolution.maze_task.base",
    "Progress": "offline_evolution.repertoire.map_elites",
    "arbitrator_file": "offline_evolution.arbitrator.evolve",
    "eq5_fitness": "offline_evolution.maze_task.base",
    "evolve_arbitrator": "offline_evolution.arbitrator.evolve:evolve",
    "generate_repertoire": "offline_evolution.repertoire.map_elites",
    "load_repertoire_settings": "offline_evolution.repertoire.settings:load_settings",
    "quality_metric": "offline_evolution.quality",
}
__all__ = sorted(_EXPORTS)
# Caches left by an earlier version whose modules have moved break numba (see numba_caches).
drop_stale_caches(__path__[0], sim_bridge.__path__[0], evorbc_ros.__path__[0])
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
