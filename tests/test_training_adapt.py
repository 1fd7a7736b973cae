"""Training on a damaged robot (issue 42 point 1, docs/adaptation.md "Trained on the damaged
robot"): ``training: perturb`` takes every set of config/perturbations/, ``training: adapt``
runs the run's episodes with the onboard adaptation of ``evaluate --adapt`` (the same
code), and ``training: post_perturb`` post-selects in worlds of the training's set.
"""

import numpy as np
import pytest
from conftest import SMALL_TASK, evolution_settings

from evorbc_ros.config import ConfigError
from offline_evolution.arbitrator.evolve import evolve
from offline_evolution.arbitrator.post_scores import scores_key
from offline_evolution.arbitrator.selection import post_evaluation_starts, selection_world
from offline_evolution.maze_task.adapting import task_adapting
from offline_evolution.maze_task.perturbation import perturbation_dir
from offline_evolution.maze_task.task import MazeTask, MazeTaskSettings
from offline_evolution.maze_task.training import TrainingSettings

TRAINING = {"generated": 2, "starts": 1, "pool": 0, "maze_seed": 5, "post_mazes": 2}
DAMAGE = "4ws-stuck-steering"


def task_dict(**training):
    return {**SMALL_TASK, "training": {**TRAINING, **training}}


def fitness_history(result) -> list[tuple[float, float]]:
    return [(h.best, h.mean) for h in result.history]


class Spy(MazeTask):
    """The 4ws-5 maze task, keeping the adaptation each evaluate() ran with."""

    def evaluate(self, networks, controller, starts, record=False, world=None):
        self.seen.append(self.adapting)
        return super().evaluate(networks, controller, starts, record, world)


def spy(settings) -> Spy:
    task = Spy(MazeTaskSettings(**settings.task), "4ws-5")
    task.seen = []
    return task


@pytest.mark.parametrize(
    "name", sorted(p.stem for p in perturbation_dir().glob("*.yaml") if "4ws" in p.stem)
)
def test_training_takes_every_4ws_set(name):
    settings = MazeTaskSettings.from_dict(task_dict(perturb=name), "t.yaml")
    task = MazeTask(settings, "4ws-5")
    task.start_training("4ws-5", seed=3)
    starts, world = task.generation_episodes(np.random.default_rng([3, 0]))
    assert world is not None and len(world) == len(starts)
    # Each episode's robot is a damaged one, or (slow drive) slowed well below realistic.
    gain = world.values.get("wheel_speed_gain", np.ones(1))
    assert world.damage is not None or name == "realistic" or gain.max() < 0.8


def test_adapt_changes_training_under_damage_with_evaluates_adaptation(
    small_neat_file, small_repertoire
):
    def run(**training):
        s = evolution_settings(
            small_neat_file, small_repertoire, task_dict(perturb=DAMAGE, **training),
            generations=2,
        )  # fmt: skip
        task = spy(s)
        return evolve(s, small_repertoire, task=task), task

    off, off_task = run()
    explicit, _ = run(adapt=False)
    on, on_task = run(adapt=True)
    # Off is the default and changes nothing; on, the same seed's episodes adapt.
    assert fitness_history(explicit) == fitness_history(off)
    assert fitness_history(on) != fitness_history(off)
    assert all(a is None for a in off_task.seen)
    # Every episode of the run adapted (training, nominal watch, post-selection), with the
    # adaptation evaluate --adapt builds for this task and repertoire.
    expected = task_adapting(on_task, small_repertoire, "recorded", "4ws-5")[1]
    assert on_task.seen and all(a is on_task.seen[0] for a in on_task.seen)
    for got, want in zip(on_task.seen[0], expected, strict=True):
        assert np.array_equal(got, want)


def test_adapt_expected_settled_compares_with_the_settled_outcomes(
    small_neat_file, small_repertoire
):
    task_values = task_dict(perturb=DAMAGE, adapt=True, adapt_expected="settled")
    s = evolution_settings(small_neat_file, small_repertoire, task_values, generations=1)
    task = spy(s)
    evolve(s, small_repertoire, task=task)
    settled = task_adapting(task, small_repertoire, "settled", "4ws-5")[1].expected
    assert np.array_equal(task.seen[0].expected, settled)
    assert not np.array_equal(settled, task.seen[0].recorded)


def test_a_standard_controller_cannot_train_adapting(small_neat_file, small_repertoire):
    s = evolution_settings(
        small_neat_file, small_repertoire, task_dict(adapt=True), kind="standard",
        mapping=None, repertoire_fingerprint=None,
    )  # fmt: skip
    with pytest.raises(ConfigError, match="training: adapt: adaptation corrects a repertoire"):
        evolve(s, None)


def test_post_perturb_selects_in_worlds_of_the_set_and_leaves_evolution_alone(
    small_neat_file, small_repertoire
):
    def run(**training):
        values = task_dict(perturb=DAMAGE, **training)
        return evolve(
            evolution_settings(small_neat_file, small_repertoire, values, generations=2),
            small_repertoire,
        )

    nominal, damaged = run(), run(post_perturb=True)
    assert fitness_history(damaged) == fitness_history(nominal)  # the same evolution
    # The post-selection ran other episodes: on the damaged robot.
    chosen_by = damaged.post_evaluation.all_fitness, nominal.post_evaluation.all_fitness
    assert not np.array_equal(*chosen_by)


def test_selection_world_draws_one_seeded_world_per_start():
    def task(**training):
        t = MazeTask(MazeTaskSettings.from_dict(task_dict(**training), "t.yaml"), "4ws-5")
        t.start_training("4ws-5", seed=3)
        return t

    on = task(perturb=DAMAGE, post_perturb=True)
    starts = post_evaluation_starts(on, 3, 2)
    moved, world = selection_world(on, starts, 3)
    again, world2 = selection_world(on, starts, 3)
    assert len(world) == len(starts) and world.damage is not None
    assert np.array_equal(moved, again) and np.array_equal(world.keys, world2.keys)
    assert np.array_equal(moved[:, 0], starts[:, 0])  # each row stays in its maze
    _, final = selection_world(on, starts, 3, final=True)
    assert not np.array_equal(final.keys, world.keys)  # the finalists' own stream
    off = task(perturb=DAMAGE)
    same, none = selection_world(off, starts, 3)
    assert none is None and same is starts
    # A resumed post-selection never takes rows of the other world: the key tells them
    # apart even where the set moves no start.
    assert scores_key([], starts, world) != scores_key([], starts)
    assert scores_key([], starts, world) == scores_key([], starts, world2)


def test_new_keys_are_recorded_only_when_set():
    assert TrainingSettings.from_dict(dict(TRAINING), "t").as_dict() == {
        **TRAINING, "task_mazes": True, "perturb": "none",
    }  # fmt: skip
    values = {**TRAINING, "perturb": DAMAGE, "adapt": True, "post_perturb": True}
    recorded = TrainingSettings.from_dict(values, "t").as_dict()
    assert recorded["adapt"] is True and recorded["adapt_expected"] == "recorded"
    assert recorded["post_perturb"] is True
