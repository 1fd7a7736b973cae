"""Perturbation sets, as the search imports them (docs/design.md section 21).

The sets live in :mod:`sim_bridge.perturbation`, one layer down, so that the simulation
bridge and ``evorbc-sim`` load the same files; this module keeps the names the search and
its users import, and checks a set's damage against a maze task (:func:`check_damage`).
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


def check_damage(task, perturbation: PerturbationSet) -> None:
    """Refuse a set whose damage ``task``'s simulation cannot apply (its ``damage_applied``).

    Raises:
        ValueError: naming the damage and the kinds the simulation applies.
    """
    damage, takes = perturbation.damage, tuple(getattr(task, "damage_applied", ()))
    if damage is not None and damage.kind not in takes:
        raise ValueError(
            f"this robot's simulation cannot apply damage {damage.kind} "
            f"(it applies: {', '.join(takes) or 'no damage'})"
        )


__all__ = [
    "KINEMATIC",
    "NONE",
    "PYBULLET_LEGGED",
    "QUANTITIES",
    "PerturbationSet",
    "WorldDraw",
    "check_damage",
    "load_perturbations",
    "perturbation_dir",
]
