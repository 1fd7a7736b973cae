"""What the outcome model knew, cycle by cycle, in an adapted offline episode.

The episode kernel keeps its adaptation state inside the episode (docs/design/adaptation.md,
"Offline episodes"); an evaluation returns the poses, choices and network outputs.
:func:`replay_model` feeds them to the onboard :class:`~evorbc_ros.adaptation.OnlineAdaptation`
exactly as the kernel's ``_adapt`` does (pose at each cycle's start stamped
``round(t dt 1e9)`` ns, yaw through the bridge's quaternion and back, the grid's choice at
the centre of the point's cell), so it takes the same observations, and checks that it
chooses what the episode chose. It gives the number of observations and of primitives
observed after each cycle, whether the choice differed from the grid's, and the corrected
outcomes at the end.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from evorbc_ros.adaptation import AdaptationSettings, OnlineAdaptation, outcome_table
from evorbc_ros.goal import quaternion_yaw
from evorbc_ros.mapping import NO_PRIMITIVE, clamped_cell, map_point
from sim_bridge.geometry import planar_quaternion


@dataclass(frozen=True)
class ReplayedModel:
    """One adapted episode's model, cycle by cycle (``k`` cycles run).

    Attributes:
        observations: ``(k,)`` observations taken before each cycle's choice.
        observed: ``(k,)`` distinct primitives in the model before each cycle's choice.
        asked: ``(k,)`` the grid's choice (what the network asked for; -1: a stop).
        changed: ``(k,)`` the primitive run differs from the grid's choice.
        corrected: ``(n, 3)`` the corrected outcomes ``(dx m, dy m, dheading rad)`` over
            ``T`` after the last cycle's choice.
        in_model: the primitives whose observations the model holds at the end.
        disagreements: cycles whose replayed choice is not the episode's (0 expected).
    """

    observations: np.ndarray
    observed: np.ndarray
    asked: np.ndarray
    changed: np.ndarray
    corrected: np.ndarray
    in_model: np.ndarray
    disagreements: int


def grid_choice(controller, m1: float, m2: float) -> tuple[int, float, float]:
    """The lookup grid's primitive for outputs ``(m1, m2)`` and its cell's centre (m, m).

    ``controller``: the task's EvoRBC ``ControllerArrays`` (mapping and lookup grid), as
    the kernel's ``_decide`` and ``_adapt`` read them.
    """
    px, py = map_point(int(controller.map_kind), controller.map_params, m1, m2)
    nx, ny = controller.lookup_table.shape
    o, c = controller.lookup_origin, controller.lookup_cell
    i = clamped_cell((px - o[0]) / c[0], nx)
    j = clamped_cell((py - o[1]) / c[1], ny)
    return int(controller.lookup_table[i, j]), o[0] + (i + 0.5) * c[0], o[1] + (j + 0.5) * c[1]


def replay_model(
    repertoire,
    controller,
    settings: AdaptationSettings,
    expected: np.ndarray | None,
    dt: float,
    pose: np.ndarray,
    choice: np.ndarray,
    outputs: np.ndarray,
) -> ReplayedModel:
    """Replay an adapted episode's outcome model from its traces.

    Args:
        repertoire: the controller's repertoire.
        controller: the task's ``ControllerArrays`` for it.
        settings, expected: the episode's adaptation settings and expected outcomes
            (``(n, 3)`` or None: the recorded ones).
        dt: s, the control period.
        pose: ``(k + 1, 3)`` poses (x m, y m, heading rad) at each cycle's start.
        choice: ``(k,)`` the primitive the episode ran each cycle.
        outputs: ``(k, n_outputs)`` the network's outputs each cycle.
    """
    recorded = outcome_table(repertoire.behaviour, repertoire.heading)
    online = OnlineAdaptation(recorded, repertoire.eval_time, settings, expected)
    k = len(choice)
    observations = np.zeros(k, dtype=np.int64)
    observed = np.zeros(k, dtype=np.int64)
    asked = np.full(k, NO_PRIMITIVE, dtype=np.int64)
    changed = np.zeros(k, dtype=bool)
    disagreements = 0
    for t in range(k):
        x, y, h = (float(v) for v in pose[t])
        z, w = planar_quaternion(h)
        online.put_pose(round(t * dt * 1e9), x, y, quaternion_yaw(0.0, 0.0, z, w))
        online.before_choice()
        observations[t] = online.model.observations
        observed[t] = online.model.used
        ran = int(choice[t])
        if ran != NO_PRIMITIVE:
            g, cx, cy = grid_choice(controller, float(outputs[t, 0]), float(outputs[t, 1]))
            chosen = online.choose(cx, cy, g)
            disagreements += chosen != ran
            asked[t] = g
            changed[t] = ran != g
        online.after_choice(ran)
    slots = online.model.slots
    return ReplayedModel(
        observations,
        observed,
        asked,
        changed,
        online.model.corrected.copy(),
        np.sort(slots[slots >= 0]),
        disagreements,
    )
