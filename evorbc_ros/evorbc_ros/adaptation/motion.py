"""What an executed primitive did, from two odometry poses (pure code, numba-compilable).

Poses are ``(x m, y m, yaw rad)`` in the odometry's fixed frame; the motion between two is
``(dx m, dy m, dheading rad)`` in the first pose's frame (x forward, y left; REP 103). An
observation over ``tau`` seconds is compared with outcomes over the repertoire's
evaluation time ``T`` by extending it as a constant body twist (an exact arc), which is
how the 4WS robot moves while its actuators hold a command (docs/design.md section 24).
"""

from __future__ import annotations

import math


def remainder(x, y):
    """IEEE 754 ``remainder(x, y)`` for finite ``x`` and ``y > 0``: ``math.remainder``'s bits.

    numba has no ``math.remainder`` (nor ``fmod``). ``%`` of positive numbers is ``fmod``,
    exact, and each subtraction below is of two numbers within a factor of two of each
    other (Sterbenz), so exact too; reducing modulo ``2 y`` first keeps the quotient's
    parity, which decides a tie (to even).
    """
    r = abs(x) % (2.0 * y)  # in [0, 2y): fmod of positive numbers, exact
    half = 0.5 * y
    if r > half:
        r = r - y  # in (-y/2, y)
        if r >= half:  # at y/2 exactly the quotient 2 (even) wins over 1
            r = r - y
    return math.copysign(r, x) if r == 0.0 else (r if x >= 0.0 else -r)


def relative_motion(x0, y0, h0, x1, y1, h1):
    """The motion from pose 0 to pose 1 in pose 0's frame: ``(dx m, dy m, dheading rad)``.

    The heading change is wrapped to ``(-pi, pi]``: odometry yaw wraps, and one control
    cycle turns far less than half a turn.
    """
    c = math.cos(h0)
    s = math.sin(h0)
    ex = x1 - x0
    ey = y1 - y0
    dh = remainder(h1 - h0, 2.0 * math.pi)
    return c * ex + s * ey, -s * ex + c * ey, dh


def compose(ax, ay, ah, bx, by, bh):
    """Motion ``a`` then motion ``b`` (``b`` in the frame where ``a`` ends), in ``a``'s frame."""
    c = math.cos(ah)
    s = math.sin(ah)
    return ax + c * bx - s * by, ay + s * bx + c * by, ah + bh


def _sinc(x):
    """``sin(x) / x``, 1 at 0."""
    return 1.0 if x == 0.0 else math.sin(x) / x


def extend_arc(dx, dy, dh, tau, horizon):
    """The motion over ``horizon`` s of the constant twist that moves ``(dx, dy, dh)`` in ``tau`` s.

    Along an arc of turn rate ``w`` the displacement after ``t`` is the complex number
    ``v (exp(i w t) - 1) / (i w)``, so the one after ``horizon`` is the one after ``tau``
    times ``(exp(i w horizon) - 1) / (exp(i w tau) - 1)
    = sin(w horizon / 2) / sin(w tau / 2) * exp(i w (horizon - tau) / 2)``,
    written with ``sinc`` so that a straight line (``w = 0``) is exact.
    """
    w = dh / tau
    gain = (horizon / tau) * _sinc(0.5 * w * horizon) / _sinc(0.5 * w * tau)
    turn = 0.5 * w * (horizon - tau)
    c = math.cos(turn)
    s = math.sin(turn)
    return gain * (c * dx - s * dy), gain * (s * dx + c * dy), w * horizon
