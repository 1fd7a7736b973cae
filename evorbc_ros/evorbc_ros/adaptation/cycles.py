"""The settled-cycle rule's state as arrays, and its steps as plain numba-compilable functions.

:class:`~evorbc_ros.adaptation.online.OnlineAdaptation` (onboard) and the offline episode
kernel (docs/design/adaptation.md) run these same functions, plain or compiled
by :func:`compiled`, so both take the same observations and choose the same primitives, bit
for bit (docs/design.md section 24, docs/design/adaptation.md).

State of one controller:

- ``ints`` (int64, :data:`N_INTS`): the newest pose's stamp (ns) and whether there is one,
  the primitive running (-1: none) and the choices of it in a row, the pose at the last
  choice (stamp, whether there is one), whether the last cycle's motion is known, the
  settled motion's duration (ns) and cycles summed.
- ``floats`` (float64, :data:`N_FLOATS`): the newest pose ``(x m, y m, yaw rad)`` in the
  odometry's fixed frame, the pose at the last choice, the last cycle's motion over ``T``
  ``(dx m, dy m, dheading rad)`` and the settled motion summed so far in its first pose's
  frame.
- ``conf`` (float64 ``(4,)``): position tolerance (m over ``T``), heading tolerance (rad
  over ``T``), ``T`` (s), the fewest settled cycles an observation sums (``min_cycles``);
  ``iconf`` (int64 ``(4,)``): ``settle_cycles``, ``window``, matching
  (:data:`MATCH_OUTCOME` or :data:`MATCH_POINT`), which cycles are settled
  (:data:`STEADY_AGREE` or :data:`STEADY_HELD`).
- the model's arrays (:meth:`~evorbc_ros.adaptation.model.OutcomeModel.arrays`) and its
  noise, and ``weight`` ``(3,)`` (1 / each outcome dimension's extent).
"""

from __future__ import annotations

import math

import numpy as np

from evorbc_ros.adaptation import gp, motion
from evorbc_ros.adaptation.gp import USED, nearest, nearest_outcome, observe
from evorbc_ros.adaptation.motion import compose, extend_arc, relative_motion

# Rows of ``ints``.
POSE_STAMP, HAS_POSE, RUNNING, HELD, ANCHOR_STAMP, HAS_ANCHOR, HAS_LAST, SUM_NS, SUM_CYCLES = range(
    9
)
N_INTS = 9
# Rows of ``floats``: 3 each.
POSE, ANCHOR, LAST, SUM = 0, 3, 6, 9
N_FLOATS = 12
# Rows of ``conf`` and ``iconf``.
POS_TOL, HEAD_TOL, HORIZON, MIN_CYCLES = 0, 1, 2, 3
SETTLE, WINDOW, MATCH, STEADY = 0, 1, 2, 3
#: ``iconf[MATCH]``: the settings' ``match``.
MATCH_OUTCOME, MATCH_POINT = 0, 1
#: ``iconf[STEADY]``: the settings' ``steady``. ``agree``: a cycle is settled when its
#: motion agrees with the cycle before's (a wheeled robot holding its command); ``held``:
#: every cycle after ``settle_cycles`` is, and ``min_cycles`` of them are summed, so that a
#: gait's oscillation within its period averages out (docs/design/adaptation.md).
STEADY_AGREE, STEADY_HELD = 0, 1


def new_state() -> tuple[np.ndarray, np.ndarray]:
    """``(ints, floats)`` of a controller that has seen nothing (as after :func:`reset_run`)."""
    ints = np.zeros(N_INTS, dtype=np.int64)
    floats = np.zeros(N_FLOATS)
    ints[RUNNING] = -1
    return ints, floats


def clear_sum(ints, floats):
    """Forget the settled motion summed so far."""
    for k in range(3):
        floats[SUM + k] = 0.0
    ints[SUM_NS] = 0
    ints[SUM_CYCLES] = 0


def clear_run(ints, floats):
    """Forget the current execution (the pose stays)."""
    ints[RUNNING] = -1
    ints[HELD] = 0
    ints[HAS_ANCHOR] = 0
    ints[HAS_LAST] = 0
    clear_sum(ints, floats)


def put_pose(ints, floats, stamp_ns, x, y, yaw):
    """The newest odometry pose (m, m, rad in its fixed frame) at ``stamp_ns``.

    A pose that is not finite is ignored.
    """
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(yaw)):
        return
    ints[POSE_STAMP] = stamp_ns
    ints[HAS_POSE] = 1
    floats[POSE] = x
    floats[POSE + 1] = y
    floats[POSE + 2] = yaw


def flush(ints, floats, conf, features, recorded, expected, kzx, slots, residual, inverse,
          alpha, correction, corrected, counts, noise):  # fmt: skip
    """Give the summed settled motion, if any, to the model (:func:`gp.observe`).

    A sum of fewer than ``min_cycles`` cycles is dropped.
    """
    if ints[SUM_CYCLES] >= conf[MIN_CYCLES] and ints[SUM_CYCLES] > 0 and ints[RUNNING] >= 0:
        o0, o1, o2 = extend_arc(
            floats[SUM], floats[SUM + 1], floats[SUM + 2], ints[SUM_NS] * 1e-9, conf[HORIZON]
        )
        observe(features, recorded, expected, kzx, slots, residual, inverse, alpha,
                correction, corrected, counts, noise, ints[RUNNING], o0, o1, o2)  # fmt: skip
    clear_sum(ints, floats)


def before_choice(ints, floats, conf, iconf, features, recorded, expected, kzx, slots,
                  residual, inverse, alpha, correction, corrected, counts, noise):  # fmt: skip
    """Attribute the motion since the last choice to the primitive chosen then.

    A cycle is observed once its primitive ran more than ``settle_cycles`` choices, and
    (``steady`` ``agree``) its motion over ``T`` translated more than the position tolerance
    and agrees with the cycle before's within the tolerances; up to ``window`` such cycles
    are summed into one observation, given to the model if it sums at least
    ``min_cycles`` (docs/design/adaptation.md).
    """
    p, a = POSE, ANCHOR
    if ints[HAS_ANCHOR] == 0 or ints[HAS_POSE] == 0 or ints[POSE_STAMP] <= ints[ANCHOR_STAMP]:
        # No odometry, or none newer: the cycle cannot be measured; start again.
        flush(ints, floats, conf, features, recorded, expected, kzx, slots, residual,
              inverse, alpha, correction, corrected, counts, noise)  # fmt: skip
        clear_run(ints, floats)
        return
    sx, sy, sh = relative_motion(
        floats[a], floats[a + 1], floats[a + 2], floats[p], floats[p + 1], floats[p + 2]
    )
    dt_ns = ints[POSE_STAMP] - ints[ANCHOR_STAMP]
    bx, by, bh = extend_arc(sx, sy, sh, dt_ns * 1e-9, conf[HORIZON])
    had_last = ints[HAS_LAST] != 0
    lx, ly, lh = floats[LAST], floats[LAST + 1], floats[LAST + 2]
    floats[LAST] = bx
    floats[LAST + 1] = by
    floats[LAST + 2] = bh
    ints[HAS_LAST] = 1
    pos = conf[POS_TOL]
    steady = iconf[STEADY] == STEADY_HELD or (
        had_last
        and math.hypot(bx, by) > pos
        and math.hypot(lx - bx, ly - by) <= pos
        and abs(lh - bh) <= conf[HEAD_TOL]
    )
    if ints[HELD] > iconf[SETTLE] and steady:
        cx, cy, ch = compose(floats[SUM], floats[SUM + 1], floats[SUM + 2], sx, sy, sh)
        floats[SUM] = cx
        floats[SUM + 1] = cy
        floats[SUM + 2] = ch
        ints[SUM_NS] += dt_ns
        ints[SUM_CYCLES] += 1
        if ints[SUM_CYCLES] >= iconf[WINDOW]:
            flush(ints, floats, conf, features, recorded, expected, kzx, slots, residual,
                  inverse, alpha, correction, corrected, counts, noise)  # fmt: skip
    else:
        # What was summed is settled; this cycle is not.
        flush(ints, floats, conf, features, recorded, expected, kzx, slots, residual,
              inverse, alpha, correction, corrected, counts, noise)  # fmt: skip


def after_choice(ints, floats, conf, index, features, recorded, expected, kzx, slots,
                 residual, inverse, alpha, correction, corrected, counts, noise):  # fmt: skip
    """The primitive chosen now (``-1``: none, the robot stops)."""
    if index != ints[RUNNING]:
        flush(ints, floats, conf, features, recorded, expected, kzx, slots, residual,
              inverse, alpha, correction, corrected, counts, noise)  # fmt: skip
        ints[RUNNING] = index
        ints[HELD] = 0
        ints[HAS_LAST] = 0
    ints[HELD] = ints[HELD] + 1 if index >= 0 else 0
    ints[HAS_ANCHOR] = ints[HAS_POSE]
    ints[ANCHOR_STAMP] = ints[POSE_STAMP]
    for k in range(3):
        floats[ANCHOR + k] = floats[POSE + k]


def choose(iconf, x, y, looked_up, recorded, corrected, counts, weight):
    """The primitive to run given the grid's ``looked_up`` (``< 0``: none) and its cell centre.

    While nothing is observed the grid's choice stands, so an adapting controller starts
    exactly as the evolved one. ``outcome`` matching: the primitive whose corrected outcome
    is nearest ``looked_up``'s recorded one; ``point``: the one whose corrected ``(dx, dy)``
    is nearest ``(x, y)`` (m, the centre of the grid cell of the mapping's point).
    """
    if counts[USED] == 0 or looked_up < 0:
        return looked_up
    if iconf[MATCH] == MATCH_OUTCOME:
        return nearest_outcome(corrected, recorded[looked_up], weight)
    return nearest(corrected, x, y)


#: The functions above, callees first.
FUNCTIONS = ("clear_sum", "clear_run", "put_pose", "flush", "before_choice", "after_choice",
             "choose")  # fmt: skip

_MOTION = ("remainder", "_sinc", "relative_motion", "compose", "extend_arc")


def compiled(jit) -> dict:
    """The functions of this module, :mod:`gp`'s and :mod:`motion`'s, compiled by ``jit`` together.

    Returns:
        name -> compiled function (each calls the others' compiled forms).
    """
    out = gp.compiled(jit)
    out.update(gp.compile_together(jit, vars(motion), _MOTION))
    space = dict(globals())
    space.update(out)
    out.update(gp.compile_together(jit, space, FUNCTIONS, plain=globals()))
    return out


def plain() -> dict:
    """Name -> the plain function, for every name :func:`compiled` returns."""
    out = {name: getattr(gp, name) for name in gp.FUNCTIONS}
    out.update({name: getattr(motion, name) for name in _MOTION})
    out.update({name: globals()[name] for name in FUNCTIONS})
    return out
