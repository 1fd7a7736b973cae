"""Choosing the written controller from a whole run: hall-of-fame snapshots, the
``balanced`` rule, and validation mazes that may change when a run resumes
(docs/design.md sections 8 and 22)."""

import numpy as np
import pytest
from test_evolution import _ScoredTask
from test_training_mazes import histories, interrupt, run_settings, task_dict

from offline_evolution.arbitrator.evolve import Evolution, EvolutionSettings, evolve
from offline_evolution.arbitrator.selection import HallOfFame, post_evaluate
from offline_evolution.checkpoint import Interrupted


def test_snapshots_keep_every_nth_champion_and_leave_the_evolution_alone(
    small_neat_file, small_repertoire
):
    base = run_settings(small_neat_file, small_repertoire, task_dict(pool=0), generations=6)
    plain = evolve(base, small_repertoire)
    snap = EvolutionSettings(**{**base.as_dict(), "snapshot_every": 2})
    run = Evolution(snap, small_repertoire)
    try:
        champions = []
        while not run.finished:
            run.step()
            # the generation's champion is the newest of the recent list
            champions.append(run.hall.recent[-1]["key"])
        # generations 1, 3, 5 (every 2nd, counting from 1), each its generation's champion
        assert [g["key"] for g in run.hall.snapshots] == [champions[i] for i in (1, 3, 5)]
        assert all(g in run.hall.candidates() for g in run.hall.snapshots)
        result = run.result(0.0)
    finally:
        run.close()
    # Snapshots only widen the choice: the population evolves exactly as without them.
    assert histories(result) == histories(plain)
    assert result.best_network == plain.best_network
    assert result.post_evaluation.candidates >= plain.post_evaluation.candidates


def test_snapshots_survive_a_checkpoint(tmp_path, small_neat_file, small_repertoire):
    s = run_settings(small_neat_file, small_repertoire, task_dict(pool=0), generations=6)
    s = EvolutionSettings(**{**s.as_dict(), "snapshot_every": 2})
    straight = evolve(s, small_repertoire)
    ckpt = tmp_path / "run.checkpoint.json"
    interrupt(s, small_repertoire, ckpt, after=4)
    resumed = evolve(s, small_repertoire, checkpoint=ckpt)
    assert resumed.selected_network == straight.selected_network
    assert resumed.post_evaluation.candidates == straight.post_evaluation.candidates
    assert np.array_equal(resumed.post_evaluation.all_fitness, straight.post_evaluation.all_fitness)


def test_hall_of_fame_snapshots_round_trip_and_old_halls_have_none():
    hall = HallOfFame(2)
    hall.update([{"key": 1, "fitness": 0.9}, {"key": 2, "fitness": 0.8}])
    hall.snapshot({"key": 7, "fitness": 0.1})
    hall.snapshot({"key": 7, "fitness": 0.1})  # an elite that wins twice is kept once
    assert [g["key"] for g in hall.candidates()] == [1, 2, 7]
    assert HallOfFame.from_dict(hall.to_dict()).snapshots == hall.snapshots
    assert "snapshots" not in HallOfFame(2).to_dict()  # files of runs without them unchanged
    assert HallOfFame.from_dict({"size": 2, "top": [], "recent": []}).snapshots == []


def test_balanced_rule_weighs_own_and_validation_mazes_equally():
    # columns: 2 rows in the task's own mazes, then 4 in validation mazes
    fitness = [
        [1.3, 1.3, 0.9, 0.9, 0.9, 0.9],  # own 1.3, validation 0.9: mean 1.033, balanced 1.1
        [0.5, 0.5, 1.2, 1.2, 1.2, 1.2],  # own 0.5, validation 1.2: mean 0.967, balanced 0.85
        [1.0, 1.0, 1.1, 1.1, 1.1, 1.1],  # own 1.0, validation 1.1: mean 1.067, balanced 1.05
    ]
    reached = np.ones((3, 6))
    starts = np.zeros((6, 4))
    task = _ScoredTask(fitness, reached)
    assert post_evaluate(task, None, [0, 1, 2], starts, "mean", 1, validation=4).index == 2
    post = post_evaluate(task, None, [0, 1, 2], starts, "balanced", 1, validation=4)
    assert post.index == 0
    assert post.fitness == pytest.approx(np.mean(fitness[0]))  # reported: the plain mean
    # Without validation rows it is the mean rule.
    assert post_evaluate(task, None, [0, 1, 2], starts, "balanced", 1, validation=0).index == 2


def test_validation_mazes_may_change_when_a_run_resumes(
    tmp_path, small_neat_file, small_repertoire
):
    s = run_settings(small_neat_file, small_repertoire, task_dict(pool=0), generations=4)
    ckpt = tmp_path / "c.json"
    with pytest.raises(Interrupted):
        evolve(s, small_repertoire, checkpoint=ckpt, should_stop=lambda: True)
    wider = EvolutionSettings(
        **{**s.as_dict(), "task": task_dict(pool=0, post_mazes=3), "post_rule": "balanced"}
    )
    result = evolve(wider, small_repertoire, checkpoint=ckpt)
    straight = evolve(wider, small_repertoire)
    assert histories(result) == histories(straight)
    # two own mazes x (nominal + 1 draw) + 3 validation mazes x 1 start
    assert result.post_evaluation.episodes == 2 * 2 + 3
    assert result.post_evaluation.rule == "balanced"


def test_nominal_then_balanced_keeps_the_candidates_that_reach_every_nominal_start():
    # columns: 1 nominal row, 1 random row in the task's own maze, then 2 validation rows
    fitness = [
        [0.9, 1.3, 1.3, 1.3],  # misses the nominal start: best balanced (1.2), not eligible
        [1.1, 1.0, 1.0, 1.0],  # reaches it: balanced 1.025
        [1.1, 0.6, 1.2, 1.2],  # reaches it: balanced 1.0125
    ]
    reached = [[0, 1, 1, 1], [1, 1, 1, 1], [1, 0, 1, 1]]
    task = _ScoredTask(fitness, np.array(reached, dtype=bool))
    starts = np.zeros((4, 4))
    args = (task, None, [0, 1, 2], starts)
    assert post_evaluate(*args, "balanced", 1, validation=2).index == 0
    post = post_evaluate(*args, "nominal_then_balanced", 1, validation=2)
    assert post.index == 1 and post.reached_nominal and post.nominal_reachers == 2
    # When no candidate reaches every nominal start it is the balanced rule.
    task = _ScoredTask(fitness, np.zeros((3, 4), dtype=bool))
    assert post_evaluate(task, None, [0, 1, 2], starts, "nominal_then_balanced", 1, 2).index == 0


def test_reach_rule_weighs_the_two_suites_reach_rates_and_breaks_ties_by_fitness():
    # columns: 2 rows in the task's own mazes, then 2 in validation mazes
    fitness = [
        [1.4, 1.4, 1.4, 1.4],  # reach own 0.5, validation 0.5: rate 0.5, best fitness
        [1.0, 1.0, 1.0, 1.0],  # own 1.0, validation 0.5: rate 0.75
        [1.1, 1.1, 1.1, 1.1],  # own 0.5, validation 1.0: rate 0.75, better fitness
        [0.9, 0.9, 0.9, 0.9],  # own 0.0, validation 1.0: rate 0.5 (plain mean 0.5 too)
    ]
    reached = [[1, 0, 1, 0], [1, 1, 1, 0], [1, 0, 1, 1], [0, 0, 1, 1]]
    task = _ScoredTask(fitness, np.array(reached, dtype=bool))
    starts = np.zeros((4, 4))
    args = (task, None, [0, 1, 2, 3], starts)
    assert post_evaluate(*args, "mean", 1, validation=2).index == 0
    post = post_evaluate(*args, "reach", 1, validation=2)
    assert post.index == 2 and post.rule == "reach"
    assert post.reached == pytest.approx(0.75)  # reported: the plain share of all episodes
    # The suites weigh the same whatever their numbers of rows: with one own row and three
    # validation rows, candidate 1 (own 1, validation 1/3: 0.67) beats candidates 2 and 3
    # (own 0, validation 1: 0.5), which a plain share (0.75 against 0.5) would pick.
    reached = [[1, 0, 0, 0], [1, 1, 0, 0], [0, 1, 1, 1], [0, 1, 1, 1]]
    task = _ScoredTask(fitness, np.array(reached, dtype=bool))
    assert post_evaluate(task, None, [0, 1, 2, 3], starts, "reach", 1, 3).index == 1
    # Without validation rows it is the plain reach rate, ties by mean fitness.
    reached = [[1, 1, 0, 0], [1, 1, 0, 0], [0, 0, 0, 0], [0, 0, 0, 1]]
    task = _ScoredTask(fitness, np.array(reached, dtype=bool))
    assert post_evaluate(task, None, [0, 1, 2, 3], starts, "reach", 1, 0).index == 0


def test_nominal_then_reach_keeps_the_candidates_that_reach_every_nominal_start():
    # columns: 1 nominal row, 2 random rows in the task's own maze (no validation mazes)
    fitness = [[1.0, 1.0, 1.0], [1.2, 1.2, 1.2], [0.9, 0.9, 0.9]]
    reached = [[0, 1, 1], [1, 1, 0], [1, 0, 1]]  # reach 2/3 each; 0 misses the nominal start
    task = _ScoredTask(fitness, np.array(reached, dtype=bool))
    starts = np.zeros((3, 4))
    args = (task, None, [0, 1, 2], starts)
    assert post_evaluate(*args, "reach", 1).index == 1  # all 2/3: the best fitness
    reached = [[0, 1, 1], [1, 0, 0], [1, 0, 1]]
    task = _ScoredTask(fitness, np.array(reached, dtype=bool))
    args = (task, None, [0, 1, 2], starts)
    assert post_evaluate(*args, "reach", 1).index == 0  # 2/3, though it misses the nominal
    post = post_evaluate(*args, "nominal_then_reach", 1)
    assert post.index == 2 and post.reached_nominal and post.nominal_reachers == 2
    # When no candidate reaches the nominal start it is the reach rule.
    reached = [[0, 1, 1], [0, 1, 0], [0, 0, 1]]
    task = _ScoredTask(fitness, np.array(reached, dtype=bool))
    assert post_evaluate(task, None, [0, 1, 2], starts, "nominal_then_reach", 1).index == 0
