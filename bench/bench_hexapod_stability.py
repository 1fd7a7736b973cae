"""How often does the hexapod fall over when an arbitrator switches gaits? Per leg design.

A repertoire primitive only has to stay upright for the 2 s of its evaluation, from rest.
An arbitrator chains primitives for 30 s and may switch every 0.1 s. For each candidate
geometry this benchmark draws random primitives, keeps those that pass the repertoire's
2 s test (tilt below 45 deg), keeps the faster half of them (repertoires are full of fast
walkers), and counts falls (tilt past 90 deg):

* holding one primitive for 10 s;
* switching to a random kept primitive every control cycle for 30 s;
* switching every 1 s for 30 s.

    python bench/bench_hexapod_stability.py [--episodes 30] [--seed 0] [--only NAME]
"""

from __future__ import annotations

import argparse

import numpy as np

from evorbc_ros.robots.hexapod import GaitTable, HexapodGeometry
from sim_bridge.hexapod.maze_world import FALLEN_TILT
from sim_bridge.hexapod.physics import HexapodSim
from sim_bridge.hexapod.robot import DISCARD_TILT
from sim_bridge.legged.evaluate import TILT, X, Y, evaluate_genes

#: The first design (fast servos, long shins); the other variants change it.
FIRST = {"max_joint_velocity": 10.0, "tibia_length": 0.14}
VARIANTS = {
    "first (10 rad/s, coxa 0.06, tibia 0.14)": FIRST,
    "coxa 0.10": {**FIRST, "coxa_length": 0.10},
    "tibia 0.10": {**FIRST, "tibia_length": 0.10},
    "coxa 0.10, tibia 0.11": {**FIRST, "coxa_length": 0.10, "tibia_length": 0.11},
    "coxa 0.10, tibia 0.11, femur 0.10": {
        **FIRST,
        "coxa_length": 0.10,
        "tibia_length": 0.11,
        "femur_length": 0.10,
    },
    "servos 5 rad/s": {**FIRST, "max_joint_velocity": 5.0},
    "current (servos 5 rad/s, tibia 0.10)": {},
    "servos 1.5 N m, tibia 0.10": {
        **FIRST,
        "coxa_torque": 1.5,
        "femur_torque": 1.5,
        "tibia_torque": 1.5,
        "tibia_length": 0.10,
    },
}


def episode(sim: HexapodSim, table: GaitTable, rows: np.ndarray, hold: int) -> bool:
    """Run ``rows[k // hold]`` in cycle ``k``; True if the robot fell over."""
    sim.reset()
    steps = sim.physics.steps(sim.geometry.control_period)
    for cycle in range(len(rows) * hold):
        row = rows[cycle // hold]
        tilt, _ = sim.run(
            table.joint_targets(sim.step_times(steps), np.full(steps, row)), FALLEN_TILT
        )
        if tilt > FALLEN_TILT:
            return True
    return False


def study(name: str, changes: dict, episodes: int, seed: int) -> None:
    """Print the fall counts of one geometry."""
    geometry = HexapodGeometry(**changes)
    sim = HexapodSim(geometry)
    try:
        rng = np.random.default_rng(seed)
        genes = rng.uniform(-1.0, 1.0, size=(20 * episodes, 37))
        out = evaluate_genes(sim, genes, 2.0, geometry.control_period, DISCARD_TILT)
        upright = out[:, TILT] < DISCARD_TILT
        reach = np.hypot(out[:, X], out[:, Y])
        fast = upright & (reach >= np.median(reach[upright]))
        kept = genes[fast]
        table = GaitTable(kept, geometry)
        n = len(kept)
        held = sum(episode(sim, table, np.array([k % n]), 100) for k in range(episodes))
        every = sum(episode(sim, table, rng.integers(n, size=300), 1) for _ in range(episodes))
        second = sum(episode(sim, table, rng.integers(n, size=30), 10) for _ in range(episodes))
    finally:
        sim.close()
    print(
        f"{name:<36} upright 2 s {upright.mean():4.0%}, median reach of the kept "
        f"{np.median(reach[fast]):.2f} m | fell: holding 10 s {held:>2}/{episodes}, "
        f"switching every 0.1 s {every:>2}/{episodes}, every 1 s {second:>2}/{episodes}",
        flush=True,
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--episodes", type=int, default=30)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--only", help="run only the variants whose name contains this")
    args = parser.parse_args()
    for name, changes in VARIANTS.items():
        if args.only is None or args.only in name:
            study(name, changes, args.episodes, args.seed)


if __name__ == "__main__":
    main()
