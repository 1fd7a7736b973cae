"""How well a legged robot's gait design walks: the measures the design search scores.

The measures (docs/legged.md, "The gait design search"; docs/a1.md for how each was first
used by hand):

* **upright**: the share of random primitives (genes uniform in [-1, 1]) that never tilt
  past the discard tilt in T = 2 s from rest, the repertoire's test (eq. 6);
* **switching**: the probability that a maze episode (``maze_time`` s) ends without a fall
  (tilt past the fallen tilt) while the steady primitives (never past :data:`POOL_TILT`)
  are chained at random every control cycle, 0.1 s, as an arbitrator may chain them.
  Every other episode runs in free space from the rest pose; the others in a walled room
  (``walls``: the maze's walls) from its centre, facing a random heading, chaining only
  the steady primitives that carry the body forward, so that they press against a wall
  as an arbitrator steering for a target beyond one does. The falls per second of
  simulated time, ``falls / exposure``, give the survival over a maze episode,
  ``exp(-falls x maze_time / exposure)`` (a constant fall rate: longer episodes fall more
  often, which the share of short episodes did not see);
* **endpoint error**: the median distance (m) between where a primitive ends after T at
  the design's physics rate and at a fine reference (1 kHz, 50 solver iterations), over
  the primitives the reference keeps upright;
* **reach**: the median distance (m) from the start after T of the upright primitives;
* **speed**: the :data:`SPEED_PERCENTILE` th percentile of the upright primitives'
  distance from the start after T, over T (m/s): what the design's fast gaits make;
* **cost**: CPU milliseconds of one process per T-second evaluation.

Units: m, s, rad (deg where a name says so).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from sim_bridge.legged.evaluate import TILT, X, Y, evaluate_genes
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.legged.settings import LeggedRobotSettings
from sim_bridge.quiet_pybullet import p

#: s, a primitive's evaluation time (the repertoire's T, paper Sec. V-B).
T = 2.0
#: rad: run every primitive the whole T so that endpoints compare.
NO_EARLY_STOP = math.radians(180.0)
#: The fine reference: physics Hz and solver iterations (docs/a1.md, "Physics rate").
REFERENCE = (1000.0, 50)
#: rad: primitives chained when switching never tilted past this in their T; circular+tilt
#: quality keeps such steady primitives in a repertoire (docs/a1.md, "Gait design").
POOL_TILT = math.radians(20.0)
#: The percentile of the upright primitives' speeds that :attr:`DesignMeasures.speed` is.
SPEED_PERCENTILE = 90.0


def with_physics(
    settings: LeggedRobotSettings, rate: float, iterations: int | None = None
) -> LeggedRobotSettings:
    """``settings`` simulated at ``rate`` Hz (and ``iterations`` solver iterations)."""
    iterations = settings.physics.solver_iterations if iterations is None else iterations
    physics = dataclasses.replace(settings.physics, rate=rate, solver_iterations=iterations)
    return dataclasses.replace(settings, physics=physics)


def endpoint_errors(rows: np.ndarray, ref: np.ndarray, discard: float) -> np.ndarray:
    """``(kept,)`` m: endpoint distances of outcome ``rows`` from the reference's.

    Over the primitives the reference keeps upright (a fallen robot's endpoint is chaos).
    """
    kept = ref[:, TILT] <= discard
    return np.hypot(rows[kept, X] - ref[kept, X], rows[kept, Y] - ref[kept, Y])


def fall_time(
    sim: LeggedSim,
    table,
    rows: np.ndarray,
    hold: int,
    fallen: float,
    pose: tuple[float, float, float] | None = None,
) -> float:
    """Run primitive ``rows[k // hold]`` of ``table`` in control cycle ``k``, from rest.

    Each switch keeps the oscillators' clock (an arbitrator's switch, eq. 10).

    Args:
        pose: ``(x m, y m, heading rad)`` of the start (world frame); None: the rest pose.

    Returns:
        s of simulated time at the end of the cycle the robot fell over in (tilted past
        ``fallen`` rad), or ``inf`` if it did not.

    """
    sim.reset(*(pose or ()))
    period = sim.settings.control_period
    steps = sim.physics.steps(period)
    for cycle in range(len(rows) * hold):
        row = rows[cycle // hold]
        targets = table.joint_targets(sim.step_times(steps), np.full(steps, row))
        tilt, _ = sim.run(targets, fallen)
        if tilt > fallen:
            return (cycle + 1) * period
    return math.inf


def switching_episode(sim: LeggedSim, table, rows: np.ndarray, hold: int, fallen: float) -> bool:
    """True if the robot fell over in :func:`fall_time`'s episode from the rest pose."""
    return math.isfinite(fall_time(sim, table, rows, hold, fallen))


def switching_falls(
    settings: LeggedRobotSettings,
    genes: np.ndarray,
    forward: np.ndarray,
    episodes: int,
    episode_time: float,
    seed: int | list[int],
    walls: np.ndarray | None = None,
) -> tuple[int, float]:
    """Chain ``genes`` at random every control cycle: ``(episodes that fell, s simulated)``.

    Every other episode runs in free space from the rest pose; with ``walls`` the others
    start at the room's centre facing a random heading and chain only the primitives
    that carry the body forward (``forward``, ``(n,)`` bool, x > 0 m in the start frame):
    they press against a wall, as an arbitrator steering for a target beyond one does.

    Args:
        genes: ``(n, 1 + 3 k)`` primitives, the pool.
        episode_time: s, each episode (a whole number of control periods).
        seed: of the sequences and headings (an int or a NumPy seed sequence).

    """
    falls, exposure = 0, 0.0
    if not len(genes) or not episodes:
        return falls, exposure
    period = settings.control_period
    ahead = np.flatnonzero(forward)
    with LeggedSim(settings, walls) as room:
        table = room.gait_table(genes)
        rng = np.random.default_rng(seed)
        cycles = round(episode_time / period)
        for k in range(episodes):
            heading = float(rng.uniform(-math.pi, math.pi))
            walled = walls is not None and k % 2 == 1 and len(ahead) > 0
            pool = ahead if walled else np.arange(len(genes))
            sequence = pool[rng.integers(len(pool), size=cycles)]
            pose = (0.0, 0.0, heading) if walled else None
            fell = fall_time(room, table, sequence, 1, settings.fallen_tilt, pose)
            falls += math.isfinite(fell)
            exposure += min(fell, cycles * period)
    return falls, exposure


def survival(falls: int, exposure: float, maze_time: float) -> float:
    """The probability of a ``maze_time``-s episode without a fall.

    At a constant rate of ``falls`` per ``exposure`` s; 0 when nothing was simulated.
    """
    return math.exp(-falls * maze_time / exposure) if exposure > 0 else 0.0


def joint_limits(settings: LeggedRobotSettings) -> tuple[np.ndarray, np.ndarray]:
    """``(joints,)`` lower and upper limits (rad) of the actuated joints, in command order.

    From the URDF's ``<limit>``; a joint without usable limits (continuous, or lower not
    below upper) has ``-inf, inf``.
    """
    with LeggedSim(settings) as sim:
        infos = [p.getJointInfo(sim.robot, j, physicsClientId=sim.client) for j in sim.joints]
    low = np.array([i[8] if i[8] < i[9] else -np.inf for i in infos])
    high = np.array([i[9] if i[8] < i[9] else np.inf for i in infos])
    return low, high


@dataclass(frozen=True)
class DesignMeasures:
    """A design's measures on one set of random primitives (see the module docstring)."""

    upright: float  # share of primitives upright after T
    switching: float  # probability of a maze episode without a fall
    endpoint_error: float  # m, median against the reference (inf: none to compare)
    reach: float  # m, median distance after T of the upright primitives (0: none)
    ms_per_evaluation: float  # CPU ms per T-second evaluation at the design's rate
    steady: int  # primitives in the switching pool
    speed: float  # m/s, SPEED_PERCENTILE of the upright primitives' distance / T (0: none)
    falls: int  # switching episodes that fell
    exposure: float  # s of switching simulated (each episode to its fall or end)
    # A trial repertoire's (validation only; offline_evolution/gait_design/trial.py):
    # its primitives (0: none grown) and their median distance after T (m). Its
    # switching then replaces the random gaits' in ``switching``, ``falls``, ``exposure``.
    trial_primitives: int = 0
    trial_reach: float = 0.0

    def as_dict(self) -> dict:
        """Plain data (JSON-safe; an infinite error is written as None)."""
        d = dataclasses.asdict(self)
        if not math.isfinite(d["endpoint_error"]):
            d["endpoint_error"] = None
        return d

    @classmethod
    def from_dict(cls, d: dict) -> DesignMeasures:
        """The inverse of :meth:`as_dict`."""
        error = d["endpoint_error"]
        return cls(**{**d, "endpoint_error": math.inf if error is None else error})


def reference_rows(settings: LeggedRobotSettings, genes: np.ndarray) -> np.ndarray:
    """``(n, 6)`` outcome rows of ``genes`` at the fine :data:`REFERENCE` physics, full T."""
    with LeggedSim(with_physics(settings, *REFERENCE)) as sim:
        return evaluate_genes(sim, genes, T, settings.control_period, NO_EARLY_STOP)


def measure_design(
    settings: LeggedRobotSettings,
    genes: np.ndarray,
    accuracy: int,
    episodes: int,
    episode_time: float,
    seed: int,
    reference: np.ndarray,
    walls: np.ndarray | None = None,
    maze_time: float = 30.0,
) -> DesignMeasures:
    """Measure one design on random primitives ``genes``.

    Args:
        settings: the design.
        genes: ``(n, 1 + 3 k)`` primitives in [-1, 1]; the first ``accuracy`` run the
            whole T (for the endpoint error and the cost), the others stop at the discard
            tilt.
        accuracy: how many of ``genes`` are compared with the reference.
        episodes: switching episodes.
        episode_time: s, each switching episode (a whole number of control periods).
        seed: of the switching sequences and start headings.
        reference: ``(accuracy, 6)`` rows of :func:`reference_rows` for ``genes[:accuracy]``.
        walls: ``(m, 6)`` wall boxes about the origin the switching episodes start at
            (facing a random heading); None: free space, from the rest pose.
        maze_time: s, the maze episode the switching survival is given for.

    """
    period, discard = settings.control_period, settings.discard_tilt
    with LeggedSim(settings) as sim:
        start = time.process_time()
        full = evaluate_genes(sim, genes[:accuracy], T, period, NO_EARLY_STOP)
        cost = (time.process_time() - start) / max(accuracy, 1)
        rest = evaluate_genes(sim, genes[accuracy:], T, period, discard)
    rows = np.concatenate([full, rest])
    upright = rows[:, TILT] <= discard
    reach = np.hypot(rows[upright, X], rows[upright, Y])
    steady = np.flatnonzero(rows[:, TILT] <= POOL_TILT)
    falls, exposure = switching_falls(
        settings, genes[steady], rows[steady, X] > 0.0, episodes, episode_time, seed, walls
    )
    errors = endpoint_errors(full, reference, discard)
    return DesignMeasures(
        upright=float(upright.mean()),
        switching=survival(falls, exposure, maze_time),
        endpoint_error=float(np.median(errors)) if len(errors) else math.inf,
        reach=float(np.median(reach)) if len(reach) else 0.0,
        ms_per_evaluation=1e3 * cost,
        steady=len(steady),
        speed=float(np.percentile(reach, SPEED_PERCENTILE)) / T if len(reach) else 0.0,
        falls=falls,
        exposure=exposure,
    )
