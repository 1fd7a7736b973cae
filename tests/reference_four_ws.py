"""Plain-Python reference of the 4WS motion model (docs/design.md section 2).

Written from the specification alone, for clarity rather than speed, to cross-check the
compiled model in ``sim_bridge.four_ws.motion``. Body frame: x forward, y left, angles
counter-clockwise. All quantities in SI units (m, s, rad, m/s).

Besides the motion itself, each step records its *margins*: how far the inputs were from every
threshold the model compares against (parallel tolerance, slip limit, wheel rectangle, wall
clearance, equal front/rear angles). Tests use them to avoid inputs where rounding alone could
flip a decision. "Equal angles" (no axle intersection) is read literally: exact equality.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

DT = 0.1  # s, control and integration step
WHEEL_X = 0.025  # m
WHEEL_Y = 0.025  # m
FOOTPRINT_RADIUS = 0.05  # m
MAX_ANGLE = math.radians(45.0)  # rad
MAX_ANGLE_STEP = math.radians(90.0) * DT  # rad per step
MAX_SPEED = 0.20  # m/s
MAX_SPEED_STEP = 0.40 * DT  # m/s per step
MAX_SLIP = math.radians(10.0)  # rad
PARALLEL_TOL = math.radians(1.0)  # rad

#: Wheel contact points in the body frame, order fl, fr, rl, rr.
WHEELS = (
    (WHEEL_X, WHEEL_Y),
    (WHEEL_X, -WHEEL_Y),
    (-WHEEL_X, WHEEL_Y),
    (-WHEEL_X, -WHEEL_Y),
)


@dataclass(frozen=True)
class State:
    """Pose (world frame), wheel speed and the four wheel angles (fl, fr, rl, rr)."""

    x: float = 0.0
    y: float = 0.0
    heading: float = 0.0
    speed: float = 0.0
    fl: float = 0.0
    fr: float = 0.0
    rl: float = 0.0
    rr: float = 0.0

    @property
    def angles(self) -> tuple[float, float, float, float]:
        """The wheel angles in the order fl, fr, rl, rr."""
        return (self.fl, self.fr, self.rl, self.rr)


@dataclass
class Margins:
    """Smallest distance seen to each decision threshold (inf if never compared)."""

    parallel: float = math.inf  # rad, |spread - 1 deg|
    slip: float = math.inf  # rad, |max slip - 10 deg|
    rectangle: float = math.inf  # m, distance of the ICR to the wheel rectangle's boundary
    wall: float = math.inf  # m, |distance to a wall - clearance|
    axle: float = math.inf  # rad, smallest nonzero |a_front - a_rear| on one side

    def smallest(self) -> float:
        """The smallest of all margins (mixing rad and m, both small SI numbers)."""
        return min(self.parallel, self.slip, self.rectangle, self.wall, self.axle)


def _clip(value: float, low: float, high: float) -> float:
    return max(low, min(high, value))


def _towards(current: float, target: float, max_step: float) -> float:
    """Move ``current`` towards ``target`` by at most ``max_step`` (reaching it exactly)."""
    return _clip(target, current - max_step, current + max_step)


def _axle_intersection(i: int, a_i: float, j: int, a_j: float):
    """Intersection of the axle lines of wheels i and j (body frame), or None if parallel."""
    if a_i == a_j:
        return None
    (px, py), (qx, qy) = WHEELS[i], WHEELS[j]
    # Axle line k: wheel point + t * (-sin a_k, cos a_k). Solve p + t u = q + r v.
    ux, uy = -math.sin(a_i), math.cos(a_i)
    vx, vy = -math.sin(a_j), math.cos(a_j)
    denom = ux * vy - uy * vx  # cross(u, v) = sin(a_j - a_i)
    if denom == 0.0:
        return None
    # Walk along the axle line of the wheel with the smaller |sin a|, so that a wheel at
    # exactly 0 rad gives an intersection exactly on its axle line x = wheel x.
    if abs(ux) <= abs(vx):
        t = ((qx - px) * vy - (qy - py) * vx) / denom
        return (px + t * ux, py + t * uy)
    r = ((qx - px) * uy - (qy - py) * ux) / denom
    return (qx + r * vx, qy + r * vy)


def _line_angle_difference(a: float, b: float) -> float:
    """Angle between two lines with directions a and b (rad), in [0, pi/2]."""
    d = math.remainder(a - b, math.pi)  # in [-pi/2, pi/2]
    return abs(d)


def _wall_distance(px: float, py: float, wall) -> float:
    """Distance from a point to a wall: a box of the segment's length and the wall's
    thickness, centred on the segment (0 inside it)."""
    x1, y1, x2, y2, thickness = wall[:5]
    length = math.hypot(x2 - x1, y2 - y1)
    ux, uy = (x2 - x1) / length, (y2 - y1) / length
    mx, my = px - (x1 + x2) / 2.0, py - (y1 + y2) / 2.0
    along = abs(mx * ux + my * uy) - length / 2.0
    across = abs(-mx * uy + my * ux) - thickness / 2.0
    return math.hypot(max(along, 0.0), max(across, 0.0))


def body_motion(angles: Sequence[float], s: float, margins: Margins | None = None):
    """Body-frame motion of one step: ``(dx, dy, dtheta, moved)``.

    ``angles`` are the (already rate-limited) wheel angles fl, fr, rl, rr and ``s`` the signed
    distance rolled. ``(dx, dy)`` is the displacement of the body centre in the body frame at
    the start of the step and ``dtheta`` the heading change.
    """
    m = margins if margins is not None else Margins()
    fl, fr, rl, rr = angles
    spread = max(angles) - min(angles)
    m.parallel = min(m.parallel, abs(spread - PARALLEL_TOL))
    if spread <= PARALLEL_TOL:  # 1. crab motion along the mean wheel direction
        mean = sum(angles) / 4.0
        return s * math.cos(mean), s * math.sin(mean), 0.0, True

    for front, rear in ((fl, rl), (fr, rr)):
        if front != rear:
            m.axle = min(m.axle, abs(front - rear))
    left = _axle_intersection(0, fl, 2, rl)
    right = _axle_intersection(1, fr, 3, rr)
    if left is None and right is None:
        # Project convention: ICR at infinity, translate along the mean angle; slip of a
        # wheel is its angle's difference to that mean.
        mean = sum(angles) / 4.0
        slip = max(abs(a - mean) for a in angles)
        m.slip = min(m.slip, abs(slip - MAX_SLIP))
        if slip > MAX_SLIP:
            return 0.0, 0.0, 0.0, False
        return s * math.cos(mean), s * math.sin(mean), 0.0, True

    points = [p for p in (left, right) if p is not None]
    cx = sum(p[0] for p in points) / len(points)
    cy = sum(p[1] for p in points) / len(points)

    # Slip: angle between the axle line and the line from the wheel to the ICR.
    slip = 0.0
    for (wx, wy), a in zip(WHEELS, angles, strict=True):
        to_icr = math.atan2(cy - wy, cx - wx)
        slip = max(slip, _line_angle_difference(to_icr, a + math.pi / 2.0))
    m.slip = min(m.slip, abs(slip - MAX_SLIP))
    outside = max(abs(cx) - WHEEL_X, abs(cy) - WHEEL_Y)  # > 0 iff outside the rectangle
    if outside != 0.0:  # exactly 0 only when a wheel at exactly 0 rad puts the ICR on the
        m.rectangle = min(m.rectangle, abs(outside))  # boundary: an exact tie, not rounding
    if slip > MAX_SLIP or outside <= 0.0:
        return 0.0, 0.0, 0.0, False

    # Rotation sense: the one whose wheel velocities point along the wheels for s > 0.
    # Velocity of wheel w for a unit CCW rotation about c is (-(wy - cy), wx - cx).
    alignment = sum(
        math.cos(a) * (cy - wy) + math.sin(a) * (wx - cx)
        for (wx, wy), a in zip(WHEELS, angles, strict=True)
    )
    radius = math.hypot(cx, cy)
    dtheta = math.copysign(1.0, alignment) * s / radius
    # Rotate the centre (origin of the body frame) about c by dtheta: the displacement is
    # (I - R(dtheta)) c, with 1 - cos written as 2 sin^2(dtheta / 2) to stay accurate when the
    # ICR is far away and dtheta tiny.
    sin_t, versine = math.sin(dtheta), 2.0 * math.sin(dtheta / 2.0) ** 2
    dx = versine * cx + sin_t * cy
    dy = versine * cy - sin_t * cx
    return dx, dy, dtheta, True


def reference_step(state: State, command: Sequence[float], walls=(), margins=None):
    """Advance ``state`` by one 0.1 s step under ``command``.

    ``command`` is ``(speed, a_fl, a_fr, a_rl, a_rr)`` in m/s and rad; ``walls`` is a sequence
    of ``(x1, y1, x2, y2, thickness)`` (full thickness, m). Returns ``(new_state, distance)``
    where ``distance`` is how far the body centre travelled (``|s|`` if it moved, else 0).
    ``margins`` (a :class:`Margins`), if given, is updated with the distances to thresholds.
    """
    m = margins if margins is not None else Margins()
    speed_cmd = _clip(command[0], -MAX_SPEED, MAX_SPEED)
    speed = _towards(state.speed, speed_cmd, MAX_SPEED_STEP)
    angles = tuple(
        _towards(old, _clip(cmd, -MAX_ANGLE, MAX_ANGLE), MAX_ANGLE_STEP)
        for old, cmd in zip(state.angles, command[1:5], strict=True)
    )
    s = speed * DT
    dx, dy, dtheta, moved = body_motion(angles, s, m)

    c, sn = math.cos(state.heading), math.sin(state.heading)
    x = state.x + c * dx - sn * dy
    y = state.y + sn * dx + c * dy
    distance = abs(s) if moved else 0.0
    blocked = False
    for wall in walls:
        clearance = FOOTPRINT_RADIUS
        d = _wall_distance(x, y, wall)
        m.wall = min(m.wall, abs(d - clearance))
        blocked = blocked or d < clearance
    if blocked:  # the footprint would overlap a wall: old position, heading change kept
        x, y, distance = state.x, state.y, 0.0
    new = replace(state, x=x, y=y, heading=state.heading + dtheta, speed=speed)
    new = replace(new, fl=angles[0], fr=angles[1], rl=angles[2], rr=angles[3])
    return new, distance


def reference_primitive(command: Sequence[float], steps: int, margins=None):
    """Hold ``command`` for ``steps`` steps from rest at the origin facing +x.

    Returns ``(x, y, heading, path_length)``.
    """
    state, path = State(), 0.0
    for _ in range(steps):
        state, d = reference_step(state, command, (), margins)
        path += d
    return state.x, state.y, state.heading, path
