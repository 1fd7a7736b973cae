"""The standing check of a robot read from its URDF: it stands in its standing pose.

:func:`stand_check` spawns the robot of a settings text in PyBullet, lets it settle
(``physics.settle_time``), holds the standing pose ``seconds`` more and measures the root
link's height, the largest tilt and the footprint (docs/legged.md, "From a URDF").
Units: m, s, deg.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import yaml

from sim_bridge.legged.physics import LeggedSim
from sim_bridge.legged.settings import robot_settings_from_mapping
from sim_bridge.legged.urdf_settings import Measured


def stand_check(text: str, path: str | Path, seconds: float = 2.0) -> Measured:
    """Stand the robot of settings ``text`` (as if read from ``path``) for ``seconds`` s.

    Returns:
        the footprint at rest (m), the root link's height after standing (m) and the
        largest tilt while standing (deg), measured after the settle time.

    """
    settings = robot_settings_from_mapping(yaml.safe_load(text), path)
    with LeggedSim(settings) as sim:
        radius = sim.reach_radius()
        steps = settings.physics.steps(seconds)
        tilt, _ = sim.run(np.tile(settings.gait.standing_pose(), (steps, 1)))
        (_, _, height), _ = sim.base_pose()
    return Measured(radius, float(height), math.degrees(tilt), seconds)
