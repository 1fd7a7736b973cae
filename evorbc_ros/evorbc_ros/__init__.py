"""EvoRBC onboard control: robot definitions, repertoires, arbitrators and ROS 2 nodes.

Everything in this package runs on the robot and needs numpy and pyyaml only (plus rclpy
for the nodes). ``import evorbc_ros`` imports nothing else: each name below loads its
module when first used (docs/design.md section 20).

The public API (shapes: ``n`` primitives, ``d`` locomotion parameters; lengths in m,
angles in rad, behaviours in the primitive's start frame, x forward and y left):

* :class:`Repertoire`: the primitives MAP-Elites found. ``genes (n, d)`` in [-1, 1],
  ``behaviour (n, 2)`` m (displacement after ``eval_time`` s), ``heading (n,)`` rad,
  ``quality (n,)``; ``load``/``save`` JSON files, validated (:class:`RepertoireError`).
* :class:`ParameterSpec`: one locomotion parameter (name, SI unit, ``[low, high]``); gene
  ``g`` in [-1, 1] maps linearly onto it.
* :class:`ArbitratorFile`: an evolved controller's file (network, sensor layout, mapping,
  repertoire fingerprint); ``load``/``save``, validated (:class:`ArbitratorError`).
* :class:`Arbitrator`: the onboard EvoRBC controller, inputs ``(n_inputs,)`` -> network ->
  mapping -> the index of the primitive to run; :class:`DirectController`: a standard
  NEAT controller, inputs -> genes ``(d,)``.
* :class:`MappingFunction`: network outputs ``(m1, m2)`` in [0, 1]^2 -> a behaviour-space
  point (m), paper eq. 7-9; :class:`PrimitiveLookup`: that point -> the nearest
  primitive, in O(1); :func:`choose_primitive` does both (:data:`NO_PRIMITIVE` if the
  outputs are not finite).
* :class:`NetworkSpec`: a feed-forward or recurrent network as plain data;
  ``compile().activate`` (and ``reset()`` between episodes).
* :class:`SensorLayout`: the arbitrator's inputs in order (rangefinders, goal sectors,
  goal bearing), ``n_inputs`` of them.
* :class:`ConfigError`: a settings file or value that is not valid (one line naming it).
"""

from evorbc_ros.lazy_exports import lazy_exports
from evorbc_ros.numba_caches import drop_stale_caches

_EXPORTS = {
    "Arbitrator": "evorbc_ros.arbitrator",
    "ArbitratorError": "evorbc_ros.arbitrator",
    "ArbitratorFile": "evorbc_ros.arbitrator",
    "ConfigError": "evorbc_ros.config",
    "DirectController": "evorbc_ros.arbitrator",
    "MappingFunction": "evorbc_ros.mapping",
    "NO_PRIMITIVE": "evorbc_ros.mapping",
    "NetworkSpec": "evorbc_ros.network",
    "ParameterSpec": "evorbc_ros.robots.primitive",
    "PrimitiveLookup": "evorbc_ros.mapping",
    "Repertoire": "evorbc_ros.repertoire",
    "RepertoireError": "evorbc_ros.repertoire",
    "SensorLayout": "evorbc_ros.sensors",
    "choose_primitive": "evorbc_ros.mapping",
}
__all__ = sorted(_EXPORTS)
# Caches left by an earlier version whose modules have moved break numba (see numba_caches).
drop_stale_caches(__path__[0])
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
