"""The gait design search's objective and budgets (docs/legged.md, "The gait design search").

    score = upright x switching x accuracy x mobility - cost

* ``upright``, ``switching``: shares in [0, 1] (sim_bridge/legged/gait_measures.py);
* ``accuracy = min(1, CELL / endpoint error)``: 1 while the design's physics ends
  primitives within one archive cell (8 cm) of the 1 kHz reference, falling as 1 / error
  beyond: a repertoire whose cells are wrong misleads the arbitrator;
* ``mobility = min(1, reach / (REACH_SHARE x speed_bound x T))``: the upright primitives'
  median reach against a quarter of the archive's half-width; without it a robot that
  stands still (zero ranges) would score best;
* ``cost = COST_PER_DOUBLING x log2(rate / 50 Hz)``: the CPU time of an evaluation is
  proportional to the physics rate (docs/a1.md: 25, 49, 129 ms at 100, 200, 500 Hz); each
  doubling halves the evaluations a budget buys, and costs as much as 5 % of the usable
  primitives. The rate, not a stopwatch, so that the same seed gives the same score.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from sim_bridge.legged.gait_measures import DesignMeasures, T

CELL = 0.08  # m, an archive cell of the A1 and hexapod (docs/a1.md, "Physics rate")
REACH_SHARE = 0.25
COST_PER_DOUBLING = 0.05
BASE_RATE = 50.0  # Hz, the cheapest rate tried: no cost

FORMULA = (
    "upright x switching x min(1, 0.08 m / endpoint_error) "
    "x min(1, reach / (0.25 x speed_bound x 2 s)) - 0.05 x log2(rate_hz / 50 Hz)"
)


def terms(measures: DesignMeasures, rate: float, speed_bound: float) -> dict[str, float]:
    """The objective's factors and cost (dimensionless)."""
    error = measures.endpoint_error
    return {
        "upright": measures.upright,
        "switching": measures.switching,
        "accuracy": min(1.0, CELL / error) if error > 0 else 1.0,
        "mobility": min(1.0, measures.reach / (REACH_SHARE * speed_bound * T)),
        "cost": COST_PER_DOUBLING * math.log2(rate / BASE_RATE),
    }


def score(measures: DesignMeasures, rate: float, speed_bound: float) -> float:
    """The objective (higher is better; at most 1)."""
    t = terms(measures, rate, speed_bound)
    return t["upright"] * t["switching"] * t["accuracy"] * t["mobility"] - t["cost"]


@dataclass(frozen=True)
class Budget:
    """How much a search measures and how many designs it tries."""

    gaits: int  # random primitives per design (T = 2 s from rest)
    accuracy: int  # of them, compared with the 1 kHz reference
    episodes: int  # switching episodes per design
    episode_time: float  # s per switching episode
    sobol: int  # designs of the space-filling stage (a power of 2)
    refine: int  # designs of the local refinement
    validate: int  # best designs measured again on fresh primitives

    def as_dict(self) -> dict:
        """Plain data (recorded in the checkpoint)."""
        return asdict(self)


#: ``--budget``: quick fits about 10 min on one core for the A1 (docs/legged.md).
BUDGETS = {
    "quick": Budget(
        gaits=40, accuracy=8, episodes=12, episode_time=5.0, sobol=32, refine=32, validate=3
    ),
    "full": Budget(
        gaits=60, accuracy=12, episodes=20, episode_time=10.0, sobol=64, refine=64, validate=5
    ),
}
