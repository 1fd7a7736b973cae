"""The post-evaluation in batches, saved as it goes (offline_evolution/arbitrator/post_scores.py).

A hexapod post-selection runs for half an hour; an interruption in it now loses at most a
batch, and batching changes nothing that is written.
"""

import dataclasses
import json

import numpy as np
import pytest
from conftest import SMALL_TASK, evolution_settings

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.defaults import default_repertoire, paper_arbitrator
from evorbc_ros.repertoire import Repertoire
from offline_evolution.arbitrator.evolve import evolve
from offline_evolution.arbitrator.post_scores import PostScores, score_candidates, scores_key
from offline_evolution.checkpoint import CheckpointError, Interrupted
from offline_evolution.maze_task.task import MazeTaskSettings, make_task
from offline_evolution.runs.errors import UserError
from offline_evolution.runs.frame import explained

GENERATIONS = 3


def settings(neat_file, repertoire, **changes):
    return evolution_settings(
        neat_file, repertoire, SMALL_TASK, seed=5, generations=GENERATIONS, **changes
    )


class StopInPostEvaluation:
    """``should_stop`` that answers yes from its ``after``-th call on: polled once after each
    generation, so ``after = GENERATIONS + 1`` stops after the post-evaluation's first batch."""

    def __init__(self, after: int) -> None:
        self.calls, self.after = 0, after

    def __call__(self) -> bool:
        self.calls += 1
        return self.calls >= self.after


def stopped_in_post_evaluation(tmp_path, s, repertoire):
    """Run ``s`` with a checkpoint until the post-evaluation's first batch is saved; the
    checkpoint's path and contents."""
    ckpt = tmp_path / "c.json"
    with pytest.raises(Interrupted):
        evolve(s, repertoire, checkpoint=ckpt, should_stop=StopInPostEvaluation(GENERATIONS + 1))
    return ckpt, json.loads(ckpt.read_text())


def changed_first_row(ckpt, saved) -> None:
    """Write ``saved`` back with the first candidate's fitness all 9.0."""
    saved["post_scores"]["fitness"][0] = [9.0] * len(saved["post_scores"]["fitness"][0])
    ckpt.write_text(json.dumps(saved))


def test_an_interrupted_post_evaluation_resumes_with_the_rows_it_saved(
    tmp_path, small_neat_file, small_repertoire
):
    s = settings(small_neat_file, small_repertoire)
    straight = evolve(s, small_repertoire)
    ckpt = tmp_path / "c.json"
    with pytest.raises(Interrupted) as info:
        evolve(s, small_repertoire, checkpoint=ckpt, should_stop=StopInPostEvaluation(4))
    candidates = straight.post_evaluation.candidates
    assert info.value.iteration == GENERATIONS
    assert info.value.during == f"the post-evaluation (1 of {candidates} candidates done)"
    saved = json.loads(ckpt.read_text())
    assert len(saved["post_scores"]["fitness"]) == 1  # the first batch: one candidate
    resumed = evolve(s, small_repertoire, checkpoint=ckpt)
    assert resumed.selected_network == straight.selected_network
    np.testing.assert_array_equal(
        resumed.post_evaluation.all_fitness, straight.post_evaluation.all_fitness
    )
    assert not ckpt.exists()  # removed at the end, as before

    # The saved row is used, not run again: a row changed in the file shows in the result.
    changed_first_row(*stopped_in_post_evaluation(tmp_path, s, small_repertoire))
    assert evolve(s, small_repertoire, checkpoint=ckpt).post_evaluation.all_fitness[0] == 9.0


def test_rows_saved_for_other_starts_are_run_again(tmp_path, small_neat_file, small_repertoire):
    s = settings(small_neat_file, small_repertoire)
    ckpt, saved = stopped_in_post_evaluation(tmp_path, s, small_repertoire)
    changed_first_row(ckpt, saved)
    # post_samples only chooses the written genome, so it may change on resume; then the
    # saved rows are of other starts and are not used.
    wider = dataclasses.replace(s, post_samples=2)
    resumed = evolve(wider, small_repertoire, checkpoint=ckpt)
    straight = evolve(wider, small_repertoire)
    np.testing.assert_array_equal(
        resumed.post_evaluation.all_fitness, straight.post_evaluation.all_fitness
    )
    assert resumed.post_evaluation.episodes == 2 * (1 + 2)  # nominal + 2 draws, 2 mazes


def test_a_damaged_post_scores_entry_is_named(tmp_path, small_neat_file, small_repertoire):
    s = settings(small_neat_file, small_repertoire)
    ckpt, saved = stopped_in_post_evaluation(tmp_path, s, small_repertoire)
    saved["post_scores"]["reached"][0][0] = 1  # not true or false
    ckpt.write_text(json.dumps(saved))
    with pytest.raises(CheckpointError, match=r"post_scores\.reached must hold true or false"):
        evolve(s, small_repertoire, checkpoint=ckpt)


def test_the_cli_says_the_run_stopped_in_its_post_evaluation():
    with pytest.raises(UserError) as info, explained("generation"):
        raise Interrupted(200, "c.json", "the post-evaluation (5 of 66 candidates done)")
    assert str(info.value) == (
        "interrupted during the post-evaluation (5 of 66 candidates done); finished work is "
        "saved in c.json; run the same command again to resume"
    )


def test_legged_batches_equal_one_batch_and_report_as_one(tmp_path):
    """PyBullet hexapod episodes: scores in batches of one candidate equal one batch of
    all, and the batches' progress reads as one run of episodes."""
    arb = ArbitratorFile.load(paper_arbitrator("hexapod"))
    rep = Repertoire.load(default_repertoire("hexapod"))
    slower = dataclasses.replace(
        arb.network,
        connections=tuple(
            dataclasses.replace(c, weight=0.5 * c.weight) for c in arb.network.connections
        ),
    )
    networks = [arb.network, slower, arb.network]
    task = make_task(MazeTaskSettings(("hexapod",), 1.5, 1, "sensors/hexapod.yaml"), "hexapod", 1)
    try:
        controller = task.controller("evorbc", rep, arb.mapping)
        starts = np.concatenate([task.sample_starts(np.random.default_rng(2)) for _ in range(2)])
        whole = task.evaluate(networks, controller, starts)
        calls, batches = [], []
        fitness, reached = score_candidates(
            task,
            controller,
            networks,
            starts,
            PostScores("k"),
            after_batch=lambda done, total: batches.append((done, total)),
            progress=lambda done, total: calls.append((done, total)),
            target_seconds=0.0,  # never grow: one candidate a batch
        )
        assert task.progress is None  # the task's own reporter is back
    finally:
        task.close()
    np.testing.assert_array_equal(fitness, whole.fitness.reshape(3, 2))
    np.testing.assert_array_equal(reached, whole.reached.reshape(3, 2))
    assert fitness[0].tolist() != fitness[1].tolist()  # the candidates differ
    assert batches == [(1, 3), (2, 3), (3, 3)]
    assert calls == [(0, 6), (1, 6), (2, 6), (3, 6), (4, 6), (5, 6), (6, 6)]


def test_the_key_is_of_the_genomes_their_order_and_the_starts():
    genomes = [
        {"key": 1, "nodes": [[0, 0.5]], "fitness": 1.0},
        {"key": 2, "nodes": [], "fitness": 0.5},
    ]
    starts = np.array([[0, -1.0, 0.5, 0.0], [0, 1.0, 0.5, 1.5]])
    key = scores_key(genomes, starts)
    assert key == scores_key([dict(g) for g in genomes], starts.copy())
    other_weight = [{**genomes[0], "nodes": [[0, 0.6]]}, genomes[1]]
    other_start = starts.copy()
    other_start[1, 3] = 1.6  # the same shape
    for changed in (
        scores_key(other_weight, starts),
        scores_key(genomes[::-1], starts),
        scores_key(genomes, other_start),
        scores_key(genomes, starts.reshape(4, 2)),
    ):
        assert changed != key


def test_a_run_stopped_in_its_post_evaluation_runs_on_to_more_generations(
    tmp_path, small_neat_file, small_repertoire
):
    # Its saved rows are of the old hall of fame: the longer run scores its own.
    s = settings(small_neat_file, small_repertoire)
    ckpt, _ = stopped_in_post_evaluation(tmp_path, s, small_repertoire)
    longer = dataclasses.replace(s, generations=GENERATIONS + 2)
    with pytest.raises(Interrupted):  # stops after the first of the two new generations
        evolve(longer, small_repertoire, checkpoint=ckpt, should_stop=lambda: True)
    assert "post_scores" not in json.loads(ckpt.read_text())
    resumed = evolve(longer, small_repertoire, checkpoint=ckpt)
    straight = evolve(longer, small_repertoire)
    assert resumed.selected_network == straight.selected_network
    np.testing.assert_array_equal(
        resumed.post_evaluation.all_fitness, straight.post_evaluation.all_fitness
    )
