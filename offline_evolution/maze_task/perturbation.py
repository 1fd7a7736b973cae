"""Perturbation sets, as the search imports them (docs/design.md section 21).

The sets live in :mod:`sim_bridge.perturbation`, one layer down, so that the simulation
bridge and ``evorbc-sim`` load the same files; this module keeps the names the search and
its users import, and checks a set's damage against a maze task (:func:`check_damage`).
"""

import numpy as np

from evorbc_ros.config import ConfigError
from sim_bridge.damage import part_names
from sim_bridge.perturbation import (
    KINEMATIC,
    NONE,
    PYBULLET_LEGGED,
    QUANTITIES,
    PerturbationSet,
    WorldDraw,
    is_set_file,
    load_perturbations,
    perturbation_dir,
)


def check_damage(task, perturbation: PerturbationSet) -> None:
    """Refuse a set whose damage ``task`` cannot apply, or on a part its robot has not.

    ``task.damage_applied``: the kinds its simulation applies; ``task.damage_legs``: its
    legs' foot links.

    Raises:
        ValueError: naming the damage and the kinds the simulation applies, or the parts.
    """
    damage, takes = perturbation.damage, tuple(getattr(task, "damage_applied", ()))
    if damage is None:
        return
    if damage.kind not in takes:
        raise ValueError(
            f"this robot's simulation cannot apply damage {damage.kind} "
            f"(it applies: {', '.join(takes) or 'no damage'})"
        )
    names = part_names(damage.kind, tuple(getattr(task, "damage_legs", ())))
    try:
        damage.draw(np.zeros(1, dtype=np.int64)).part(0, names)
    except ConfigError as e:
        raise ValueError(str(e)) from None


__all__ = [
    "KINEMATIC",
    "NONE",
    "PYBULLET_LEGGED",
    "QUANTITIES",
    "PerturbationSet",
    "WorldDraw",
    "check_damage",
    "is_set_file",
    "load_perturbations",
    "perturbation_dir",
]
