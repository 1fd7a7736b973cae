"""The differential-drive motion model, compiled with numba and batched.

The counterpart of :mod:`sim_bridge.four_ws.motion` for a differential-drive robot
(docs/design.md section 19): repertoire generation, the maze task's episode kernel and the
simulation bridge all step it with :func:`step_diff`.

Robot state, one row per robot, world frame (REP 103):
``[x m, y m, heading rad, v m/s, omega rad/s]``; wider rows (the episode kernel's) leave
the rest alone. The heading is not wrapped.

A command is the body twist ``(v m/s, omega rad/s)``, as ``geometry_msgs/Twist`` carries
it. Each control step of ``dt``:

1. ``v`` and ``omega`` move towards the command, clipped to their limits, by at most
   their acceleration limit times ``dt`` (ros2_control's diff_drive_controller limiter);
2. the wheels' rim speeds ``v -+ omega b / 2`` are clipped to the wheels' top speed;
3. the body moves along the arc those wheel speeds give over ``dt``. If the footprint
   would overlap a wall after the step, the position stays and the heading change is
   kept, as for the 4WS robots.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba as nb

from evorbc_ros.robots.diff_drive import DiffDriveGeometry
from sim_bridge.geometry import clearance

STATE_SIZE = 5
X, Y, HEADING, V, OMEGA = range(STATE_SIZE)


class DiffLimits(NamedTuple):
    """The geometry and limits the compiled kernels need, as plain floats."""

    separation: float  # m
    footprint_radius: float  # m
    max_v: float  # m/s
    max_omega: float  # rad/s
    max_v_step: float  # m/s per control step
    max_omega_step: float  # rad/s per control step
    max_wheel: float  # m/s
    dt: float  # s


def diff_limits(geometry: DiffDriveGeometry) -> DiffLimits:
    """Pack a :class:`DiffDriveGeometry` for the compiled kernels."""
    dt = geometry.control_period
    return DiffLimits(
        separation=geometry.wheel_separation,
        footprint_radius=geometry.footprint_radius,
        max_v=geometry.max_linear_speed,
        max_omega=geometry.max_angular_speed,
        max_v_step=geometry.max_linear_acceleration * dt,
        max_omega_step=geometry.max_angular_acceleration * dt,
        max_wheel=geometry.max_wheel_speed,
        dt=dt,
    )


@nb.njit(cache=True, inline="always")
def _toward(value, target, bound, max_step):
    """``value`` moved towards ``target`` (clipped to +-bound) by at most ``max_step``."""
    target = min(max(target, -bound), bound)
    delta = min(max(target - value, -max_step), max_step)
    return value + delta


@nb.njit(cache=True)
def body_twist(v, omega, lim):
    """The body's ``(v m/s, omega rad/s)`` once each wheel's rim speed is clipped."""
    half = 0.5 * lim.separation * omega
    left = min(max(v - half, -lim.max_wheel), lim.max_wheel)
    right = min(max(v + half, -lim.max_wheel), lim.max_wheel)
    return 0.5 * (left + right), (right - left) / lim.separation


@nb.njit(cache=True)
def step_diff(state, i, command, lim, boxes, candidates):
    """Advance robot ``i`` by one control step of ``lim.dt`` seconds.

    Args:
        state: ``(n, >= STATE_SIZE)`` robot states, updated in place.
        i: row of the robot to step.
        command: ``(2,)`` body twist ``(v m/s, omega rad/s)``.
        lim: :class:`DiffLimits`.
        boxes: ``(m, 6)`` wall boxes (see :mod:`sim_bridge.geometry`), may be empty.
        candidates: rows of ``boxes`` to test (every wall near the robot).

    Returns:
        Distance the body centre travelled this step (m, >= 0).

    """
    state[i, V] = _toward(state[i, V], command[0], lim.max_v, lim.max_v_step)
    state[i, OMEGA] = _toward(state[i, OMEGA], command[1], lim.max_omega, lim.max_omega_step)
    v, omega = body_twist(state[i, V], state[i, OMEGA], lim)
    distance = v * lim.dt
    dheading = omega * lim.dt
    if dheading == 0.0:
        dx, dy = distance, 0.0
    else:
        # Along the arc of radius distance / dheading about the ICR on the body's y axis;
        # 1 - cos = 2 sin^2(./2) keeps nearly straight arcs exact.
        radius = distance / dheading
        h = math.sin(0.5 * dheading)
        dx = radius * math.sin(dheading)
        dy = radius * 2.0 * h * h
    heading = state[i, HEADING]
    c = math.cos(heading)
    s = math.sin(heading)
    nx = state[i, X] + c * dx - s * dy
    ny = state[i, Y] + s * dx + c * dy
    state[i, HEADING] = heading + dheading
    if candidates.shape[0] > 0 and clearance(nx, ny, boxes, candidates) < lim.footprint_radius:
        return 0.0
    state[i, X] = nx
    state[i, Y] = ny
    return abs(distance)
