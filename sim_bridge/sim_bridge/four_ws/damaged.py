"""A 4WS robot with one damaged wheel (docs/perturbations.md, "The 4WS body motion").

The intact model (:mod:`sim_bridge.four_ws.motion`) moves the body about the ICR the four
steering angles agree on. A damaged wheel no longer does what the others expect, so the
body motion is derived from the wheels:

1. The intact step (:func:`~sim_bridge.four_ws.motion.body_motion`) gives the motion the
   command asks for, a rigid displacement ``(dx, dy, dtheta)`` over the step; as a
   constant twist over the step its per-step twist is ``(ux, uy, dtheta)`` (m, m, rad;
   body frame at the step's start), the inverse of the exact arc.
2. Each wheel ``i`` at ``p_i`` (body frame, m) would move its contact point by
   ``V_i = (ux - dtheta p_iy, uy + dtheta p_ix)``; it rolls by ``r_i = V_i . d_i`` along its
   direction ``d_i = (cos a_i, sin a_i)``
   and ``s_i = V_i . n_i`` across it (``n_i = (-sin a_i, cos a_i)``: the sideways slip the
   intact model tolerates, up to 10 deg).
3. The damaged wheel ``w`` moves its contact point by ``T_w = f r_w d'_w + s_w n'_w``
   instead: ``stuck_steering`` moves the same along and across its stuck angle
   (``d'_w``, ``n'_w``), ``slow_wheel`` turns at the factor ``f`` of its speed,
   ``slipping_wheel`` loses a share ``slip x u`` of its traction each cycle
   (``f = 1 - slip x u``, ``u`` uniform in [0, 1) from the episode's key and the cycle,
   :func:`~sim_bridge.hashing.hash_uniform`). An undamaged wheel (``f = 1``, its own
   angle) gives ``T_w = V_w``.
4. The body's twist is the least-squares rigid-body fit of the four contact-point
   motions, rolling and sideways slip weighted alike: minimise
   ``sum_i |(ux' - dtheta' p_iy, uy' + dtheta' p_ix) - T_i|^2`` with ``T_i = V_i`` for the
   intact wheels. The wheels sit at ``(+-wheel_x, +-wheel_y)``, so the normal equations
   decouple: ``ux' = ux + e_x / 4``, ``uy' = uy + e_y / 4``,
   ``dtheta' = dtheta + (p_wx e_y - p_wy e_x) / (4 (wheel_x^2 + wheel_y^2))`` with
   ``e = T_w - V_w`` (the intact wheels fit the asked twist exactly).
5. The body moves along the exact arc of that twist, and walls stop it as in the intact
   model.

A command the intact model refuses (wheels fighting) moves the damaged robot no more. The
intact robot never runs this code: the kernel and the bridge call it only for damage.
"""

from __future__ import annotations

import math

import numba as nb

from sim_bridge.four_ws.motion import (
    ANGLE_FL,
    ANGLE_RR,
    SPEED,
    apply_rate_limits,
    body_motion,
    move_body,
    step_robot,
)
from sim_bridge.hashing import hash_uniform

#: Kinds of damage (sim_bridge.damage.FOUR_WS_CODES).
INTACT, STUCK_STEERING, SLOW_WHEEL, SLIPPING_WHEEL = 0, 1, 2, 3
#: The slip's draw in :func:`hash_uniform`: reading index 0 with salt 3, which the
#: rangefinder noise (salts 0-2) never uses.
_SLIP_INDEX, _SLIP_SALT = 0, 3
# Below this |dtheta| (rad per step) the arc is taken as straight: its chord and arc agree
# to far below a float's precision at the robot's step lengths (< 0.05 m).
_STRAIGHT = 1e-12


@nb.njit(cache=True, inline="always")
def _arc_terms(dtheta):
    """``(sin dtheta, 1 - cos dtheta)``; the second as ``2 sin^2(dtheta / 2)``, exact near 0."""
    h = math.sin(0.5 * dtheta)
    return math.sin(dtheta), 2.0 * h * h


@nb.njit(cache=True, inline="always")
def _arc_to_twist(dx, dy, dtheta):
    """Per-step twist ``(ux, uy)`` (m) whose exact arc over the step moves by ``(dx, dy)``."""
    if abs(dtheta) < _STRAIGHT:
        return dx, dy
    s, c = _arc_terms(dtheta)
    k = dtheta / (s * s + c * c)
    return k * (s * dx + c * dy), k * (-c * dx + s * dy)


@nb.njit(cache=True, inline="always")
def _twist_to_arc(ux, uy, dtheta):
    """Displacement ``(dx, dy)`` (m) of the exact arc of the per-step twist."""
    if abs(dtheta) < _STRAIGHT:
        return ux, uy
    s, c = _arc_terms(dtheta)
    return (ux * s - uy * c) / dtheta, (ux * c + uy * s) / dtheta


@nb.njit(cache=True)
def damaged_body_motion(angles, distance, lim, kind, wheel, level, traction):
    """Displacement over one step with wheel ``wheel`` damaged (module docstring).

    Args:
        angles: ``(4,)`` wheel angles (rad, fl, fr, rl, rr) after rate limiting.
        distance: the step's commanded distance (speed x dt, m).
        lim: :class:`~sim_bridge.four_ws.motion.MotionLimits`.
        kind: :data:`STUCK_STEERING`, :data:`SLOW_WHEEL` or :data:`SLIPPING_WHEEL`.
        wheel: the damaged wheel, 0-3 (fl, fr, rl, rr).
        level: the stuck angle (rad), the speed factor, or the largest traction loss.
        traction: this cycle's ``u`` in [0, 1) for a slipping wheel.

    Returns:
        ``(moved, dx m, dy m, dheading rad)`` in the body frame at the step's start.
    """
    moved, dx, dy, dtheta = body_motion(angles[0], angles[1], angles[2], angles[3], distance, lim)
    if not moved:
        return False, 0.0, 0.0, 0.0
    ux, uy = _arc_to_twist(dx, dy, dtheta)
    px = lim.wheel_x if wheel < 2 else -lim.wheel_x  # front wheels at +x
    py = lim.wheel_y if wheel % 2 == 0 else -lim.wheel_y  # left wheels at +y
    vx = ux - dtheta * py
    vy = uy + dtheta * px
    a = angles[wheel]
    # Its motion along its direction (rolling, m) and across it (the intact model's
    # tolerated slip, m), in the wheel's frame.
    roll = vx * math.cos(a) + vy * math.sin(a)
    across = -vx * math.sin(a) + vy * math.cos(a)
    if kind == STUCK_STEERING:
        a = level
    elif kind == SLOW_WHEEL:
        roll *= level
    elif kind == SLIPPING_WHEEL:
        roll *= 1.0 - level * traction
    ex = roll * math.cos(a) - across * math.sin(a) - vx
    ey = roll * math.sin(a) + across * math.cos(a) - vy
    ux += 0.25 * ex
    uy += 0.25 * ey
    dtheta += (px * ey - py * ex) / (4.0 * (px * px + py * py))
    dx, dy = _twist_to_arc(ux, uy, dtheta)
    return True, dx, dy, dtheta


@nb.njit(cache=True)
def step_damaged(state, i, command, lim, boxes, candidates, damage, key, cycle):
    """:func:`~sim_bridge.four_ws.motion.step_robot` with one damaged wheel.

    Args:
        damage: ``(3,)`` kind, wheel, level (:meth:`sim_bridge.damage.DamageDraw.wheel_arrays`);
            kind 0 runs the intact step.
        key, cycle: the episode's noise key and the cycle (a slipping wheel's traction).

    Returns:
        Distance the wheels were asked to roll this step (m, >= 0) if the body moved.
    """
    kind = int(damage[0])
    if kind == INTACT:
        return step_robot(state, i, command, lim, boxes, candidates)
    apply_rate_limits(state, i, command, lim)
    distance = state[i, SPEED] * lim.dt
    traction = 0.0
    if kind == SLIPPING_WHEEL:
        traction = hash_uniform(key, cycle, _SLIP_INDEX, _SLIP_SALT)
    moved, dx, dy, dheading = damaged_body_motion(
        state[i, ANGLE_FL : ANGLE_RR + 1], distance, lim, kind, int(damage[1]), damage[2], traction
    )
    if not moved or not move_body(state, i, dx, dy, dheading, lim, boxes, candidates):
        return 0.0
    return abs(distance)
