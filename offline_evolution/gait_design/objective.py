"""The gait design search's objective and budgets (docs/legged.md, "The gait design search").

    score = upright x switching x accuracy x mobility - cost

* ``upright``: the share of random primitives upright after T (sim_bridge/legged/
  gait_measures.py);
* ``switching``: the probability that a maze episode (the robot's episode time, 30 s)
  ends without a fall while random steady primitives are chained every 0.1 s in a room
  of the maze's walls (gait_measures.py; walls and episode length felled the quick
  profile's A1, docs/your-robot.md);
* ``accuracy = min(1, CELL / endpoint error)``: 1 while the design's physics ends
  primitives within one archive cell (8 cm) of the 1 kHz reference, falling as 1 / error
  beyond: a repertoire whose cells are wrong misleads the arbitrator;
* ``mobility = min(1, SPREAD x speed / required speed)``: ``speed`` (m/s) is the 90th
  percentile of the upright random primitives' distance over T; the repertoire's search
  (MAP-Elites) finds faster gaits than random ones, and ``SPREAD`` = 2 is the lowest ratio
  measured between a quick repertoire's fastest forward primitive and that percentile
  (the Laikago's 0.185 m/s against 0.092 m/s; the A1's 0.75 against 0.20). The required
  speed (m/s) is the longest path of the robot's generated mazes over 2/3 of its episode
  time (maze_needs.py: the generator's own allowance; the A1: 8.67 m / 20 s = 0.43 m/s).
  Without it a robot that stands still (zero ranges, a soft servo) would score best, and
  a slow upright one (the quick profile's Laikago, docs/your-robot.md) did;
* ``cost = COST_PER_DOUBLING x log2(rate / 50 Hz)``: the CPU time of an evaluation is
  proportional to the physics rate (docs/a1.md: 25, 49, 129 ms at 100, 200, 500 Hz); each
  doubling halves the evaluations a budget buys, and costs as much as 5 % of the usable
  primitives. The rate, not a stopwatch, so that the same seed gives the same score.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from sim_bridge.legged.gait_measures import DesignMeasures

CELL = 0.08  # m, an archive cell of the A1 and hexapod (docs/a1.md, "Physics rate")
SPREAD = 2.0  # a repertoire's fastest forward speed over random gaits' 90th percentile
COST_PER_DOUBLING = 0.05
BASE_RATE = 50.0  # Hz, the cheapest rate tried: no cost

FORMULA = (
    "upright x survival of a maze episode switching among walls x min(1, 0.08 m / "
    "endpoint_error) x min(1, 2 x speed_p90 / (maze path / (2/3 x episode time))) "
    "- 0.05 x log2(rate_hz / 50 Hz)"
)


def terms(measures: DesignMeasures, rate: float, required_speed: float) -> dict[str, float]:
    """The objective's factors and cost (dimensionless); ``required_speed`` in m/s."""
    error = measures.endpoint_error
    return {
        "upright": measures.upright,
        "switching": measures.switching,
        "accuracy": min(1.0, CELL / error) if error > 0 else 1.0,
        "mobility": min(1.0, SPREAD * measures.speed / required_speed),
        "cost": COST_PER_DOUBLING * math.log2(rate / BASE_RATE),
    }


def score(measures: DesignMeasures, rate: float, required_speed: float) -> float:
    """The objective (higher is better; at most 1); ``required_speed`` in m/s."""
    t = terms(measures, rate, required_speed)
    return t["upright"] * t["switching"] * t["accuracy"] * t["mobility"] - t["cost"]


@dataclass(frozen=True)
class Budget:
    """How much a search measures and how many designs it tries."""

    gaits: int  # random primitives per design (T = 2 s from rest)
    accuracy: int  # of them, compared with the 1 kHz reference
    episodes: int  # switching episodes per design, in a walled room
    episode_time: float  # s per switching episode
    sobol: int  # designs of the space-filling stage (a power of 2)
    refine: int  # designs of the local refinement
    validate: int  # best designs measured again on fresh primitives
    # Validation's switching on a trial repertoire of each validated design (trial.py):
    # its evaluations (0: chain random gaits, as the search stages do) and its episodes,
    # each as long as the robot's maze episode.
    trial_evaluations: int = 0
    trial_episodes: int = 0

    def as_dict(self) -> dict:
        """Plain data (recorded in the checkpoint)."""
        return asdict(self)


#: ``--budget`` (fields in :class:`Budget`'s order): quick fits about 10 min on one core
#: for the A1 (docs/legged.md), plus about a minute on 2 cores per validated design for
#: its trial repertoire. The switching episodes simulate as much as before walls came
#: (quick 12 x 5 s, full 20 x 10 s), in fewer, longer episodes: pressing against a wall
#: takes time to fell a robot.
BUDGETS = {
    "quick": Budget(40, 8, 6, 10.0, 32, 32, 3, trial_evaluations=2000, trial_episodes=10),
    "full": Budget(60, 12, 10, 20.0, 64, 64, 5, trial_evaluations=6000, trial_episodes=20),
}
