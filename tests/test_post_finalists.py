"""The post-evaluation's second round (``post_finalists``, docs/design.md section 8).

The first round scores every hall-of-fame candidate on a few dozen starts and its winner is
often the luckiest; the finalists run further starts and the rule picks among them over
both rounds. The round resumes like the first (saved rows under a key) and is recorded.
"""

import dataclasses
import json

import numpy as np
import pytest
from conftest import SMALL_TASK, evolution_settings

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.config import ConfigError
from offline_evolution.arbitrator.evolve import arbitrator_file, evolve
from offline_evolution.arbitrator.selection import _join, final_starts, post_evaluate
from offline_evolution.checkpoint import Interrupted
from offline_evolution.maze_task.task import MazeTaskSettings, make_task

GENERATIONS = 3


class _Table:
    """Stands in for a task's ``evaluate`` with fixed outcomes (the rule's logic only):
    a "network" is a row of ``reached``, a start's first value (its maze index) names the
    column, so the two rounds read different columns of one table."""

    def __init__(self, reached):
        self.mazes = ("a",)
        self.reached = np.asarray(reached, bool)
        self.runs = []  # (networks, columns) of every call

    def evaluate(self, networks, controller, starts):
        from types import SimpleNamespace

        rows, cols = list(networks), starts[:, 0].astype(int)
        self.runs.append((rows, cols.tolist()))
        reached = self.reached[np.ix_(rows, cols)]
        return SimpleNamespace(fitness=np.where(reached, 1.5, 0.5).ravel(), reached=reached.ravel())


def columns(first, last):
    """Starts whose maze index names the table's columns ``first`` to ``last - 1``."""
    out = np.zeros((last - first, 4))
    out[:, 0] = np.arange(first, last)
    return out


# Columns 0-4 are the first round (the nominal start, then 4 random), 5-20 the second. All
# three reach from the nominal start; 0 is lucky in the first round (4 of 4) and reaches 8
# of 16 after; 1 reaches 3 of 4, then 14 of 16; 2 reaches 2 of 4 and is not a finalist.
TABLE = [
    [1] + [1, 1, 1, 1] + [1, 0] * 8,
    [1] + [1, 1, 1, 0] + [1] * 14 + [0, 0],
    [1] + [1, 1, 0, 0] + [1] * 16,
]


@pytest.mark.parametrize("rule", ["reach", "mean", "nominal_then_reach"])
def test_the_finalists_round_undoes_a_lucky_first_round(rule):
    one = post_evaluate(_Table(TABLE), None, [0, 1, 2], columns(0, 5), rule, 1)
    assert one.index == 0 and one.finalists == 0
    task = _Table(TABLE)
    two = post_evaluate(
        task, None, [0, 1, 2], columns(0, 5), rule, 1,
        finalists=2, more_starts=lambda: (columns(5, 21), 0),
    )  # fmt: skip
    assert two.index == 1
    assert (two.finalists, two.final_episodes, two.episodes, two.candidates) == (2, 21, 5, 3)
    assert two.reached == pytest.approx(18 / 21)  # over both rounds
    assert two.fitness == pytest.approx((18 * 1.5 + 3 * 0.5) / 21)
    assert two.reached_nominal and two.nominal_reachers == 3
    # The third candidate never ran the second round; the first round's figures stay.
    assert all(2 not in rows for rows, cols in task.runs if cols[0] == 5)
    np.testing.assert_array_equal(two.all_fitness, one.all_fitness)
    assert two.as_dict()["finalists"] == 2 and two.as_dict()["episodes_per_finalist"] == 21
    assert "finalists" not in one.as_dict()  # files without a second round read as before


def test_ties_after_the_second_round_go_to_the_earlier_candidate():
    # The first round ranks 1 above 0 (4 of 4 against 3 of 4); over both rounds both reach
    # 17 of 21 with the same fitness: the hall's order decides, as in one round.
    table = [
        [1] + [1, 1, 1, 0] + [1] * 14 + [0, 0],
        [1] + [1, 1, 1, 1] + [1] * 13 + [0, 0, 0],
    ]
    for rule in ("mean", "reach"):
        post = post_evaluate(
            _Table(table), None, [0, 1], columns(0, 5), rule, 1,
            finalists=2, more_starts=lambda: (columns(5, 21), 0),
        )  # fmt: skip
        assert post.index == 0, rule


def _old_choice(fitness, reached, rule, nominal_rows, validation):
    """The one-round choice as written before the second round (git 1698b40)."""
    candidates, n = fitness.shape
    mean, rate = fitness.mean(axis=1), reached.mean(axis=1)
    nominal = reached[:, :nominal_rows].all(axis=1)
    base = rule.removeprefix("nominal_then_")
    eligible = nominal if base != rule and nominal.any() else np.ones_like(nominal)
    score = mean
    two = 0 < validation < n
    if base in ("balanced", "reach") and two:
        score = 0.5 * (fitness[:, : n - validation].mean(1) + fitness[:, n - validation :].mean(1))
    if base == "reach":
        if two:
            rate = 0.5 * (
                reached[:, : n - validation].mean(1) + reached[:, n - validation :].mean(1)
            )
        return int(np.lexsort((np.arange(candidates), -score, -rate, ~eligible))[0])
    return int(np.argmax(np.where(eligible, score, -np.inf)))


def test_one_round_chooses_as_before_for_every_rule():
    from offline_evolution.arbitrator.selection import RULES, _ranking

    rng = np.random.default_rng(0)
    for _ in range(400):
        candidates, n = rng.integers(1, 7), rng.integers(2, 9)
        validation = int(rng.integers(0, n))
        reached = rng.random((candidates, n)) < 0.6
        # coarse fitness values, so that ties happen
        fitness = (
            np.where(reached, rng.integers(3, 5, reached.shape), rng.integers(0, 3, reached.shape))
            / 2
        )
        for rule in RULES:
            order, _ = _ranking(fitness, reached, rule, 1, validation)
            assert order[0] == _old_choice(fitness, reached, rule, 1, validation)


def test_the_second_rounds_validation_episodes_count_as_validation():
    # columns: 0 nominal, 1 own, 2 validation (first round); 3 own, 4-5 validation (second)
    table = [[1, 1, 0, 1, 1, 1], [1, 1, 1, 1, 0, 0]]
    first = post_evaluate(_Table(table), None, [0, 1], columns(0, 3), "reach", 1, 1)
    assert first.index == 1  # validation 1 of 1 against 0 of 1
    two = post_evaluate(
        _Table(table), None, [0, 1], columns(0, 3), "reach", 1, 1,
        finalists=2, more_starts=lambda: (columns(3, 6), 2),
    )  # fmt: skip
    assert two.index == 0  # own 3 of 3 both; validation 2 of 3 against 1 of 3


def test_validation_columns_stay_last_when_the_rounds_are_joined():
    first = np.array([[1, 2, 3, 90]])  # nominal, two own starts, one validation start
    second = np.array([[4, 5, 91, 92]])  # two own starts, two validation starts
    np.testing.assert_array_equal(_join(first, second, 1, 2), [[1, 2, 3, 4, 5, 90, 91, 92]])


def test_the_further_starts_are_new_and_seeded():
    task = make_task(
        MazeTaskSettings(("obstacle", "gaps"), 15.0, 1, "sensors/4ws.yaml"), "4ws-5", 1
    )
    try:
        a, b = final_starts(task, 5, 3), final_starts(task, 5, 3)
        from offline_evolution.arbitrator.selection import post_evaluation_starts

        first = post_evaluation_starts(task, 5, 3)
    finally:
        task.close()
    np.testing.assert_array_equal(a, b)
    assert a.shape == (6, 4) and a[:, 0].tolist() == [0, 1] * 3  # no nominal rows
    assert not any((first == row).all(axis=1).any() for row in a)


def same(a, b):
    """Two post-evaluations chose the same candidate with the same figures."""
    assert (a.index, a.as_dict()) == (b.index, b.as_dict())
    np.testing.assert_array_equal(a.all_fitness, b.all_fitness)


def settings(neat_file, repertoire, **changes):
    return evolution_settings(
        neat_file, repertoire, SMALL_TASK, seed=5, generations=GENERATIONS,
        **{"post_finalists": 2, "post_final_samples": 3, **changes},
    )  # fmt: skip


def test_an_interrupted_finalists_round_resumes_to_the_straight_result(
    tmp_path, small_neat_file, small_repertoire
):
    s = settings(small_neat_file, small_repertoire)
    straight = evolve(s, small_repertoire)
    assert straight.post_evaluation.finalists == 2
    assert straight.post_evaluation.final_episodes == 2 * (1 + 1) + 2 * 3

    ckpt = tmp_path / "c.json"

    def in_the_second_round() -> bool:
        return ckpt.exists() and "post_final_scores" in json.loads(ckpt.read_text())

    with pytest.raises(Interrupted) as info:
        evolve(s, small_repertoire, checkpoint=ckpt, should_stop=in_the_second_round)
    assert info.value.during == "the post-evaluation (1 of 2 finalists done)"
    saved = json.loads(ckpt.read_text())
    assert len(saved["post_final_scores"]["fitness"]) == 1
    resumed = evolve(s, small_repertoire, checkpoint=ckpt, keep_checkpoint=True)
    assert resumed.selected_network == straight.selected_network
    same(resumed.post_evaluation, straight.post_evaluation)

    # The saved rows are used, not run again: a row changed in the file shows in the result
    # (fitness 9 is more than eq. 5 gives, 2 at most).
    saved = json.loads(ckpt.read_text())
    rows = saved["post_final_scores"]
    rows["fitness"][1] = [9.0] * len(rows["fitness"][1])
    rows["reached"][1] = [True] * len(rows["reached"][1])
    ckpt.write_text(json.dumps(saved))
    assert (
        evolve(s, small_repertoire, checkpoint=ckpt, keep_checkpoint=True).post_evaluation.fitness
        > 2
    )

    # Another number of further starts: those rows are of other starts and run again.
    wider = dataclasses.replace(s, post_final_samples=4)
    again = evolve(wider, small_repertoire, checkpoint=ckpt, keep_checkpoint=True)
    straight_wider = evolve(wider, small_repertoire)
    same(again.post_evaluation, straight_wider.post_evaluation)
    assert again.post_evaluation.final_episodes == 2 * (1 + 1) + 2 * 4

    # A longer run drops the finished run's rows of both rounds.
    longer = dataclasses.replace(s, generations=GENERATIONS + 2)
    with pytest.raises(Interrupted):
        evolve(longer, small_repertoire, checkpoint=ckpt, should_stop=lambda: True)
    kept = json.loads(ckpt.read_text())
    assert "post_scores" not in kept and "post_final_scores" not in kept


def test_the_arbitrator_file_records_the_second_round(tmp_path, small_neat_file, small_repertoire):
    s = settings(small_neat_file, small_repertoire)
    result = evolve(s, small_repertoire)
    task = make_task(MazeTaskSettings.from_dict(dict(SMALL_TASK), "t"), "4ws-5", 1)
    try:
        arbitrator_file(result, task, small_repertoire, "r.json").save(tmp_path / "a.json")
    finally:
        task.close()
    post = ArbitratorFile.load(tmp_path / "a.json").evolution["post_evaluation"]
    assert (post["finalists"], post["final_samples_per_maze"]) == (2, 3)
    assert post["episodes_per_finalist"] == 2 * (1 + 1) + 2 * 3
    assert post["episodes_per_candidate"] == 2 * (1 + 1)


def test_the_second_round_counts_in_the_memory_check(monkeypatch):
    from offline_evolution import memory

    monkeypatch.setattr(memory, "machine_memory", lambda: 24 << 30)
    task = MazeTaskSettings.from_dict(dict(SMALL_TASK), "t")
    memory.check_evolution_memory(task, 150, "4ws-5", "t", 75, 10, 10, 100)
    with pytest.raises(ConfigError, match="post_final_samples") as info:
        memory.check_evolution_memory(task, 150, "4ws-5", "t", 75, 10, 10, 10**8)
    assert "the post-evaluation's finalists (2,000,000,000 episodes: 10 genomes" in str(info.value)
    # More finalists than candidates: only the candidates run.
    with pytest.raises(ConfigError) as info:
        memory.check_evolution_memory(task, 150, "4ws-5", "t", 75, 10, 1000, 10**7)
    assert "(1,500,000,000 episodes: 75 genomes x 2 mazes x 10000000 starts)" in str(info.value)


def test_the_run_settings_carry_the_second_round_and_refuse_a_negative_one(tmp_path):
    from offline_evolution.arbitrator.settings import load_run_settings

    path = tmp_path / "run.yaml"
    base = "generations: 1\nneat: neat/4ws.ini\ntask: tasks/maze-4ws.yaml\n"
    path.write_text(base + "post_finalists: 10\npost_final_samples: 75\n")
    selection = load_run_settings(path).selection()
    assert (selection["post_finalists"], selection["post_final_samples"]) == (10, 75)
    for half in ("post_finalists: -1\n", "post_finalists: 10\n", "post_final_samples: 5\n"):
        path.write_text(base + half)
        with pytest.raises(ConfigError) as info:
            load_run_settings(path)
        assert str(info.value).startswith(f"{path}: post_final")
        assert "\n" not in str(info.value)
    assert "go together" in str(info.value)


def test_the_cli_reports_the_chosen_ones_figures_over_both_rounds(
    tmp_path, capsys, small_repertoire, small_neat_file, small_task_file
):
    from offline_evolution.cli import main

    rep, settings_file = tmp_path / "r.json", tmp_path / "run.yaml"
    small_repertoire.save(rep)
    settings_file.write_text(
        "generations: 2\nneat: neat/4ws.ini\ntask: tasks/maze-4ws.yaml\nhall_of_fame: 3\n"
        "post_samples: 1\npost_finalists: 2\npost_final_samples: 2\n"
    )
    argv = ["arbitrator", "--repertoire", rep, "--config", settings_file, "--quiet"]
    argv += ["--neat-config", small_neat_file, "--task", small_task_file]
    assert main([str(a) for a in [*argv, "--out", tmp_path / "a.json"]]) == 0
    out = capsys.readouterr().out
    arb = ArbitratorFile.load(tmp_path / "a.json")
    post = arb.evolution["post_evaluation"]
    # two mazes: 2 x (nominal + 1) in the first round, 2 x 2 in the second
    assert post["episodes_per_finalist"] == 8 and post["finalists"] == 2
    assert f"of 8 post-evaluation episodes (one of 2 finalists of {post['candidates']} " in out


def test_a_damaged_post_final_scores_entry_is_named(tmp_path, small_neat_file, small_repertoire):
    from offline_evolution.checkpoint import CheckpointError

    s = settings(small_neat_file, small_repertoire)
    ckpt = tmp_path / "c.json"
    evolve(s, small_repertoire, checkpoint=ckpt, keep_checkpoint=True)
    saved = json.loads(ckpt.read_text())
    saved["post_final_scores"]["fitness"][0][0] = None
    ckpt.write_text(json.dumps(saved))
    with pytest.raises(CheckpointError, match=r"post_final_scores\.fitness must hold finite"):
        evolve(s, small_repertoire, checkpoint=ckpt)


def test_another_rule_or_more_finalists_than_candidates(
    tmp_path, small_neat_file, small_repertoire
):
    s = settings(small_neat_file, small_repertoire)
    ckpt = tmp_path / "c.json"
    evolve(s, small_repertoire, checkpoint=ckpt, keep_checkpoint=True)
    # Another rule may pick other finalists: their rows are run, as a straight run would.
    for changed in (
        dataclasses.replace(s, post_rule="nominal_then_reach", post_finalists=1),
        dataclasses.replace(s, post_finalists=50),  # every candidate is a finalist
    ):
        kept = evolve(changed, small_repertoire, checkpoint=ckpt, keep_checkpoint=True)
        same(kept.post_evaluation, evolve(changed, small_repertoire).post_evaluation)
    assert kept.post_evaluation.finalists == kept.post_evaluation.candidates


def test_a_generated_maze_task_keeps_its_validation_columns_apart(
    tmp_path, small_neat_file, small_repertoire
):
    """A training task's second round draws its own validation mazes after the first round
    has run in its own; interrupted in either round, it resumes to the straight result."""
    task = {**SMALL_TASK, "training": {"generated": 1, "starts": 1, "pool": 0,
            "maze_seed": 5, "post_mazes": 2}}  # fmt: skip
    s = evolution_settings(
        small_neat_file, small_repertoire, task, seed=5, generations=2,
        post_finalists=2, post_final_samples=2, post_rule="balanced",
    )  # fmt: skip
    straight = evolve(s, small_repertoire)
    post = straight.post_evaluation
    # first round: 2 mazes x (nominal + 1) + 2 validation mazes x 1; second: 2 x 2 + 2 x 2
    assert (post.episodes, post.final_episodes) == (6, 14)
    # The first round ran in its own validation mazes, as a run without a second round does.
    one_round = dataclasses.replace(s, post_finalists=0, post_final_samples=0)
    np.testing.assert_array_equal(
        post.all_fitness, evolve(one_round, small_repertoire).post_evaluation.all_fitness
    )
    for key in ("post_scores", "post_final_scores"):
        ckpt = tmp_path / f"{key}.json"

        def saved(key=key, ckpt=ckpt) -> bool:
            return ckpt.exists() and key in json.loads(ckpt.read_text())

        with pytest.raises(Interrupted):
            evolve(s, small_repertoire, checkpoint=ckpt, should_stop=saved)
        same(evolve(s, small_repertoire, checkpoint=ckpt).post_evaluation, post)
