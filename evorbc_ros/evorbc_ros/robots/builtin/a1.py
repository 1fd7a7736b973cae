"""Unitree's A1 quadruped (docs/a1.md), registered: a legged robot from settings.

``config/robots/a1.yaml`` names the URDF that ships with pybullet_data (``a1/a1.urdf``: 12
revolute joints, 12.5 kg) and gives its gait, servos and physics; every factory is the
generic legged one (:mod:`.legged`).
"""

from __future__ import annotations

from evorbc_ros.robots.builtin.legged import legged_robot

ROBOTS = (
    legged_robot(
        "robots/a1.yaml",
        "Unitree A1 quadruped (pybullet_data URDF), 12 joints, 25-parameter periodic gait",
        # s, as the hexapod's (paper Table I): its fastest primitives reach 0.5 m/s, as the
        # hexapod's do, and its maze's shortest path is as long (docs/a1.md).
        episode_time=30.0,
        # Standard NEAT's extra generations at equal budget: a Table I repertoire's
        # simulated time (1.025M x 2 s) in generations of 150 x 30 s episodes.
        equal_budget_generations=455,
        # EvoRBC seed 1 of the A1 comparison over the reduced repertoire (docs/a1.md,
        # evorbc_ros/data/README.md).
        shipped_repertoire="a1.repertoire.json",
        shipped_arbitrator="a1.arbitrator.json",
    ),
)
