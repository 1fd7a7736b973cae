"""The 4WS motion model (docs/design.md section 2), compiled with numba and batched.

This is the one motion model used everywhere: repertoire generation, the maze task and the
simulation bridge all call :func:`step_robot`. Everything here works on plain floats and
float64 arrays so that numba can inline it into the batched loops of the callers.

Robot state, one row per robot, world frame (REP 103):
``[x m, y m, heading rad, speed m/s, angle_fl, angle_fr, angle_rl, angle_rr (rad)]``.
The heading is not wrapped, so a primitive's net rotation stays readable.

A wheel command is ``(speed m/s, angle_fl, angle_fr, angle_rl, angle_rr rad)``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba as nb

from evorbc_ros.robots.four_ws import FourWSGeometry
from sim_bridge.geometry import clearance

STATE_SIZE = 8
X, Y, HEADING, SPEED, ANGLE_FL, ANGLE_FR, ANGLE_RL, ANGLE_RR = range(STATE_SIZE)

# Two axle lines whose directions differ by less than this (rad) are taken as parallel:
# their intersection would lie further than ~0.05 m / 1e-9 = 5e7 m away.
_PARALLEL_EPS = 1e-9


class MotionLimits(NamedTuple):
    """The geometry and limits that the compiled kernels need, as plain floats."""

    wheel_x: float
    wheel_y: float
    footprint_radius: float
    max_angle: float  # rad
    max_angle_step: float  # rad per control step
    max_speed: float  # m/s
    max_speed_step: float  # m/s per control step
    dt: float  # s
    tan_max_slip: float
    parallel_tolerance: float  # rad


def motion_limits(geometry: FourWSGeometry) -> MotionLimits:
    """Pack a :class:`FourWSGeometry` for the compiled kernels."""
    dt = geometry.control_period
    return MotionLimits(
        wheel_x=geometry.wheel_x,
        wheel_y=geometry.wheel_y,
        footprint_radius=geometry.footprint_radius,
        max_angle=geometry.max_wheel_angle,
        max_angle_step=geometry.max_wheel_rate * dt,
        max_speed=geometry.max_speed,
        max_speed_step=geometry.max_acceleration * dt,
        dt=dt,
        tan_max_slip=math.tan(geometry.max_slip),
        parallel_tolerance=geometry.parallel_tolerance,
    )


@nb.njit(cache=True)
def speed_through_wheels(speed, wheel_radius):
    """The speed (m/s) as the bridge gets it back from wheel velocities: (speed / r) x r.

    Onboard the executor sends speed / r (rad/s) and the bridge multiplies by r, which can
    move the speed by one ulp; maze episodes apply the same round trip so that a lockstep
    graph reproduces them bit for bit (docs/design.md section 2).
    """
    return (speed / wheel_radius) * wheel_radius


@nb.njit(cache=True, inline="always")
def _approach(value, target, max_step):
    """Move ``value`` towards ``target`` by at most ``max_step``."""
    delta = target - value
    if delta > max_step:
        delta = max_step
    elif delta < -max_step:
        delta = -max_step
    return value + delta


@nb.njit(cache=True, inline="always")
def _clip(value, bound):
    return min(max(value, -bound), bound)


@nb.njit(cache=True)
def axle_intersection(px1, py1, s1, c1, px2, py2, s2, c2):
    """Intersection of the axle lines of two wheels (body frame).

    A wheel at ``p`` steered by ``a`` rolls along ``(cos a, sin a)``; its axle line is
    ``p + t (-sin a, cos a)``. The angles come as their sines ``s`` and cosines ``c``,
    computed once per step by the caller.

    Returns:
        ``(exists, x, y)``; ``exists`` is False for parallel axles.

    """
    den = s2 * c1 - c2 * s1  # sin(a2 - a1): cross product of the unit axle directions
    if abs(den) < _PARALLEL_EPS:
        return False, 0.0, 0.0
    t = ((px2 - px1) * c2 + (py2 - py1) * s2) / den
    return True, px1 - t * s1, py1 + t * c1


@nb.njit(cache=True)
def _slips(icr_x, icr_y, px, py, s, c, tan_max_slip):
    """True if the wheel at ``(px, py)`` slips more than allowed.

    The wheel's steering angle ``a`` comes as ``s = sin a`` and ``c = cos a``. The slip is
    the angle between the wheel's axle line ``(-s, c)`` and the line from the wheel to the
    ICR; comparing tangents avoids an atan2 in the hot loop.
    """
    wx = icr_x - px
    wy = icr_y - py
    cross = abs(-s * wy - c * wx)
    dot = abs(-s * wx + c * wy)
    return cross > tan_max_slip * dot


@nb.njit(cache=True)
def body_motion(a_fl, a_fr, a_rl, a_rr, distance, lim):
    """Displacement of the body over one step, in the body frame at the start of the step.

    Args:
        a_fl, a_fr, a_rl, a_rr: wheel angles (rad) after rate limiting.
        distance: signed distance the wheels roll this step (speed * dt, m).
        lim: :class:`MotionLimits`.

    Returns:
        ``(moved, dx, dy, dheading)``. ``moved`` is False when the wheels fight each other
        (slip above the limit, or the ICR inside the wheel rectangle).

    """
    hx = lim.wheel_x
    hy = lim.wheel_y
    a_max = max(max(a_fl, a_fr), max(a_rl, a_rr))
    a_min = min(min(a_fl, a_fr), min(a_rl, a_rr))
    a_mean = 0.25 * (a_fl + a_fr + a_rl + a_rr)
    if a_max - a_min <= lim.parallel_tolerance:
        # Crab motion: translate along the common wheel direction, heading unchanged.
        return True, distance * math.cos(a_mean), distance * math.sin(a_mean), 0.0

    s_fl, c_fl = math.sin(a_fl), math.cos(a_fl)
    s_fr, c_fr = math.sin(a_fr), math.cos(a_fr)
    s_rl, c_rl = math.sin(a_rl), math.cos(a_rl)
    s_rr, c_rr = math.sin(a_rr), math.cos(a_rr)
    ok_l, lx, ly = axle_intersection(hx, hy, s_fl, c_fl, -hx, hy, s_rl, c_rl)
    ok_r, rx, ry = axle_intersection(hx, -hy, s_fr, c_fr, -hx, -hy, s_rr, c_rr)
    if ok_l and ok_r:
        icr_x = 0.5 * (lx + rx)
        icr_y = 0.5 * (ly + ry)
    elif ok_l:
        icr_x, icr_y = lx, ly
    elif ok_r:
        icr_x, icr_y = rx, ry
    else:
        # Each side's wheels are parallel but the sides differ: the ICR is at infinity, so
        # the body would translate along the mean direction; each wheel slips by its
        # deviation from that direction.
        tan_dev = max(
            max(abs(math.tan(a_fl - a_mean)), abs(math.tan(a_fr - a_mean))),
            max(abs(math.tan(a_rl - a_mean)), abs(math.tan(a_rr - a_mean))),
        )
        if tan_dev > lim.tan_max_slip:
            return False, 0.0, 0.0, 0.0
        return True, distance * math.cos(a_mean), distance * math.sin(a_mean), 0.0

    # One shared wheel speed cannot spin the body about a point inside the wheel rectangle.
    if abs(icr_x) <= hx and abs(icr_y) <= hy:
        return False, 0.0, 0.0, 0.0
    t = lim.tan_max_slip
    if (
        _slips(icr_x, icr_y, hx, hy, s_fl, c_fl, t)
        or _slips(icr_x, icr_y, hx, -hy, s_fr, c_fr, t)
        or _slips(icr_x, icr_y, -hx, hy, s_rl, c_rl, t)
        or _slips(icr_x, icr_y, -hx, -hy, s_rr, c_rr, t)
    ):
        return False, 0.0, 0.0, 0.0

    # Sense of rotation: rolling forward, each wheel moves along (cos a, sin a); a rotation
    # omega about the ICR moves a wheel at p with omega * z x (p - icr). Summing the
    # projections over the wheels decides the sign robustly.
    sense = (
        c_fl * (icr_y - hy)
        - s_fl * (icr_x - hx)
        + c_fr * (icr_y + hy)
        - s_fr * (icr_x - hx)
        + c_rl * (icr_y - hy)
        - s_rl * (icr_x + hx)
        + c_rr * (icr_y + hy)
        - s_rr * (icr_x + hx)
    )
    radius = math.hypot(icr_x, icr_y)
    dheading = distance / radius
    if sense < 0.0:
        dheading = -dheading
    # The centre rotates about the ICR by dheading: new centre = (I - Rot) icr. Using
    # 1 - cos = 2 sin^2(./2) keeps this exact for far-away ICRs (nearly straight arcs).
    s = math.sin(dheading)
    h = math.sin(0.5 * dheading)
    c = 2.0 * h * h
    dx = c * icr_x + s * icr_y
    dy = -s * icr_x + c * icr_y
    return True, dx, dy, dheading


@nb.njit(cache=True)
def apply_rate_limits(state, i, command, lim):
    """Move robot ``i``'s speed and wheel angles towards ``command`` for one step.

    Commands beyond the actuator ranges are clipped first.
    """
    state[i, SPEED] = _approach(
        state[i, SPEED], _clip(command[0], lim.max_speed), lim.max_speed_step
    )
    for w in range(4):
        state[i, ANGLE_FL + w] = _approach(
            state[i, ANGLE_FL + w], _clip(command[1 + w], lim.max_angle), lim.max_angle_step
        )


@nb.njit(cache=True)
def step_robot(state, i, command, lim, boxes, candidates):
    """Advance robot ``i`` by one control step of ``lim.dt`` seconds.

    Rate limits apply first; the body then moves with the limited speed and wheel angles.
    If the footprint would overlap a wall after the step, the position stays where it was
    and the heading change is kept (docs/design.md section 2).

    Args:
        state: ``(n, STATE_SIZE)`` robot states, updated in place.
        i: row of the robot to step.
        command: ``(5,)`` wheel command.
        lim: :class:`MotionLimits`.
        boxes: ``(m, 6)`` wall boxes (see :mod:`sim_bridge.geometry`), may be empty.
        candidates: rows of ``boxes`` to test; they must include every wall within
            ``footprint_radius`` plus one step (0.02 m) of the robot.

    Returns:
        Distance the body centre travelled this step (m, >= 0).
    """
    apply_rate_limits(state, i, command, lim)
    distance = state[i, SPEED] * lim.dt
    moved, dx, dy, dheading = body_motion(
        state[i, ANGLE_FL],
        state[i, ANGLE_FR],
        state[i, ANGLE_RL],
        state[i, ANGLE_RR],
        distance,
        lim,
    )
    if not moved or not move_body(state, i, dx, dy, dheading, lim, boxes, candidates):
        return 0.0
    return abs(distance)


@nb.njit(cache=True, inline="always")
def move_body(state, i, dx, dy, dheading, lim, boxes, candidates):
    """Move robot ``i`` by ``(dx, dy)`` (m, body frame at the step's start) and ``dheading``.

    The heading change is always kept; the position only if the footprint stays clear of
    the walls (docs/design.md section 2). Returns whether the position moved.
    """
    heading = state[i, HEADING]
    c = math.cos(heading)
    s = math.sin(heading)
    nx = state[i, X] + c * dx - s * dy
    ny = state[i, Y] + s * dx + c * dy
    state[i, HEADING] = heading + dheading
    if candidates.shape[0] > 0 and clearance(nx, ny, boxes, candidates) < lim.footprint_radius:
        return False
    state[i, X] = nx
    state[i, Y] = ny
    return True
