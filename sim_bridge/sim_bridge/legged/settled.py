"""What a legged primitive does when the controller executes it: its *settled* outcome.

A legged repertoire records each primitive from rest over ``T`` with its gait clock at 0.
Onboard adaptation observes something else (docs/design/adaptation.md, "Legged robots:
whole executions"): a primitive chosen after another one, with the gait clock running on
from the first primitive of the episode, its first ``settle_cycles`` cycles skipped and the
next ``window`` cycles summed, extended to ``T``. On the intact robot in a maze that reads
far from the recorded outcome, so a model that compares observations with the recorded
outcomes learns the gap, not the damage.

:func:`settled_outcomes` measures the expected observation instead, in PyBullet on flat
ground, on the intact robot: for each primitive and each of ``contexts`` seeded contexts,
from the rest state, predecessor runs of random other primitives (1-3 cycles each, for
2 cycles plus a share of one gait period, stratified over the contexts so that the gait's
phase at the switch covers the period), then the primitive for ``settle_cycles + window``
cycles; the body's motion over the last ``window`` cycles, read as the arbitrator node
reads odometry (position and the yaw of the orientation), extended to ``T`` as the arc it
is (:func:`evorbc_ros.adaptation.motion.extend_arc`). The mean over the contexts is the
primitive's settled outcome. Each context draws from its own generator, seeded by
``(seed, primitive, context)``, and starts from the saved rest state (Bullet is
deterministic), so a primitive's outcome does not depend on which others are computed.
"""

from __future__ import annotations

import math

import numpy as np

from evorbc_ros.adaptation.motion import extend_arc, relative_motion
from evorbc_ros.goal import yaw_from_quaternion
from evorbc_ros.robots.legged import LeggedGaitTable
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.legged.settings import LeggedRobotSettings

#: Seeded contexts (predecessors and gait phase) averaged per primitive.
CONTEXTS = 4
#: The longest predecessor run, in cycles (the shipped hexapod controller's runs last 1.8
#: cycles on average, docs/design/adaptation.md).
LONGEST_RUN = 3
#: Predecessor cycles before any phase offset: the robot is walking when the primitive starts.
LEAD_CYCLES = 2


def gait_period_cycles(settings: LeggedRobotSettings) -> int:
    """Control cycles in one gait period (at least 1): 10 for the hexapod (1 Hz, 0.1 s)."""
    return max(1, round(1.0 / (settings.gait.frequency * settings.control_period)))


def context_outcomes(
    settings: LeggedRobotSettings,
    genes: np.ndarray,
    horizon: float,
    settle_cycles: int = 1,
    window: int = 5,
    contexts: int = CONTEXTS,
    seed: int = 0,
    indices=None,
    sim: LeggedSim | None = None,
) -> np.ndarray:
    """``(m, contexts, 3)`` each context's observation ``(dx m, dy m, dheading rad)`` over ``T``.

    Args:
        settings: the legged robot (intact; flat ground, no walls).
        genes: ``(n, 1 + 3 k)`` the repertoire's genes (predecessors are drawn among them).
        horizon: ``T`` (s), the repertoire's evaluation time.
        settle_cycles, window: the adaptation settings' (cycles skipped, cycles observed).
        contexts: seeded contexts per primitive.
        seed: seeds every context's generator with ``(seed, primitive, context)``.
        indices: the primitives to compute (``m`` of them, default all ``n``).
        sim: a simulation without walls to run in (default: one built and closed here).

    Raises:
        ValueError: one line: genes of another width than the robot's, fewer than two
            primitives, or a non-positive ``horizon``, ``window`` or ``contexts``.
    """
    genes = np.asarray(genes, dtype=np.float64)
    width = settings.gait.n_parameters
    if genes.ndim != 2 or genes.shape[1] != width or len(genes) < 2:
        raise ValueError(
            f"legged settled outcomes: genes must be (n >= 2, {width}) for the "
            f"{settings.name}, got {genes.shape}"
        )
    checks = (("horizon", horizon), ("window", window), ("contexts", contexts))
    for name, value in checks:
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ValueError(f"legged settled outcomes: {name} must be > 0, got {value!r}")
    if settle_cycles < 0:
        raise ValueError(
            f"legged settled outcomes: settle_cycles must be >= 0, got {settle_cycles!r}"
        )
    n = len(genes)
    rows = np.arange(n) if indices is None else np.asarray(indices, dtype=np.int64)
    if len(rows) and (rows.min() < 0 or rows.max() >= n):
        raise ValueError(f"legged settled outcomes: indices must be in [0, {n})")
    own = sim is None
    sim = LeggedSim(settings) if own else sim
    try:
        table = LeggedGaitTable(genes, settings.gait, settings.name)
        per_period = settings.physics.steps(settings.control_period)
        period = gait_period_cycles(settings)
        tau = window * settings.control_period
        out = np.empty((len(rows), contexts, 3))
        for r, i in enumerate(rows):
            for j in range(contexts):
                rng = np.random.default_rng((seed, int(i), j))
                lead = LEAD_CYCLES + int((j + rng.random()) * period / contexts)
                sim.reset()  # the rest state, the gait clock at 0 (as an episode starts)
                for other, cycles in _predecessors(rng, lead, n, int(i)):
                    _run(sim, table, other, cycles, per_period)
                _run(sim, table, int(i), settle_cycles, per_period)
                a = _odometry(sim)
                _run(sim, table, int(i), window, per_period)
                b = _odometry(sim)
                out[r, j] = extend_arc(*relative_motion(*a, *b), tau, float(horizon))
        return out
    finally:
        if own:
            sim.close()


def settled_outcomes(
    settings: LeggedRobotSettings,
    genes: np.ndarray,
    horizon: float,
    settle_cycles: int = 1,
    window: int = 5,
    contexts: int = CONTEXTS,
    seed: int = 0,
) -> np.ndarray:
    """``(n, 3)`` every primitive's settled outcome: the mean of :func:`context_outcomes`.

    Deterministic given its arguments. Cost: ``n x contexts`` runs of about
    ``LEAD_CYCLES + period / 2 + settle_cycles + window`` cycles (the shipped hexapod
    repertoire, 405 primitives x 4 contexts: about 20,000 cycles).

    Raises:
        ValueError: as :func:`context_outcomes`.
    """
    samples = context_outcomes(settings, genes, horizon, settle_cycles, window, contexts, seed)
    return samples.mean(axis=1)


def _predecessors(rng: np.random.Generator, lead: int, n: int, primitive: int):
    """``[(other primitive, cycles), ...]``: runs of 1 to ``LONGEST_RUN`` cycles, lead in all."""
    runs = []
    while lead > 0:
        cycles = min(lead, int(rng.integers(1, LONGEST_RUN + 1)))
        other = int(rng.integers(n - 1))
        runs.append((other + (other >= primitive), cycles))  # any primitive but this one
        lead -= cycles
    return runs


def _run(sim: LeggedSim, table: LeggedGaitTable, primitive: int, cycles: int, per_period: int):
    """Run ``primitive`` for ``cycles`` control cycles, the gait clock running on (eq. 10)."""
    steps = cycles * per_period
    if steps:
        times = sim.step_times(steps)  # the clock began with the first predecessor
        sim.run(table.joint_targets(times, np.full(steps, primitive)))


def _odometry(sim: LeggedSim) -> tuple[float, float, float]:
    """The body's ``(x m, y m, yaw rad)`` as the bridge's odometry gives it to the node."""
    (x, y, _), orn = sim.base_pose()
    return float(x), float(y), yaw_from_quaternion(*orn)
