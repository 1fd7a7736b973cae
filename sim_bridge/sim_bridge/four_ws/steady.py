"""What a 4WS primitive does once its actuators hold its command (docs/design.md section 24).

A repertoire records each primitive's outcome from rest over ``T`` (its speed and wheel
angles ramp up first, at 0.4 m/s^2 and 90 deg/s). An onboard observation is taken only
once a primitive has run long enough to settle, so the outcome it should be compared with
is the settled one: the motion of one settled control step, extended to ``T`` as the arc
it is. :func:`settled_outcomes` computes it with the motion model itself.
"""

from __future__ import annotations

import math

import numpy as np

from evorbc_ros.adaptation.motion import extend_arc, relative_motion
from sim_bridge.four_ws.damaged import step_damaged
from sim_bridge.four_ws.motion import HEADING, STATE_SIZE, X, Y, step_robot

_NO_WALLS = np.zeros((0, 6))
_NO_CANDIDATES = np.zeros(0, dtype=np.int64)


def settle_steps(lim) -> int:
    """Control steps from rest to any command: top speed or the full steering angle."""
    return max(
        math.ceil(lim.max_speed / lim.max_speed_step - 1e-9),
        math.ceil(lim.max_angle / lim.max_angle_step - 1e-9),
    )


def settled_outcomes(
    commands: np.ndarray,
    lim,
    horizon: float,
    gain: float = 1.0,
    damage: np.ndarray | None = None,
    key: int = 0,
) -> np.ndarray:
    """``(n, 3)`` settled outcomes ``(dx m, dy m, dheading rad)`` over ``horizon`` s.

    Args:
        commands: ``(n, 5)`` wheel commands (speed m/s, fl, fr, rl, rr rad).
        lim: the robot's :class:`~sim_bridge.four_ws.motion.MotionLimits`.
        horizon: ``T`` (s), the repertoire's evaluation time.
        gain: the world's wheel speed gain (docs/design.md section 21): the speed the
            wheels turn at over the commanded one.
        damage: ``(3,)`` a damaged wheel (:meth:`sim_bridge.damage.DamageDraw.wheel_arrays`
            row), or None: the intact robot. What the damaged robot does once settled.
        key: the episode's noise key (a slipping wheel's traction in the measured step).
    """
    n = len(commands)
    state = np.zeros((n, STATE_SIZE))
    out = np.zeros((n, 3))
    steps = settle_steps(lim)
    for i in range(n):
        command = np.array(commands[i], dtype=np.float64)  # a copy: the gain scales it
        if gain != 1.0:
            command[0] *= gain
        for t in range(steps):
            _step(state, i, command, lim, damage, key, t)
        x0, y0, h0 = state[i, X], state[i, Y], state[i, HEADING]
        _step(state, i, command, lim, damage, key, steps)
        step = relative_motion(x0, y0, h0, state[i, X], state[i, Y], state[i, HEADING])
        out[i] = extend_arc(*step, lim.dt, horizon)
    return out


def _step(state, i, command, lim, damage, key, cycle) -> None:
    """One step of the intact model, or of the damaged one (no walls)."""
    if damage is None:
        step_robot(state, i, command, lim, _NO_WALLS, _NO_CANDIDATES)
    else:
        step_damaged(state, i, command, lim, _NO_WALLS, _NO_CANDIDATES, damage, key, cycle)
