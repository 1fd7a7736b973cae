"""What the runs' controllers did: mapping outputs and chosen primitives (Fig. 14, 18).

Each run's written controller is replayed from every maze's nominal start of its own task
(recorded in the arbitrator file) with its own repertoire; the outputs and the chosen
primitives' displacements of every control cycle are pooled over the runs.
"""

from __future__ import annotations

import numpy as np

from offline_evolution.study.results import (
    CHOSEN_BINS,
    OUTPUT_BINS,
    FinishedRun,
    SelectionCounts,
)


def aggregate_selection(runs: list[FinishedRun]) -> tuple[np.ndarray, np.ndarray, float]:
    """Pool the replays of ``runs``' controllers.

    Returns:
        ``outputs (k, 2)`` mapping outputs in [0, 1], ``chosen (k, 2)`` the chosen
        primitives' displacements (m, start frame), and the largest displacement of the
        repertoires (m), for the panel's extent.
    """
    from evorbc_ros.config import build_settings
    from offline_evolution.maze_task.replay import replay
    from offline_evolution.maze_task.task import MazeTaskSettings, make_task

    outputs, chosen, reach = [], [], 0.0
    for run in runs:
        arb = run.arbitrator()
        repertoire = run.repertoire()
        if arb.kind != "evorbc" or repertoire is None:
            continue
        settings = build_settings(
            MazeTaskSettings, arb.evolution["task"], f"{run.folder}: evolution.task"
        )
        task = make_task(settings, arb.robot, workers=1)
        try:
            _, result = replay(arb, task, task.nominal_starts(), repertoire)
        finally:
            task.close()
        for e in range(len(result.cycles)):
            n = int(result.cycles[e])
            out = result.outputs[e, :n, :2]
            keep = np.all(np.isfinite(out), axis=1) & (result.choice[e, :n] >= 0)
            outputs.append(out[keep])
            chosen.append(repertoire.behaviour[result.choice[e, :n][keep]])
        reach = max(reach, float(np.max(np.abs(repertoire.behaviour))))
    empty = np.empty((0, 2))
    return (
        np.concatenate(outputs) if outputs else empty,
        np.concatenate(chosen) if chosen else empty,
        reach,
    )


def selection_counts(runs: list[FinishedRun]) -> SelectionCounts:
    """The selection heatmaps' counts of ``runs`` (:func:`aggregate_selection`, binned)."""
    outputs, chosen, reach = aggregate_selection(runs)
    out, _, _ = np.histogram2d(*outputs.T, bins=OUTPUT_BINS, range=[[0, 1], [0, 1]])
    extent = [[-reach, reach], [-reach, reach]]
    ran, _, _ = np.histogram2d(*chosen.T, bins=CHOSEN_BINS, range=extent)
    return SelectionCounts(len(runs), reach, out.astype(np.int64), ran.astype(np.int64))
