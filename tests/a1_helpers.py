"""A small real A1 repertoire for tests: trots, curving trots and their mirror images."""

import numpy as np

from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots import registry
from sim_bridge.legged.evaluate import HEADING, TILT, X, Y, evaluate_genes
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.legged.settings import load_robot_settings

#: Trot: the diagonal pairs FL+RR and FR+RL half a cycle apart (cycles).
TROT_PHASE = {"FL": 0.0, "FR": 0.5, "RL": 0.5, "RR": 0.0}


def a1_settings():
    """The A1's settings, from its registration's settings file."""
    return load_robot_settings(registry.lookup("a1").model.path())


def trot(left=0.5, right=0.5, knee=1.0):
    """A trot's genes: each leg's swing of amplitude ``left`` / ``right`` (of its range) and
    its knee flexing a quarter cycle ahead, so that the foot lifts while the leg swings
    forward. Unequal amplitudes curve the walk."""
    genes = [-1.0]  # rho: nearly a sine
    for leg, phase in TROT_PHASE.items():
        amplitude = left if leg[1] == "L" else right
        genes += [0.0, 2 * amplitude - 1, 2 * phase - 1]
        genes += [0.0, 2 * knee - 1, 2 * ((phase + 0.25) % 1) - 1]
    return np.array(genes)


def trot_repertoire() -> Repertoire:
    """Six primitives evaluated in PyBullet: trots of three curvatures and their mirrors."""
    settings = a1_settings()
    genes = np.array([trot(), trot(0.6, 0.3), trot(0.8, 0.2)])
    genes = np.vstack([genes, settings.gait.mirror_genes(genes)])
    sim = LeggedSim(settings)
    try:
        out = evaluate_genes(sim, genes, 2.0, 0.1, settings.discard_tilt)
    finally:
        sim.close()
    assert np.all(out[:, TILT] < settings.discard_tilt)
    return Repertoire(
        robot="a1",
        parameters=settings.gait.parameter_specs(),
        genes=genes,
        behaviour=out[:, [X, Y]],
        heading=out[:, HEADING],
        quality=np.ones(len(genes)),
        metric="circular+tilt",
        eval_time=2.0,
        bin_size=0.08,
        seed=0,
        algorithm={"simulation": settings.describe()},
    )
