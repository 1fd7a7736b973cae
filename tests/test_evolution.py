"""Arbitrator evolution: determinism, JSON checkpoints and exact resume."""

import json

import numpy as np
import pytest
import yaml
from conftest import SMALL_TASK

from evorbc_ros.arbitrator import Arbitrator, ArbitratorFile
from evorbc_ros.config import config_dir
from offline_evolution.arbitrator.evolve import (
    EvolutionSettings,
    arbitrator_file,
    evolve,
    file_sha256,
)
from offline_evolution.checkpoint import CheckpointError, Interrupted
from offline_evolution.maze_task.task import MazeTask, MazeTaskSettings


def settings(neat_file, kind="evorbc", seed=3, generations=6, repertoire=None):
    return EvolutionSettings(
        kind=kind,
        robot="4ws-5",
        generations=generations,
        seed=seed,
        neat_file=str(neat_file),
        neat_sha256=file_sha256(neat_file),
        task=SMALL_TASK,
        mapping="polar" if kind == "evorbc" else None,
        repertoire_fingerprint=repertoire.fingerprint() if repertoire else None,
    )


def same(a, b):
    assert a.best_network == b.best_network
    assert a.best_fitness == b.best_fitness and a.best_generation == b.best_generation
    strip = [("seconds", "evaluation_seconds")]
    for x, y in zip(a.history, b.history, strict=True):
        dx, dy = x.as_dict(), y.as_dict()
        for key in strip[0]:
            dx.pop(key), dy.pop(key)
        assert dx == dy


def test_same_seed_same_run_other_seed_differs(small_neat_file, small_repertoire):
    s = settings(small_neat_file, repertoire=small_repertoire)
    a = evolve(s, small_repertoire)
    same(a, evolve(s, small_repertoire))
    other = evolve(settings(small_neat_file, seed=4, repertoire=small_repertoire), small_repertoire)
    assert other.best_network != a.best_network
    assert len(a.history) == 6 and a.history[-1].best_so_far == a.best_fitness


def test_interrupted_run_resumes_to_the_same_result(tmp_path, small_neat_file, small_repertoire):
    s = settings(small_neat_file, generations=8, repertoire=small_repertoire)
    straight = evolve(s, small_repertoire)
    ckpt = tmp_path / "run.checkpoint.json"
    polls = []
    with pytest.raises(Interrupted) as info:
        evolve(
            s,
            small_repertoire,
            checkpoint=ckpt,
            checkpoint_every=100,
            should_stop=lambda: polls.append(1) or len(polls) == 3,
        )
    assert info.value.iteration == 3
    data = json.loads(ckpt.read_text())  # plain JSON: nothing to unpickle
    assert data["population"]["generation"] == 3 and len(data["history"]) == 3
    resumed = evolve(s, small_repertoire, checkpoint=ckpt)
    same(straight, resumed)
    assert not ckpt.exists()


def test_checkpoint_of_another_run_is_refused(tmp_path, small_neat_file, small_repertoire):
    ckpt = tmp_path / "c.json"
    s = settings(small_neat_file, repertoire=small_repertoire)
    with pytest.raises(Interrupted):
        evolve(s, small_repertoire, checkpoint=ckpt, should_stop=lambda: True)
    with pytest.raises(CheckpointError, match="seed is 3 in the checkpoint but 5 now"):
        evolve(
            settings(small_neat_file, seed=5, repertoire=small_repertoire),
            small_repertoire,
            checkpoint=ckpt,
        )
    ckpt.write_text(ckpt.read_text()[:500])
    with pytest.raises(CheckpointError, match="not a checkpoint"):
        evolve(s, small_repertoire, checkpoint=ckpt)


def test_checkpoint_for_another_robot_design_is_refused(
    tmp_path, small_neat_file, small_repertoire
):
    ckpt = tmp_path / "c.json"
    s = settings(small_neat_file, repertoire=small_repertoire)
    with pytest.raises(Interrupted):
        evolve(s, small_repertoire, checkpoint=ckpt, should_stop=lambda: True)
    data = json.loads(ckpt.read_text())
    assert data["simulation"] is None  # the 4WS kinematics: nothing to record
    data["simulation"] = {"geometry": {"max_joint_velocity": 10.0}}
    ckpt.write_text(json.dumps(data))
    with pytest.raises(CheckpointError, match=r"different robot .*simulation"):
        evolve(s, small_repertoire, checkpoint=ckpt)


def test_standard_neat_drives_the_parameters(small_neat_file):
    result = evolve(settings(small_neat_file, kind="standard", generations=3), None)
    assert len(result.best_network.output_keys) == 5  # speed and four wheel angles


def test_arbitrator_file_holds_the_post_evaluated_controller(
    tmp_path, small_neat_file, small_repertoire
):
    s = settings(small_neat_file, repertoire=small_repertoire)
    result = evolve(s, small_repertoire)
    task = MazeTask(
        MazeTaskSettings(**{**SMALL_TASK, "mazes": tuple(SMALL_TASK["mazes"])}), "4ws-5"
    )
    path = tmp_path / "a.json"
    arbitrator_file(result, task, small_repertoire, "r.json").save(path)
    loaded = ArbitratorFile.load(path)
    assert loaded.repertoire["fingerprint"] == small_repertoire.fingerprint()
    assert loaded.evolution["best_fitness"] == result.best_fitness
    assert loaded.network == result.selected_network
    from offline_evolution.arbitrator.selection import post_evaluation_starts
    from offline_evolution.maze_task.replay import replay

    # The file's controller scores its recorded post-evaluation fitness on those starts ...
    starts = post_evaluation_starts(task, s.seed, s.post_samples)
    assert len(starts) == 2 * (1 + s.post_samples)
    outcomes, _ = replay(loaded, task, starts, small_repertoire)
    post = loaded.evolution["post_evaluation"]
    assert np.mean([o.fitness for o in outcomes]) == pytest.approx(post["fitness"], abs=1e-12)
    assert post["fitness"] == result.post_evaluation.all_fitness.max()
    # ... and the best training genome reproduces its fitness on its generation's starts.
    best = ArbitratorFile(**{**vars(loaded), "network": result.best_network})
    rng = np.random.default_rng([s.seed, result.best_generation])
    outcomes, _ = replay(best, task, task.sample_starts(rng), small_repertoire)
    assert np.mean([o.fitness for o in outcomes]) == pytest.approx(result.best_fitness, abs=1e-12)
    Arbitrator(loaded, small_repertoire).choose(np.zeros(10))


def test_hall_of_fame_keeps_the_top_and_the_recent_champions():
    from offline_evolution.arbitrator.selection import HallOfFame

    hall = HallOfFame(3)
    hall.update([{"key": k, "fitness": f} for k, f in [(1, 0.5), (2, 0.9), (3, 0.1)]])
    hall.update([{"key": k, "fitness": f} for k, f in [(4, 0.2), (5, 0.3), (2, 0.9)]])
    hall.update([{"key": 6, "fitness": 0.05}])
    assert [g["key"] for g in hall.top] == [2, 1, 5]
    assert [g["key"] for g in hall.recent] == [2, 2, 6]  # an elite can win twice
    assert [g["key"] for g in hall.candidates()] == [2, 1, 5, 6]
    assert HallOfFame.from_dict(hall.to_dict()).candidates() == hall.candidates()


def test_post_evaluation_settings_may_change_on_resume(tmp_path, small_neat_file, small_repertoire):
    # They act only after the last generation, so a wider post-evaluation or another rule
    # must not throw away finished generations.
    ckpt = tmp_path / "c.json"
    s = settings(small_neat_file, generations=4, repertoire=small_repertoire)
    with pytest.raises(Interrupted):
        evolve(s, small_repertoire, checkpoint=ckpt, should_stop=lambda: True)
    wider = EvolutionSettings(
        **{**s.as_dict(), "post_samples": 3, "post_rule": "nominal_then_mean"}
    )
    result = evolve(wider, small_repertoire, checkpoint=ckpt)
    assert result.post_evaluation.rule == "nominal_then_mean"
    assert result.post_evaluation.episodes == 2 * (1 + 3)  # two mazes


def resumes_moved_but_not_edited(tmp_path, s, repertoire, moved, edit, refused):
    """Run ``s`` straight; interrupt it and resume with ``moved()`` (the settings with an
    input file at another path, same contents): the same result; interrupt again, ``edit()``
    the moved file: resuming with ``moved()`` is refused with a message matching ``refused``."""
    straight = evolve(s, repertoire)
    ckpt = tmp_path / "c.json"
    with pytest.raises(Interrupted):
        evolve(s, repertoire, checkpoint=ckpt, should_stop=lambda: True)
    same(straight, evolve(moved(), repertoire, checkpoint=ckpt))
    with pytest.raises(Interrupted):
        evolve(s, repertoire, checkpoint=ckpt, should_stop=lambda: True)
    edit()
    with pytest.raises(CheckpointError, match=refused):
        evolve(moved(), repertoire, checkpoint=ckpt)


def test_a_run_resumes_with_its_neat_file_elsewhere_but_not_edited(
    tmp_path, small_neat_file, small_repertoire
):
    # A long run carried to another checkout or machine finds its NEAT settings at another
    # path; only their contents decide whether the population may continue.
    s = settings(small_neat_file, generations=4, repertoire=small_repertoire)
    moved = tmp_path / "elsewhere" / "neat.ini"
    moved.parent.mkdir()
    moved.write_text(small_neat_file.read_text())
    resumes_moved_but_not_edited(
        tmp_path,
        s,
        small_repertoire,
        lambda: settings(moved, generations=4, repertoire=small_repertoire),
        lambda: moved.write_text(small_neat_file.read_text() + "\n# edited\n"),
        "neat_sha256 is",
    )


def test_a_run_resumes_with_its_sensor_file_moved_but_not_with_another_layout(
    tmp_path, small_neat_file, small_repertoire
):
    # A sensor layout moved into config/sensors to ship a controller (docs/design.md
    # section 13) is the same layout: the run resumes; a different layout is another run.
    s = settings(small_neat_file, generations=4, repertoire=small_repertoire)
    moved = tmp_path / "layout.yaml"
    moved.write_text((config_dir() / SMALL_TASK["sensors"]).read_text())

    def longer_range():
        layout = yaml.safe_load(moved.read_text())
        layout["rangefinders"]["range"] *= 2
        moved.write_text(yaml.safe_dump(layout))

    task = {**SMALL_TASK, "sensors": str(moved)}
    resumes_moved_but_not_edited(
        tmp_path,
        s,
        small_repertoire,
        lambda: EvolutionSettings(**{**s.as_dict(), "task": task}),
        longer_range,
        r"task\.sensors is 'layout",
    )


def test_a_run_resumes_with_a_maze_file_moved_or_renamed_but_not_with_other_walls(
    tmp_path, small_neat_file, small_repertoire
):
    # A training maze kept beside a run and then moved into config/mazes to ship its
    # controller under another name is the same maze: the run resumes; moved walls are
    # another run. The task names the shipped `gaps` by name, the copy by its path.
    s = settings(small_neat_file, generations=4, repertoire=small_repertoire)
    moved = tmp_path / "my-gaps.yaml"
    maze = yaml.safe_load((config_dir() / "mazes" / "gaps.yaml").read_text())
    moved.write_text(yaml.safe_dump({**maze, "name": "my-gaps", "description": "a copy"}))

    def shift_a_wall():
        maze["walls"][0][0] += 0.05
        moved.write_text(yaml.safe_dump({**maze, "name": "my-gaps"}))

    task = {**SMALL_TASK, "mazes": ["obstacle", str(moved)]}
    resumes_moved_but_not_edited(
        tmp_path,
        s,
        small_repertoire,
        lambda: EvolutionSettings(**{**s.as_dict(), "task": task}),
        shift_a_wall,
        r"task\.mazes",
    )


def test_a_maze_file_moved_away_resumes_and_one_edited_in_place_does_not(
    tmp_path, small_neat_file, small_repertoire
):
    # The checkpoint records what the task's mazes held when it was saved, so the old path
    # need not exist any more, and a file edited where it lies is not the same maze.
    here, there = tmp_path / "here.yaml", tmp_path / "there.yaml"
    here.write_text((config_dir() / "mazes" / "gaps.yaml").read_text())
    s = settings(small_neat_file, generations=4, repertoire=small_repertoire)
    at = lambda p: EvolutionSettings(**{**s.as_dict(), "task": {**SMALL_TASK, "mazes": [str(p)]}})  # noqa: E731
    straight = evolve(at(here), small_repertoire)
    ckpt = tmp_path / "c.json"
    with pytest.raises(Interrupted):
        evolve(at(here), small_repertoire, checkpoint=ckpt, should_stop=lambda: True)
    here.rename(there)
    same(straight, evolve(at(there), small_repertoire, checkpoint=ckpt))
    with pytest.raises(Interrupted):
        evolve(at(there), small_repertoire, checkpoint=ckpt, should_stop=lambda: True)
    maze = yaml.safe_load(there.read_text())
    maze["target"][0] -= 0.1
    there.write_text(yaml.safe_dump(maze))
    with pytest.raises(CheckpointError, match=r"task\.mazes"):
        evolve(at(there), small_repertoire, checkpoint=ckpt)


class _ScoredTask:
    """Stands in for MazeTask.evaluate with fixed per-episode outcomes (rule logic only):
    the "networks" are row numbers of ``fitness`` and ``reached`` (candidates x starts)."""

    def __init__(self, fitness, reached):
        self.mazes = ("a",)
        self.fitness, self.reached = np.asarray(fitness, float), np.asarray(reached, bool)

    def evaluate(self, networks, controller, starts):
        from types import SimpleNamespace

        rows = list(networks)  # a batch of the post-evaluation (post_scores.py)
        return SimpleNamespace(
            fitness=self.fitness[rows].ravel(), reached=self.reached[rows].ravel()
        )


@pytest.mark.parametrize(
    ("reached", "rule", "chosen", "from_nominal"),
    [
        # columns: the nominal start, then two random starts; rows: candidates
        ([[0, 1, 1], [1, 0, 0], [1, 1, 0]], "mean", 0, False),
        ([[0, 1, 1], [1, 0, 0], [1, 1, 0]], "nominal_then_mean", 2, True),
        ([[0, 1, 1], [0, 0, 0], [0, 1, 0]], "nominal_then_mean", 0, False),  # none: by mean
    ],
)
def test_post_evaluation_rules(reached, rule, chosen, from_nominal):
    from offline_evolution.arbitrator.selection import post_evaluate

    fitness = [[0.9, 1.2, 1.2], [1.1, 0.5, 0.5], [1.1, 1.1, 0.6]]  # means 1.1, 0.7, 0.93
    post = post_evaluate(_ScoredTask(fitness, reached), None, [0, 1, 2], np.zeros((3, 4)), rule)
    assert (post.index, post.reached_nominal) == (chosen, from_nominal)
    assert post.fitness == pytest.approx(np.mean(fitness[chosen]))
    assert post.nominal_reachers == sum(row[0] for row in reached)
    with pytest.raises(ValueError, match="rule must be one of"):
        post_evaluate(_ScoredTask(fitness, reached), None, [0, 1, 2], np.zeros((3, 4)), "best")


def test_nominal_watch_keeps_genomes_that_reach_and_leaves_the_evolution_alone(
    tmp_path, small_neat_file
):
    import yaml
    from test_maze_task import CORRIDOR

    from offline_evolution.arbitrator.evolve import Evolution

    # A corridor whose target is 2 m straight ahead of the nominal start (heading 0).
    maze = tmp_path / "corridor.yaml"
    maze.write_text(yaml.safe_dump(CORRIDOR))
    task = {"mazes": [str(maze)], "episode_time": 20.0, "samples_per_maze": 1,
            "sensors": "sensors/4ws.yaml"}  # fmt: skip
    base = {**settings(small_neat_file, kind="standard", generations=3).as_dict(), "task": task}
    plain = evolve(EvolutionSettings(**base), None)
    watched = EvolutionSettings(**{**base, "nominal_watch": 5, "post_rule": "nominal_then_mean"})
    same(plain, evolve(watched, None))  # the watch draws no random numbers
    run = Evolution(watched)
    try:
        run.step()
        config = run.config
        # Full speed (sigmoid(5 x 10) = 1), wheels straight (sigmoid(0) = 0.5 is gene 0):
        # it crosses the corridor (tests/test_maze_task.py). A zero-speed one does not.
        fast, still = (config.genome_type(k) for k in (10_001, 10_002))
        for genome, speed_bias in ((fast, 10.0), (still, -10.0)):
            genome.configure_new(config.genome_config)
            genome.connections.clear()
            for key, node in genome.nodes.items():
                node.bias, node.response = (speed_bias if key == 0 else 0.0), 1.0
                node.activation, node.aggregation = "sigmoid", "sum"
            genome.fitness = 0.0  # a training fitness that keeps it out of the top
        run._watch_nominal([fast, still], config)
        assert [g["key"] for g in run.hall.nominal] == [10_001]
        assert run.hall.nominal[0]["nominal_fitness"] == pytest.approx(2.0 - 9.5 / 20.0)
        result = run.result(0.0)  # the rule finds it among the mere top and recent
        assert result.post_evaluation.reached_nominal
        assert result.post_evaluation.nominal_reachers >= 1
    finally:
        run.task.close()


def test_hall_of_fame_keeps_the_best_nominal_reachers():
    from offline_evolution.arbitrator.selection import HallOfFame

    hall = HallOfFame(2)
    for key, f in [(1, 1.5), (2, 1.7), (1, 1.5), (3, 1.6)]:
        hall.add_nominal({"key": key, "fitness": 0.3, "nominal_fitness": f})
    assert [g["key"] for g in hall.nominal] == [2, 3]
    assert [g["key"] for g in hall.candidates()] == [2, 3]
    assert HallOfFame.from_dict(hall.to_dict()).nominal == hall.nominal
    old = {"size": 2, "top": [], "recent": []}  # a checkpoint from before the watch
    assert HallOfFame.from_dict(old).nominal == []


def test_an_interrupted_run_resumes_with_another_length(
    tmp_path, small_neat_file, small_repertoire
):
    """Only the end depends on the run's length: a run of 8 generations interrupted after
    3 and resumed with 10 gives what a straight run of 10 gives; one past generation 3
    cannot be resumed to stop at 2."""
    ten = settings(small_neat_file, generations=10, repertoire=small_repertoire)
    straight = evolve(ten, small_repertoire)
    ckpt = tmp_path / "run.checkpoint.json"
    polls = []
    eight = settings(small_neat_file, generations=8, repertoire=small_repertoire)
    with pytest.raises(Interrupted):
        evolve(
            eight,
            small_repertoire,
            checkpoint=ckpt,
            should_stop=lambda: polls.append(1) or len(polls) == 3,
        )
    kept = ckpt.read_text()
    two = settings(small_neat_file, generations=2, repertoire=small_repertoire)
    with pytest.raises(
        CheckpointError,
        match="the run is past generation 3, so it cannot stop "
        "at 2; run it with --generations 3 or more",
    ):
        evolve(two, small_repertoire, checkpoint=ckpt)
    assert ckpt.read_text() == kept  # refused, nothing lost
    same(straight, evolve(ten, small_repertoire, checkpoint=ckpt))


def test_the_post_evaluation_reports_and_leaves_a_given_tasks_reporter(
    small_neat_file, small_repertoire
):
    s = settings(small_neat_file, generations=2, repertoire=small_repertoire)
    task = MazeTask(MazeTaskSettings(**SMALL_TASK), "4ws-5")

    def mine(done, total):
        """The caller's own reporter."""

    task.progress = mine
    reports = []
    # The callback of the API before reporters still works, and says what replaces it.
    with pytest.warns(DeprecationWarning, match=r"pass reporters=\[\.\.\.\]"):
        result = evolve(
            s, small_repertoire, task=task,
            post_progress=lambda done, total: reports.append((done, total)),
        )  # fmt: skip
    assert task.progress is mine
    assert result.post_evaluation.candidates > 0
    # the 4WS kernel runs the post-evaluation in one call and does not report
    assert reports == []
