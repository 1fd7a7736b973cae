"""A small real hexapod repertoire for tests: tripod gaits and their mirror images."""

import numpy as np

from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.hexapod import mirror_genes, parameter_specs
from sim_bridge.hexapod.physics import HexapodSim
from sim_bridge.hexapod.robot import DISCARD_TILT, describe_simulation
from sim_bridge.legged.evaluate import HEADING, TILT, X, Y, evaluate_genes


def tripod(offset_a=0.0):
    """A tripod gait: legs lf, lr, rm swing with phase 0, the others half a cycle later;
    ``offset_a`` (joint-range units) shifts every hip forward and curves the walk."""
    genes = [0.0]
    for leg in range(6):
        phase = 0.0 if leg in (0, 2, 4) else 0.5
        genes += [offset_a, 1.0, 2 * phase - 1]
        genes += [0.0, -0.4, 2 * ((phase + 0.75) % 1) - 1]
    return np.array(genes)


def tripod_repertoire() -> Repertoire:
    """Six primitives evaluated in PyBullet: straight, curving both ways, and mirrors."""
    genes = np.array([tripod(), tripod(0.3), tripod(-0.3)])
    genes = np.vstack([genes, mirror_genes(genes)])
    sim = HexapodSim()
    try:
        out = evaluate_genes(sim, genes, 2.0, 0.1, DISCARD_TILT)
    finally:
        sim.close()
    assert np.all(out[:, TILT] < DISCARD_TILT)
    return Repertoire(
        robot="hexapod",
        parameters=parameter_specs(),
        genes=genes,
        behaviour=out[:, [X, Y]],
        heading=out[:, HEADING],
        quality=np.ones(len(genes)),
        metric="circular+tilt",
        eval_time=2.0,
        bin_size=0.08,
        seed=0,
        algorithm={"simulation": describe_simulation(sim.geometry, sim.physics)},
    )
