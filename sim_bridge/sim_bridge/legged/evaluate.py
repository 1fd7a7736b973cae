"""Executing legged primitives from rest: the outcome MAP-Elites scores (paper Sec. V-B).

Each primitive starts from the same saved rest state, runs eq. 10 for T seconds (time from
0) and reports its final displacement and heading in the start frame, its path length and
the largest body tilt. A primitive that tilts past the discard limit stops at once: its
outcome is already decided (eq. 6 discards it), so the rest of its T seconds is not
simulated.
"""

from __future__ import annotations

import math

import numpy as np

from sim_bridge.legged.physics import LeggedSim

#: Columns of an outcome row.
X, Y, HEADING, PATH, TILT, SECONDS = range(6)


def evaluate_genes(
    sim: LeggedSim, genes: np.ndarray, eval_time: float, control_period: float, max_tilt: float
) -> np.ndarray:
    """Run primitives one after another in ``sim``.

    Args:
        sim: the simulation (its rest state is the start of every primitive).
        genes: ``(n, 1 + 3 k)`` genes in [-1, 1] (``k`` oscillators; the hexapod: 37).
        eval_time: T, s.
        control_period: s between heading samples (for unwrapping: the robot turns far
            less than pi in one period).
        max_tilt: rad; beyond it the primitive stops early.

    Returns:
        ``(n, 6)`` rows ``x, y`` (m, start frame: x forward, y left), heading (rad,
        unwrapped), path length (m), largest tilt (rad) and seconds simulated (less than
        ``eval_time`` if the primitive stopped early).

    """
    table = sim.gait_table(genes)
    x0, y0, h0 = sim.rest_pose()
    c0, s0 = math.cos(h0), math.sin(h0)
    per_period = sim.physics.steps(control_period)
    periods = round(eval_time / control_period)
    out = np.empty((len(table), 6))
    for i in range(len(table)):
        sim.reset()
        # The whole evaluation's targets at once (rad): one row per physics step.
        times = sim.step_times(per_period * periods)
        targets = table.joint_targets(times, np.full(len(times), i))
        heading, tilt, path, seconds = 0.0, 0.0, 0.0, 0.0
        for k in range(periods):
            t_max, d = sim.run(targets[k * per_period : (k + 1) * per_period], max_tilt)
            tilt, path = max(tilt, t_max), path + d
            x, y, yaw, _ = sim.pose()
            heading += math.remainder(yaw - h0 - heading, 2.0 * math.pi)
            seconds = sim.time
            if tilt > max_tilt:
                break
        dx, dy = x - x0, y - y0
        out[i] = (c0 * dx + s0 * dy, -s0 * dx + c0 * dy, heading, path, tilt, seconds)
    return out
