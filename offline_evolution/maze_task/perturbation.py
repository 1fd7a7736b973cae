"""Perturbation sets, as the search imports them (docs/design.md section 21).

The sets live in :mod:`sim_bridge.perturbation`, one layer down, so that the simulation
bridge and ``evorbc-sim`` load the same files; this module keeps the names the search and
its users import.
"""

from sim_bridge.perturbation import (
    KINEMATIC,
    NONE,
    PYBULLET_LEGGED,
    QUANTITIES,
    PerturbationSet,
    WorldDraw,
    load_perturbations,
    perturbation_dir,
)

__all__ = [
    "KINEMATIC",
    "NONE",
    "PYBULLET_LEGGED",
    "QUANTITIES",
    "PerturbationSet",
    "WorldDraw",
    "load_perturbations",
    "perturbation_dir",
]
