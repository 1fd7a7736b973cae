"""Each post-selection candidate of a kept checkpoint, on the run's own post-selection episodes.

docs/generalisation.md ("What the kept checkpoint tells"): for every genome of the hall of
fame (the candidates the post-selection chooses from, in its order), the share of the
run's post-selection episodes it reaches in the task's own mazes (each maze's nominal start
and ``post_samples`` random starts; per maze too) and in the generated validation mazes
(never the held-out set), and its mean fitness in each. Seeded like the run's own
post-selection, so the figures are the ones its rule saw.

    .venv/bin/python docs/runs/generalise/ship/candidates.py CHECKPOINT REPERTOIRE OUT.json
"""

from __future__ import annotations

import json
import os
import sys

from evorbc_ros.repertoire import Repertoire, RepertoireError
from offline_evolution.arbitrator.evolve import Evolution, EvolutionSettings
from offline_evolution.arbitrator.selection import post_evaluation_starts, validation_rows


def main(checkpoint: str, repertoire: str, out: str) -> None:
    """Write one row per candidate to ``out`` (JSON)."""
    with open(checkpoint) as f:
        settings = EvolutionSettings(**json.load(f)["settings"])
    try:
        rep = Repertoire.load(repertoire)
    except RepertoireError as e:
        sys.exit(str(e))
    if rep.fingerprint() != settings.repertoire_fingerprint:
        sys.exit(f"{repertoire}: not the repertoire {checkpoint} was evolved with")
    if not (settings.task.get("training") or {}).get("post_mazes"):
        sys.exit(f"{checkpoint}: its task has no generated validation mazes to compare with")
    run = Evolution(settings, rep, 1)
    try:
        run.restore(checkpoint)
        candidates = run.hall.candidates()
        starts = post_evaluation_starts(run.task, settings.seed, settings.post_samples)
        result = run.task.evaluate([run.network(g) for g in candidates], run.controller, starts)
        n = len(starts)
        reached = result.reached.reshape(len(candidates), n).astype(bool)
        fitness = result.fitness.reshape(len(candidates), n)
        held = validation_rows(run.task, settings.post_samples)
        mazes = len(run.task.nominal_starts())  # the task's own mazes, one nominal start each
        names = [m.name for m in run.task.mazes[:mazes]]
        maze_of_row = starts[: n - held, 0].astype(int)  # rows are (maze, x, y, heading)
        rows = []
        for i, genome in enumerate(candidates):
            own = reached[i, : n - held]
            rows.append(
                {
                    "candidate": i,
                    "key": genome["key"],
                    "training_fitness": genome["fitness"],
                    "nominal_all": bool(own[:mazes].all()),
                    "own_reached": float(own.mean()),
                    "own_per_maze": {
                        name: float(own[maze_of_row == k].mean()) for k, name in enumerate(names)
                    },
                    "validation_reached": float(reached[i, n - held :].mean()),
                    "own_fitness": float(fitness[i, : n - held].mean()),
                    "validation_fitness": float(fitness[i, n - held :].mean()),
                }
            )
    finally:
        run.close()
    with open(out + ".tmp", "w") as f:
        json.dump({"checkpoint": checkpoint, "episodes": n, "validation_episodes": held,
                   "candidates": rows}, f, indent=1)  # fmt: skip
    os.replace(out + ".tmp", out)


if __name__ == "__main__":
    main(*sys.argv[1:4])
