"""Which A1 gait design walks without falling? Joint ranges, couplings, frequency, servos.

Each variant changes ``config/robots/a1.yaml`` (the current design) and is measured on
the same random primitives (T = 2 s from rest, the repertoire's test):

* upright: the share whose body never tilts past the discard tilt (45 deg);
* the reach (distance from the start after T) of the upright ones: median, 90th
  percentile and largest, and how many 8 cm cells of displacement they fill, left and
  right of the start's axis;
* switching: the faster half of the upright primitives, chained at random every control
  cycle (0.1 s) or every second for 10 s, as an arbitrator may chain them; a fall is a
  tilt past 90 deg.

    python bench/bench_a1_design.py [--primitives 100] [--episodes 20] [--only NAME]
"""

from __future__ import annotations

import argparse
import copy
import os
import time

import numpy as np

from evorbc_ros.config import load_yaml_mapping
from sim_bridge.legged.evaluate import TILT, X, Y, evaluate_genes
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.legged.settings import robot_settings_from_mapping

SETTINGS = "config/robots/a1.yaml"
LEGS = ("FL", "FR", "RL", "RR")
CELL = 0.08  # m, the cells counted for the spread of displacements


def oscillators(data: dict, name: str, **entry) -> None:
    """Set oscillator ``NAME`` (or ``*_NAME`` for every leg) in ``data``, mirrored."""
    for leg in LEGS:
        data["oscillators"][f"{leg}_{name}"].update(entry)


def direct(data: dict, thigh: float, calf: float) -> None:
    """Thigh and calf evolved directly, ``+-thigh`` and ``+-calf`` deg about the stand."""
    for leg in LEGS:
        o = data["oscillators"]
        stand_thigh, stand_calf = 51.5, -103.0  # deg: the current design's standing pose
        mirror = "FR" if leg == "FL" else "FL" if leg == "FR" else "RR" if leg == "RL" else "RL"
        del o[f"{leg}_swing"], o[f"{leg}_knee"]
        o[f"{leg}_thigh"] = {
            "range_deg": [stand_thigh - thigh, stand_thigh + thigh],
            "mirror": f"{mirror}_thigh",
        }
        o[f"{leg}_calf"] = {
            "range_deg": [stand_calf - calf, stand_calf + calf],
            "mirror": f"{mirror}_calf",
        }
        data["joints"][f"{leg}_upper_joint"] = {f"{leg}_thigh": 1}
        data["joints"][f"{leg}_lower_joint"] = {f"{leg}_calf": 1}
    # Keep the per-leg order hip, thigh, calf.
    data["oscillators"] = {
        f"{leg}_{k}": data["oscillators"][f"{leg}_{k}"]
        for leg in LEGS
        for k in ("hip", "thigh", "calf")
    }


def fixed_hips(data: dict) -> None:
    """No hip abduction oscillator: every hip held at 0."""
    for leg in LEGS:
        del data["oscillators"][f"{leg}_hip"]
        data["joints"][f"{leg}_hip_joint"] = {"constant_deg": 0}


def _swing(deg):
    return lambda d: oscillators(d, "swing", range_deg=[-deg, deg])


def _knee(deg):
    return lambda d: oscillators(d, "knee", range_deg=[-103 - deg, -103 + deg])


def _hip(deg):
    return lambda d: oscillators(d, "hip", range_deg=[-deg, deg])


def _set(section, key, value):
    return lambda d: d[section].__setitem__(key, value)


VARIANTS = {
    "current": [],
    "1 Hz": [_set("gait", "frequency_hz", 1.0)],
    "1.5 Hz": [_set("gait", "frequency_hz", 1.5)],
    "direct thigh/calf +-23/29 deg": [lambda d: direct(d, 23.0, 29.0)],
    "swing 15, knee 20": [_swing(15.0), _knee(20.0)],
    "swing 35, knee 29": [_swing(35.0)],
    "knee 15": [_knee(15.0)],
    "hip 6": [_hip(6.0)],
    "hip 20": [_hip(20.0)],
    "hips fixed": [fixed_hips],
    "gain 40": [_set("servo", "gain", 40.0)],
    "gain 10": [_set("servo", "gain", 10.0)],
    "torque 20": [_set("servo", "max_torque", 20.0)],
    "velocity 10": [_set("servo", "max_velocity", 10.0)],
}


def episode(sim: LeggedSim, table, rows: np.ndarray, hold: int, fallen: float) -> bool:
    """Run ``rows[k // hold]`` in cycle ``k``; True if the robot fell over."""
    sim.reset()
    steps = sim.physics.steps(sim.settings.control_period)
    for cycle in range(len(rows) * hold):
        row = rows[cycle // hold]
        targets = table.joint_targets(sim.step_times(steps), np.full(steps, row))
        tilt, _ = sim.run(targets, fallen)
        if tilt > fallen:
            return True
    return False


def study(name: str, changes, args) -> dict:
    """Measure one variant; print and return its figures."""
    data = copy.deepcopy(load_yaml_mapping(SETTINGS))
    for change in changes:
        change(data)
    settings = robot_settings_from_mapping(data, SETTINGS)
    start = time.perf_counter()
    with LeggedSim(settings) as sim:
        rng = np.random.default_rng(args.seed)
        genes = rng.uniform(-1.0, 1.0, (args.primitives, settings.gait.n_parameters))
        out = evaluate_genes(sim, genes, 2.0, settings.control_period, settings.discard_tilt)
        upright = out[:, TILT] <= settings.discard_tilt
        reach = np.hypot(out[:, X], out[:, Y])
        cells = {tuple(c) for c in np.floor(out[upright][:, [X, Y]] / CELL + 0.5).astype(int)}
        left = sum(1 for c in cells if c[1] > 0)
        right = sum(1 for c in cells if c[1] < 0)
        fast = upright & (reach >= np.median(reach[upright]))
        table = sim.gait_table(genes[fast])
        n, fallen = len(table), settings.fallen_tilt
        every = sum(
            episode(sim, table, rng.integers(n, size=100), 1, fallen) for _ in range(args.episodes)
        )
        second = sum(
            episode(sim, table, rng.integers(n, size=10), 10, fallen) for _ in range(args.episodes)
        )
    r = {
        "upright": float(upright.mean()),
        "reach_median": float(np.median(reach[upright])),
        "reach_p90": float(np.percentile(reach[upright], 90)),
        "reach_max": float(reach[upright].max()),
        "cells": len(cells),
        "left": left,
        "right": right,
        "fell_switching_0.1s": every,
        "fell_switching_1s": second,
    }
    print(
        f"{name:<32} upright {r['upright']:4.0%}  reach median {r['reach_median']:.2f} "
        f"p90 {r['reach_p90']:.2f} max {r['reach_max']:.2f} m  cells {len(cells):>3} "
        f"(L {left} R {right})  fell switching every 0.1 s {every:>2}/{args.episodes}, "
        f"every 1 s {second:>2}/{args.episodes}  [{time.perf_counter() - start:.0f} s, "
        f"load {os.getloadavg()[0]:.1f}]",
        flush=True,
    )
    return r


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--primitives", type=int, default=100)
    parser.add_argument("--episodes", type=int, default=20)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--only", help="run only the variants whose name contains this")
    args = parser.parse_args()
    for name, changes in VARIANTS.items():
        if args.only is None or args.only in name:
            study(name, changes, args)


if __name__ == "__main__":
    main()
