"""Which A1 gait design walks without falling? Joint ranges, couplings, frequency, servos.

Each variant is a change to the *first design* (:func:`first_design`: hip abduction
+-12 deg, swing +-25 deg, knee -103 +-29 deg, 2 Hz, servo gain 20 /s) or, for "chosen",
the design ``config/robots/a1.yaml`` holds now, and is measured on the same random
primitives (T = 2 s from rest, the repertoire's test). Runs made while the first design was
the settings file's printed it as "current"; docs/a1.md records both.

* upright: the share whose body never tilts past the discard tilt (45 deg);
* the reach (distance from the start after T) of the upright ones: median, 90th
  percentile and largest, and how many 8 cm cells of displacement they fill, left and
  right of the start's axis;
* switching: the faster half of the upright primitives (or, with ``--pool-tilt DEG``,
  the upright ones that never tilted past DEG in their 2 s), chained at random every
  control cycle (0.1 s) or every second for 10 s, as an arbitrator may chain them; a fall
  is a tilt past 90 deg;
* holding: the same primitives, each run alone for 10 s: does a gait that stayed upright
  for its 2 s test stay upright for longer, without any switch?

    python bench/bench_a1_design.py [--primitives 100] [--episodes 20] [--only NAME]
        [--pool-tilt DEG]
"""

from __future__ import annotations

import argparse
import copy
import os
import time

import numpy as np

from evorbc_ros.config import load_yaml_mapping
from sim_bridge.legged.evaluate import TILT, X, Y, evaluate_genes
from sim_bridge.legged.gait_measures import switching_episode as episode
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.legged.settings import robot_settings_from_mapping

SETTINGS = "config/robots/a1.yaml"
LEGS = ("FL", "FR", "RL", "RR")
CELL = 0.08  # m, the cells counted for the spread of displacements


def first_design(data: dict) -> None:
    """The first A1 design, whatever ``config/robots/a1.yaml`` holds now.

    Per leg, oscillators hip (abduction, +-12 deg, the right leg's the mirror image with
    the opposite sign), swing (+-25 deg) and knee (-132 to -74 deg), each hip joint driven
    by its hip oscillator; 2 Hz, servo gain 20 /s.
    """
    mirror = {"FL": "FR", "FR": "FL", "RL": "RR", "RR": "RL"}
    o = {}
    for leg in LEGS:
        o[f"{leg}_hip"] = {
            "range_deg": [-12, 12],
            "mirror": f"{mirror[leg]}_hip",
            "mirror_sign": -1,
        }
        o[f"{leg}_swing"] = {"range_deg": [-25, 25], "mirror": f"{mirror[leg]}_swing"}
        o[f"{leg}_knee"] = {"range_deg": [-132, -74], "mirror": f"{mirror[leg]}_knee"}
        data["joints"][f"{leg}_hip_joint"] = {f"{leg}_hip": 1}
        data["joints"][f"{leg}_upper_joint"] = {f"{leg}_swing": 1, f"{leg}_knee": -0.5}
        data["joints"][f"{leg}_lower_joint"] = {f"{leg}_knee": 1}
    data["oscillators"] = o
    data["gait"]["frequency_hz"] = 2.0
    data["servo"]["gain"] = 20.0


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
    "first design": [first_design],
    "1 Hz": [first_design, _set("gait", "frequency_hz", 1.0)],
    "1.5 Hz": [first_design, _set("gait", "frequency_hz", 1.5)],
    "direct thigh/calf +-23/29 deg": [first_design, lambda d: direct(d, 23.0, 29.0)],
    "swing 15, knee 20": [first_design, _swing(15.0), _knee(20.0)],
    "swing 35, knee 29": [first_design, _swing(35.0)],
    "knee 15": [first_design, _knee(15.0)],
    "hip 6": [first_design, _hip(6.0)],
    "hip 20": [first_design, _hip(20.0)],
    "hips fixed": [first_design, fixed_hips],
    "gain 40": [first_design, _set("servo", "gain", 40.0)],
    "gain 10": [first_design, _set("servo", "gain", 10.0)],
    "torque 20": [first_design, _set("servo", "max_torque", 20.0)],
    "velocity 10": [first_design, _set("servo", "max_velocity", 10.0)],
    "knee 15, gain 10": [first_design, _knee(15.0), _set("servo", "gain", 10.0)],
    "swing 15, knee 15, gain 10": [
        first_design,
        _swing(15.0),
        _knee(15.0),
        _set("servo", "gain", 10.0),
    ],
    "knee 15, gain 10, hips fixed": [
        first_design,
        _knee(15.0),
        _set("servo", "gain", 10.0),
        fixed_hips,
    ],
    "swing 20, knee 15, gain 10": [
        first_design,
        _swing(20.0),
        _knee(15.0),
        _set("servo", "gain", 10.0),
    ],
    "swing 20, knee 15, gain 10, hips fixed": [
        first_design,
        _swing(20.0),
        _knee(15.0),
        _set("servo", "gain", 10.0),
        fixed_hips,
    ],
    "knee 15, gain 10, hips fixed, 2.5 Hz": [
        first_design,
        _knee(15.0),
        _set("servo", "gain", 10.0),
        fixed_hips,
        _set("gait", "frequency_hz", 2.5),
    ],
    "swing 15, knee 15, gain 10, 2.5 Hz": [
        first_design,
        _swing(15.0),
        _knee(15.0),
        _set("servo", "gain", 10.0),
        _set("gait", "frequency_hz", 2.5),
    ],
    "chosen (config/robots/a1.yaml)": [],
}


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
        if args.pool_tilt is None:
            pool = upright & (reach >= np.median(reach[upright]))
        else:
            pool = out[:, TILT] <= np.radians(args.pool_tilt)
        table = sim.gait_table(genes[pool])
        n, fallen = len(table), settings.fallen_tilt
        every = sum(
            episode(sim, table, rng.integers(n, size=100), 1, fallen) for _ in range(args.episodes)
        )
        second = sum(
            episode(sim, table, rng.integers(n, size=10), 10, fallen) for _ in range(args.episodes)
        )
        held = [k % n for k in range(args.episodes)]
        alone = sum(episode(sim, table, np.array([k]), 100, fallen) for k in held)
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
        "pool": n,
        "fell_holding_10s": alone,
    }
    print(
        f"{name:<32} upright {r['upright']:4.0%}  reach median {r['reach_median']:.2f} "
        f"p90 {r['reach_p90']:.2f} max {r['reach_max']:.2f} m  cells {len(cells):>3} "
        f"(L {left} R {right})  fell switching every 0.1 s {every:>2}/{args.episodes}, "
        f"every 1 s {second:>2}/{args.episodes}, holding one {alone:>2}/{args.episodes} "
        f"(pool {n})  [{time.perf_counter() - start:.0f} s, "
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
    parser.add_argument(
        "--pool-tilt", type=float, help="switch among primitives that tilted at most DEG"
    )
    args = parser.parse_args()
    for name, changes in VARIANTS.items():
        if args.only is None or args.only in name:
            study(name, changes, args)


if __name__ == "__main__":
    main()
