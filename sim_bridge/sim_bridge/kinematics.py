"""One compiled step for every kinematic robot, chosen by the type of its limits.

The episode kernel (:mod:`offline_evolution.maze_task.kernel`) runs whichever kinematic
robot its task has: :func:`step_model` and :func:`halt` resolve at compile time, from the
limits' NamedTuple type, to the 4WS model (:class:`~sim_bridge.four_ws.motion.MotionLimits`)
or the differential-drive one (:class:`~sim_bridge.diff_drive.motion.DiffLimits`). numba
compiles one kernel per model, so neither pays for the other: no branch runs per step
(docs/design.md section 19).
"""

from __future__ import annotations

import numba as nb
import numpy as np
from numba import types
from numba.extending import overload

from sim_bridge.diff_drive.motion import DiffLimits, step_diff
from sim_bridge.four_ws.damaged import step_damaged
from sim_bridge.four_ws.motion import HEADING, STATE_SIZE, MotionLimits, X, Y, step_robot


def step_model(state, i, command, lim, boxes, candidates):
    """Advance robot ``i`` one control step in the motion model of ``lim`` (compiled only)."""
    raise NotImplementedError("step_model runs inside compiled code only")


def step_model_damaged(state, i, command, lim, boxes, candidates, damage, key, cycle):
    """:func:`step_model` with a damaged wheel (compiled only; 4WS, docs/perturbations.md).

    ``damage``: ``(3,)`` kind, wheel, level; ``key``, ``cycle``: a slipping wheel's draw. A
    differential drive takes no wheel damage (its task refuses it) and steps intact.
    """
    raise NotImplementedError("step_model_damaged runs inside compiled code only")


def halt(command, lim):
    """Make ``command`` a stop in the model of ``lim`` (compiled only)."""
    raise NotImplementedError("halt runs inside compiled code only")


def _model(lim) -> type | None:
    """The limits class a numba type stands for."""
    if isinstance(lim, (types.NamedTuple, types.NamedUniTuple)):
        return lim.instance_class
    return None


@overload(step_model, inline="always")
def _step_model(state, i, command, lim, boxes, candidates):
    if _model(lim) is MotionLimits:

        def four_ws(state, i, command, lim, boxes, candidates):
            return step_robot(state, i, command, lim, boxes, candidates)

        return four_ws
    if _model(lim) is DiffLimits:

        def diff_drive(state, i, command, lim, boxes, candidates):
            return step_diff(state, i, command, lim, boxes, candidates)

        return diff_drive
    return None


@overload(step_model_damaged, inline="always")
def _step_model_damaged(state, i, command, lim, boxes, candidates, damage, key, cycle):
    if _model(lim) is MotionLimits:

        def four_ws(state, i, command, lim, boxes, candidates, damage, key, cycle):
            return step_damaged(state, i, command, lim, boxes, candidates, damage, key, cycle)

        return four_ws
    if _model(lim) is DiffLimits:

        def diff_drive(state, i, command, lim, boxes, candidates, damage, key, cycle):
            return step_diff(state, i, command, lim, boxes, candidates)

        return diff_drive
    return None


@overload(halt, inline="always")
def _halt(command, lim):
    if _model(lim) is MotionLimits:

        def four_ws(command, lim):
            command[0] = 0.0  # zero wheel speed, steering held

        return four_ws
    if _model(lim) is DiffLimits:

        def diff_drive(command, lim):
            command[0] = 0.0  # a zero twist
            command[1] = 0.0

        return diff_drive
    return None


@nb.njit(cache=True, parallel=True)
def run_model_primitives(commands, n_steps, lim):
    """Execute primitives from rest at the origin facing +x, in free space.

    Each row of ``commands`` is held constant for ``n_steps`` control steps in the motion
    model of ``lim``; rate limits apply throughout (docs/design.md section 2). Robots are
    independent, so the result does not depend on the number of threads.

    Args:
        commands: ``(n, w)`` commands of the model (4WS: ``(n, 5)`` wheel commands;
            differential drive: ``(n, 2)`` body twists).
        n_steps: number of control steps (T / dt).
        lim: :class:`~sim_bridge.four_ws.motion.MotionLimits` or
            :class:`~sim_bridge.diff_drive.motion.DiffLimits`.

    Returns:
        ``(n, 4)`` rows ``(x m, y m, final heading rad (unwrapped), path length m)``.

    """
    n = commands.shape[0]
    out = np.empty((n, 4))
    # Wide enough for either model's state (x, y and heading first in both).
    state = np.zeros((n, STATE_SIZE))
    no_boxes = np.empty((0, 6))
    no_candidates = np.empty(0, dtype=np.int64)
    for i in nb.prange(n):
        path = 0.0
        for _ in range(n_steps):
            path += step_model(state, i, commands[i], lim, no_boxes, no_candidates)
        out[i, 0] = state[i, X]
        out[i, 1] = state[i, Y]
        out[i, 2] = state[i, HEADING]
        out[i, 3] = path
    return out
