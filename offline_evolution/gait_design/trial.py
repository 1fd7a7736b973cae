"""A trial repertoire per validated design: the switching its own repertoire would meet.

Random gaits are slower than the ones MAP-Elites keeps. The A1's quick search chained
random steady gaits (a median 0.155 m in T) and saw no fall in 60 s; the repertoire then
grown on the design it chose (a median 0.76 m) fell in 31 of 50 episodes of 30 s when its
primitives were switched every 0.1 s (docs/your-robot.md, bench/legged_switching.py). So
the validation stage grows a small repertoire on each finalist, as the repertoire step
grows one (a CVT archive of 8 cm cells, Iso+LineDD, circular+tilt quality), and chains its
primitives instead (docs/legged.md, "The gait design search").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from offline_evolution.gait_design.objective import CELL
from offline_evolution.repertoire.archive import elites_by_cell
from offline_evolution.repertoire.map_elites import MapElites
from offline_evolution.repertoire.settings import MapElitesSettings
from sim_bridge.legged.gait_measures import T
from sim_bridge.legged.robot import LeggedRobot
from sim_bridge.legged.settings import LeggedRobotSettings

ITERATIONS = 5  # mutant batches after the random half of the budget


@dataclass(frozen=True)
class TrialRepertoire:
    """The elites of a small MAP-Elites run.

    ``genes (n, 1 + 3 k)``; ``x, y (n,)`` m, where each ends after T (start frame, x
    forward).
    """

    genes: np.ndarray
    x: np.ndarray
    y: np.ndarray

    @property
    def reach(self) -> float:
        """m, the median distance from the start after T (0 for an empty repertoire)."""
        return float(np.median(np.hypot(self.x, self.y))) if len(self.x) else 0.0


def trial_repertoire(
    settings: LeggedRobotSettings, evaluations: int, seed: int, workers: int | None = None
) -> TrialRepertoire:
    """Grow a repertoire of ``evaluations`` primitive evaluations on the design ``settings``.

    Half are random; the rest are :data:`ITERATIONS` batches of Iso+LineDD mutants, which
    carry the archive out to the fast gaits. Seeded; the result does not depend on
    ``workers`` (processes; default every core).
    """
    half = max(1, evaluations // 2)
    run_settings = MapElitesSettings(
        robot=settings.name,
        metric="circular+tilt",
        bin_size=CELL,
        eval_time=T,
        initial_batch=half,
        batch_size=max(1, (evaluations - half) // ITERATIONS),
        iterations=ITERATIONS,
        seed=seed,
        archive="cvt",
        variation="iso_line_dd",
    )
    robot = LeggedRobot(settings, workers=workers)
    run = MapElites(run_settings, robot)
    try:
        while not run.finished:
            run.step()
        elites = elites_by_cell(run.archive)
    finally:
        run.close()
    behaviour = np.asarray(elites["measures"], dtype=np.float64).reshape(-1, 2)
    return TrialRepertoire(
        np.asarray(elites["solution"], dtype=np.float64), behaviour[:, 0], behaviour[:, 1]
    )
