"""The hexapod's maze episodes, perturbed and not, as digests that pin them bit for bit.

Before the hexapod and the generic legged robot shared one episode runner, the hexapod
had its own (``offline_evolution/maze_task/hexapod_episode.py``, with the perturbed worlds
of docs/design.md section 21). ``test_legged_hexapod.py`` holds the digests these cases
gave on that code (commit 9ef42ce) and checks that the shared runner still gives them.
Only public API is used here, so the same cases ran on the old code and run on the new.
"""

from __future__ import annotations

import hashlib

import numpy as np
from neat_helpers import neat_config, network_spec, random_genomes

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.defaults import default_repertoire, paper_arbitrator
from evorbc_ros.repertoire import Repertoire
from offline_evolution.maze_task.perturbation import PerturbationSet, load_perturbations
from offline_evolution.maze_task.task import MazeTaskSettings, make_task


def digest(result) -> str:
    """SHA-256 of every array of an :class:`EpisodeResult`: names, dtypes, shapes, bytes."""
    h = hashlib.sha256()
    for name, value in result._asdict().items():
        if value is None:
            h.update(f"{name}:None;".encode())
            continue
        a = np.ascontiguousarray(value)
        h.update(f"{name}:{a.dtype.str}:{a.shape};".encode())
        h.update(a.tobytes())
    return h.hexdigest()


def _perturbed(task, network, controller, starts, perturbation, seed):
    """Episodes from ``starts`` in worlds drawn as ``evorbc-evolve evaluate`` draws them."""
    world = perturbation.draw(np.random.default_rng([seed, 1]), len(starts))
    starts = world.shift_starts(starts, task.mazes, task.footprint_radius)
    return task.evaluate([network], controller, starts, record=True, world=world), world


#: A set that acts on every quantity the hexapod takes, latency a whole cycle everywhere.
HARSH = PerturbationSet(
    name="harsh",
    friction=(0.5, 0.6),
    body_mass=(1.2, 1.3),
    payload=(0.1, 0.2),
    servo_strength=(0.6, 0.7),
    servo_speed=(0.6, 0.7),
    latency_cycles=(1, 1),
    range_noise=(0.03, 0.05),
    dropout=(0.1, 0.2),
    start_position=(0.02, 0.05),
    start_heading_deg=(5, 10),
)


def cases() -> dict:
    """Case name -> ``(EpisodeResult, world draw or None)`` on the hexapod's maze task.

    * ``shipped``: the shipped controller from its maze's nominal start, unperturbed (30 s);
    * ``shipped-realistic``: the shipped controller from 3 seeded starts in worlds of the
      ``realistic`` set (seed 5: latency 0, 1 and 0 cycles);
    * ``standard-harsh``: a standard-NEAT network (37 outputs) from 2 starts in worlds of
      :data:`HARSH`, 4 s episodes.
    """
    out = {}
    arb = ArbitratorFile.load(paper_arbitrator("hexapod"))
    rep = Repertoire.load(default_repertoire("hexapod"))
    task = make_task(MazeTaskSettings(**arb.evolution["task"]), "hexapod", workers=1)
    try:
        controller = task.controller("evorbc", rep, arb.mapping)
        out["shipped"] = (
            task.evaluate([arb.network], controller, task.nominal_starts(), True),
            None,
        )
        starts = task.sample_starts(np.random.default_rng(3))
        starts = np.vstack([starts, task.sample_starts(np.random.default_rng(4))])
        starts = np.vstack([starts, task.sample_starts(np.random.default_rng(5))])
        realistic = load_perturbations("realistic")
        out["shipped-realistic"] = _perturbed(task, arb.network, controller, starts, realistic, 5)
    finally:
        task.close()
    task = make_task(MazeTaskSettings(("hexapod",), 4.0, 1, "sensors/hexapod.yaml"), "hexapod", 1)
    try:
        config = neat_config(6, 37, path="config/neat/hexapod.ini")
        network = network_spec(random_genomes(config, 1, seed=11)[0], config)
        starts = np.vstack([task.sample_starts(np.random.default_rng(k)) for k in (1, 2)])
        out["standard-harsh"] = _perturbed(
            task, network, task.controller("standard"), starts, HARSH, 2
        )
    finally:
        task.close()
    return out


if __name__ == "__main__":
    for name, (result, world) in cases().items():
        latency = None if world is None else world.values["latency_cycles"].tolist()
        print(name, digest(result), result.reached.tolist(), result.cycles.tolist(), latency)
        print("   ", [float(d).hex() for d in result.final_distance], result.fell.tolist())
